"""The bearing-rate collision rule (Nagavarapu et al. Sec. 4) and the bearing sensor."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from algorithms.collision import CollisionRule, epsilons
from mjswarm.core.bearing import BearingSensor
from mjswarm.core.simulation import Simulation
from mjswarm.core.world import Pose2D, WallSegment, world_spec

S = 0.05


def satisfies_28(eps: list[float]) -> bool:
    """Eq. (28) for a team of ``len(eps)`` robots (``<=`` within a robot's terms)."""
    k = len(eps)
    if k == 1:  # a lone robot meets nobody
        return 0.0 < eps[0] < 1.0
    chain = []
    for e in eps:
        chain += [e, (k - 1) * e]
    for (a, b), i in zip(itertools.pairwise(chain), range(len(chain) - 1)):
        same_robot = i % 2 == 0
        if not (a <= b if same_robot else a < b):
            return False
    return chain[-1] < 1.0


@pytest.mark.parametrize("k", range(1, 21))
def test_epsilons_satisfy_eq_28(k):
    eps = epsilons(k)
    assert len(eps) == k and satisfies_28(eps)
    assert all(0 < e < 1 for e in eps)


def test_eq_28_check_has_teeth():
    assert satisfies_28([0.05, 0.25])  # the paper's two-robot choice
    assert not satisfies_28([0.25, 0.05])  # order matters
    assert not satisfies_28([0.1, 0.3, 0.5])  # (K-1) eps_2 = 0.6 > eps_3
    assert not satisfies_28([0.3, 1.2])  # (K-1) eps_K must stay < 1
    assert not satisfies_28([0.2, 0.9, 0.95])


def feed(rule: CollisionRule, bearings: list[dict[int, float]]) -> list[float]:
    return [rule.update(b) for b in bearings]


def test_robot_ahead_on_same_lane_stops_follower_until_out_of_view():
    rule = CollisionRule(S, 0.1)
    speeds = feed(rule, [{1: 0.0}] * 20 + [{}] * 3)
    assert speeds[5] == S  # not enough samples for a rate yet
    assert speeds[15] == 0.0  # eq. (27), beta = 0
    assert speeds[-1] == S  # eq. (33) from 0
    assert rule.activations == 1


def test_constant_bearing_off_axis_slows_by_epsilon_and_recovers():
    rule = CollisionRule(S, 0.1)
    speeds = feed(rule, [{2: 0.6}] * 20)
    assert speeds[-1] == pytest.approx(S - 0.1 * S)  # eq. (27), otherwise
    speeds = feed(rule, [{}])
    assert speeds[-1] == pytest.approx(S)  # eq. (33)


def test_changing_bearing_is_no_collision():
    rule = CollisionRule(S, 0.1)
    speeds = feed(rule, [{3: 0.5 + 0.01 * i} for i in range(40)])  # 0.5 rad/s
    assert speeds == [S] * 40 and rule.activations == 0


def test_crossing_the_vertex_restores_speed_and_forgets_reductions():
    rule = CollisionRule(S, 0.1)
    feed(rule, [{1: 0.6, 2: -0.7}] * 20)
    assert rule.speed == pytest.approx(S - 0.2 * S)  # one reduction per robot
    rule.crossed_vertex()  # eq. (34)
    assert rule.speed == S
    feed(rule, [{}])  # both leave the view: no increase beyond S after (34)
    assert rule.speed == S


def test_lower_index_reaches_the_common_vertex_first():
    """Theorem 3 on two point robots approaching one vertex at equal times."""
    k_eps = epsilons(2)
    pos = {0: np.array([-1.0, 0.0]), 1: np.array([0.0, -1.0])}
    heading = {0: np.array([1.0, 0.0]), 1: np.array([0.0, 1.0])}
    rules = {i: CollisionRule(S, k_eps[i]) for i in (0, 1)}
    arrival = {}
    for tick in range(3000):
        for i in (0, 1):
            if i in arrival:
                continue
            j = 1 - i
            d = pos[j] - pos[i]
            beta = math.atan2(d[1], d[0]) - math.atan2(heading[i][1], heading[i][0])
            visible = np.hypot(*d) < 1.5 and abs(math.remainder(beta, 2 * math.pi)) < 1.05
            speed = rules[i].update({j: beta} if visible else {})
            pos[i] = pos[i] + heading[i] * speed * 0.02
            if np.dot(pos[i], heading[i]) >= 0.0:
                arrival[i] = tick
        if len(arrival) == 2:
            break
    assert arrival[0] < arrival[1]
    gap_s = (arrival[1] - arrival[0]) * 0.02
    assert gap_s * S > 0.15  # robot 1 arrives over a robot diameter later


def test_bearing_sensor_range_fov_and_line_of_sight():
    poses = [Pose2D(0, 0, 0), Pose2D(0.5, 0.2, 0), Pose2D(0.5, -0.5, 0),
             Pose2D(-0.5, 0, 0), Pose2D(1.5, 0, 0)]
    wall = WallSegment((0.3, -0.6), (0.3, -0.3))
    sim = Simulation(world_spec(poses, walls=[wall]))
    sim.step()
    seen = BearingSensor(sim).read()
    assert set(seen[0]) == {1}  # r2 behind the wall, r3 behind, r4 beyond 1 m
    assert seen[0][1] == pytest.approx(math.atan2(0.2, 0.5), abs=1e-3)
    assert seen[3] == {0: pytest.approx(0.0, abs=1e-3)}
    assert seen[1] == {} and seen[4] == {}
