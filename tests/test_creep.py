"""The creep (ours): a robot the speed rule has held still on its lane for a long
time creeps on, guarded by its front IR; and a robot waiting at its wall's end for the
vertex ahead backs off (algorithms/exploration/explorer.py)."""

from __future__ import annotations

import math

import pytest

from algorithms.collision import CollisionRule
from algorithms.exploration.explorer import (
    CREEP_AFTER_S,
    CREEP_GUARD_M,
    CREEP_M_S,
    WAIT_BACKOFF_M,
    Explorer,
)
from mjswarm.core.simulation import Simulation
from mjswarm.core.world import Pose2D, world_spec
from mjswarm.experiments.minds import make_minds
from mjswarm.experiments.stress import StressRun, passed
from mjswarm.worlds.navigation import calibration, conventions

DT_S = 0.02


@pytest.fixture(scope="module")
def robot() -> Explorer:
    geometry = Simulation(world_spec([Pose2D(0.0, 0.0)])).geometry
    return Explorer(make_minds("incidence-dfs", 1)[0], calibration(geometry),
                    conventions(geometry), 0.15, CollisionRule(0.15, 1e-6, dt=DT_S),
                    control_dt_s=DT_S)


def held(robot: Explorer, seconds: float, front_m: float) -> list[float]:
    """The speeds (m/s) of ``seconds`` of ticks in which the rule says stop."""
    return [robot._creep(0.0, (math.nan, front_m, math.nan))
            for _ in range(round(seconds / DT_S))]


def test_a_long_stop_creeps_on_while_the_front_is_clear_and_stops_for_a_body(robot):
    robot._creep(0.15, None)  # moving: the count starts anew
    speeds = held(robot, CREEP_AFTER_S + 1.0, math.nan)
    first = speeds.index(CREEP_M_S)
    assert set(speeds[:first]) == {0.0} and set(speeds[first:]) == {CREEP_M_S}
    assert first * DT_S == pytest.approx(CREEP_AFTER_S, abs=DT_S)
    assert set(held(robot, 1.0, CREEP_GUARD_M - 0.01)) == {0.0}  # a body ahead
    assert set(held(robot, 1.0, CREEP_GUARD_M + 0.01)) == {CREEP_M_S}
    assert robot._creep(0.1, None) == 0.1  # the rule lets it go: its own speed
    assert held(robot, 1.0, math.nan)[-1] == 0.0  # and a new stop waits again


@pytest.mark.slow
def test_the_phantom_wait_of_a_dense_team_ends():
    """``lattice:6x6``, 8 robots, 0.15 m/s, seed 1 stalls without the creep: a robot on its
    lane is held by the rule for one standing on the vertex beyond the next, which waits
    for the vertex the first holds (stations' docstring)."""
    result = StressRun("lattice:6x6", 8, 0.15, 1).run(max_sim_time_s=1500.0)
    assert passed(result), (result.ended_because, result.collisions, result.stopped_robots)


def test_a_robot_waiting_at_its_wall_end_backs_off_its_stopping_overshoot(robot):
    """It backs ``WAIT_BACKOFF_M`` from where it began to wait, slowly, then stands; a new
    wait starts from where that one begins."""
    odometry = robot.nav.odometry
    robot._wait_from_m, odometry.distance_m = None, 2.0
    assert robot._back_off() == -CREEP_M_S
    odometry.distance_m = 2.0 + 0.01  # the stop's overshoot
    assert robot._back_off() == -CREEP_M_S
    odometry.distance_m = 2.0 - WAIT_BACKOFF_M + 0.001
    assert robot._back_off() == -CREEP_M_S
    odometry.distance_m = 2.0 - WAIT_BACKOFF_M
    assert robot._back_off() == 0.0
    robot._wait_from_m, odometry.distance_m = None, 5.0
    assert robot._back_off() == -CREEP_M_S
