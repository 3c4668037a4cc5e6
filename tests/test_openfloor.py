"""Open-floor worlds and velocity tracking: the embodied robot follows planar velocity
commands like the kinematic unicycle does, and robots can be added and removed."""

from __future__ import annotations

import math

import numpy as np
import pytest

from algorithms.motion import track_velocity
from mjswarm.errors import MjswarmError
from mjswarm.openfloor import EmbodiedFloor, PointWorld, spread


def test_track_velocity_turns_first_and_never_reverses():
    assert track_velocity(0.0, (0.1, 0.0), 0.2, 2.0) == pytest.approx((0.1, 0.0))
    v, w = track_velocity(0.0, (-0.1, 0.0), 0.2, 2.0)  # behind: turn on the spot
    assert v == 0.0 and abs(w) == 2.0
    v, w = track_velocity(0.0, (0.0, 0.5), 0.2, 2.0)
    assert v == pytest.approx(0.0, abs=1e-12) and w == 2.0


@pytest.mark.parametrize("world", [PointWorld, EmbodiedFloor])
def test_worlds_reach_a_goal_by_velocity_commands(world):
    w = world([(0.0, 0.0), (1.0, 1.0)])
    goal = np.array([0.6, -0.4])
    for _ in range(200):
        sensed = w.sense()
        command = np.zeros((2, 2))
        delta = goal - sensed[0, :2]
        command[0] = delta / max(1.0, np.linalg.norm(delta) / 0.1)
        w.step(command, 0.1)
    assert np.linalg.norm(w.true_positions()[0] - goal) < 0.03
    assert np.linalg.norm(w.true_positions()[1] - (1.0, 1.0)) < 1e-3  # idle robot stays


def test_embodied_and_point_trajectories_agree():
    """Same commands, same start: the MuJoCo robot ends within a few cm of the point."""
    ends = []
    for world in (PointWorld, EmbodiedFloor):
        w = world([(0.0, 0.0)])
        for k in range(100):
            angle = 0.02 * k
            w.step(np.array([[0.1 * math.cos(angle), 0.1 * math.sin(angle)]]), 0.1)
        ends.append(w.true_positions()[0].copy())
    assert np.linalg.norm(ends[0] - ends[1]) < 0.05


def test_add_and_remove_robots():
    w = EmbodiedFloor([(0.0, 0.0), (0.5, 0.0)], present=[True, False])
    assert not w.present[1] and w.true_positions()[1, 1] < -10
    w.place(1, (0.5, 0.5))
    w.step(np.zeros((2, 2)), 0.2)
    assert w.present[1] and np.linalg.norm(w.true_positions()[1] - (0.5, 0.5)) < 0.01
    w.place(0, None)
    assert not w.present[0]


def test_spread_and_bad_parameters():
    points = spread(10, 1.0, seed=1)
    assert len(points) == 10 and all(math.hypot(*p) <= 1.0 for p in points)
    with pytest.raises(MjswarmError, match="cannot place"):
        spread(200, 0.3, seed=1)
    with pytest.raises(MjswarmError, match="at least one robot"):
        PointWorld([])
