"""Open-floor worlds and velocity tracking: the embodied robot follows planar velocity
commands like the kinematic unicycle does, and robots can be added and removed."""

from __future__ import annotations

import math

import numpy as np
import pytest

from algorithms.motion import track_velocity
from algorithms.robot import Command, Controller, Observation
from mjswarm.errors import MjswarmError
from mjswarm.worlds.loop import Loop
from mjswarm.worlds.openfloor import EmbodiedFloor, PointWorld, spread


def test_track_velocity_turns_first_and_never_reverses():
    assert track_velocity(0.0, (0.1, 0.0), 0.2, 2.0) == pytest.approx((0.1, 0.0))
    v, w = track_velocity(0.0, (-0.1, 0.0), 0.2, 2.0)  # behind: turn on the spot
    assert v == 0.0 and abs(w) == 2.0
    v, w = track_velocity(0.0, (0.0, 0.5), 0.2, 2.0)
    assert v == pytest.approx(0.0, abs=1e-12) and w == 2.0


class GoTo(Controller):
    """Heads for ``goal`` (m) at up to 0.1 m/s from its own positioning sensor."""

    def __init__(self, goal) -> None:
        self.goal = np.asarray(goal, float)

    def step(self, observation: Observation) -> Command:
        delta = self.goal - observation.pose[:2]
        return Command(velocity_m_s=tuple(delta / max(1.0, np.linalg.norm(delta) / 0.1)))


class Fixed(Controller):
    """Commands the planar velocity ``velocity(tick)`` (m/s)."""

    def __init__(self, velocity) -> None:
        self.velocity, self.tick = velocity, 0

    def step(self, observation: Observation) -> Command:
        self.tick += 1
        return Command(velocity_m_s=self.velocity(self.tick - 1))


@pytest.mark.parametrize("world", [PointWorld, EmbodiedFloor])
def test_worlds_reach_a_goal_by_velocity_commands(world):
    w = world([(0.0, 0.0), (1.0, 1.0)])
    Loop(w, {0: GoTo((0.6, -0.4)), 1: Fixed(lambda t: (0.0, 0.0))}).run(max_ticks=200)
    assert np.linalg.norm(w.true_positions()[0] - (0.6, -0.4)) < 0.03
    assert np.linalg.norm(w.true_positions()[1] - (1.0, 1.0)) < 1e-3  # idle robot stays


def test_embodied_and_point_trajectories_agree():
    """Same commands, same start: the MuJoCo robot ends within a few cm of the point."""
    ends = []
    for world in (PointWorld, EmbodiedFloor):
        w = world([(0.0, 0.0)])
        arc = Fixed(lambda k: (0.1 * math.cos(0.02 * k), 0.1 * math.sin(0.02 * k)))
        Loop(w, {0: arc}).run(max_ticks=100)
        ends.append(w.true_positions()[0].copy())
    assert np.linalg.norm(ends[0] - ends[1]) < 0.05


def test_add_and_remove_robots():
    w = EmbodiedFloor([(0.0, 0.0), (0.5, 0.0)], present=[True, False])
    assert not w.present[1] and w.true_positions()[1, 1] < -10
    loop = Loop(w, {0: Fixed(lambda t: (0.0, 0.0)), 1: Fixed(lambda t: (0.0, 0.0))})
    assert w.active() == [0]
    w.place(1, (0.5, 0.5))
    loop.run(max_ticks=2)
    assert w.present[1] and np.linalg.norm(w.true_positions()[1] - (0.5, 0.5)) < 0.01
    w.place(0, None)
    assert not w.present[0] and w.active() == [1]


def test_spread_and_bad_parameters():
    points = spread(10, 1.0, seed=1)
    assert len(points) == 10 and all(math.hypot(*p) <= 1.0 for p in points)
    with pytest.raises(MjswarmError, match="cannot place"):
        spread(200, 0.3, seed=1)
    with pytest.raises(MjswarmError, match="at least one robot"):
        PointWorld([])


class _Drive(Controller):
    """Drives straight ahead at 0.1 m/s, or at a planar velocity along +x."""

    def __init__(self, planar: bool = False) -> None:
        self.planar = planar

    def step(self, observation: Observation) -> Command:
        return Command(velocity_m_s=(0.1, 0.0)) if self.planar else Command(0.1, 0.0)


@pytest.mark.parametrize("world", [PointWorld, EmbodiedFloor])
def test_a_control_period_is_integrated_exactly(world):
    """With patrol's 0.15 s tick both worlds drive exactly 0.15 s per tick (ten ticks at
    0.1 m/s end at 1.5 s and, but for the motors' ramp, at x = 0.150 m)."""
    w = world([(0.0, 0.0)], control_dt_s=0.15)
    Loop(w, {0: _Drive()}).run(max_ticks=10)
    assert w.time_s == pytest.approx(1.5)
    expected = 0.150 if world is PointWorld else 0.1439  # the motors' 0.05 s speed ramp
    assert w.true_poses()[0, 0] == pytest.approx(expected, abs=5e-4)


@pytest.mark.parametrize("make, words", [
    (lambda: PointWorld([(0.0, 0.0)], dt_s=0.02, control_dt_s=0.15), "integration step"),
    (lambda: EmbodiedFloor([(0.0, 0.0)], control_dt_s=0.015), "physics step 0.002"),
])
def test_a_period_that_is_no_whole_number_of_steps_is_refused(make, words):
    with pytest.raises(MjswarmError, match=words):
        make()


def test_the_tracker_steers_by_the_one_reading_the_robot_observed():
    """One positioning reading per tick (it was drawn twice: the tracker used another
    noisy reading than the controller saw)."""
    w = PointWorld([(0.0, 0.0)], position_noise_m=0.01, heading_noise_rad=0.05)
    readings = []
    sense = w.sense
    w.sense = lambda: readings.append(1) or sense()
    Loop(w, {0: _Drive(planar=True)}).run(max_ticks=20)
    assert len(readings) == 20
