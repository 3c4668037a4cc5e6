"""Passing a robot that stopped on its lane (ours): the robot sees it with its own
senses, the stations hold the opposite lane, and it passes there
(algorithms/exploration/explorer.py, algorithms/navigation/navigator.py,
mjswarm/experiments/stations.py)."""

from __future__ import annotations

import math

import pytest

from algorithms.collision import CollisionRule
from algorithms.exploration.entry import VertexStations
from algorithms.exploration.passing import PASS_AFTER_S, PASS_STEADY_M, PassRequest
from algorithms.exploration.explorer import Explorer
from algorithms.navigation import NavEvent, Navigator, NavigatorState
from algorithms.navigation.navigator import PASS_MARGIN_M
from algorithms.robot import Detection
from mjswarm.arena import load_arena
from mjswarm.arena.geometry import (LANE_OFFSET_M, SPOKE_INNER_RADIUS_M, VERTEX_CLEAR_RADIUS_M,
                                    vertex_fans)
from mjswarm.core.simulation import Simulation
from mjswarm.core.world import Pose2D, world_spec
from mjswarm.experiments.embodied import EmbodiedConfig
from mjswarm.experiments.exploration import EmbodiedExploration
from mjswarm.experiments.faults import parse_fault
from mjswarm.experiments.minds import make_minds
from mjswarm.worlds.navigation import calibration, conventions

DT_S = 0.02


def explorer() -> Explorer:
    geometry = Simulation(world_spec([Pose2D(0.0, 0.0)])).geometry
    robot = Explorer(make_minds("incidence-dfs", 1)[0], calibration(geometry),
                     conventions(geometry), 0.15, CollisionRule(0.15, 1e-6, dt=DT_S),
                     control_dt_s=DT_S)
    robot.nav.state = NavigatorState.ON_EDGE  # on its lane
    return robot


def asks(robot: Explorer, seconds: float, fronts, detections=()) -> float | None:
    """Stand ``seconds`` on its lane with the front IR reading ``fronts(t)`` (m); when (s)
    it asked to pass, or None."""
    for tick in range(round(seconds / DT_S)):
        t = tick * DT_S
        seen = {j: d for j, d in enumerate(detections)}
        if isinstance(robot.body_watch.watch(t, fronts(t), True, seen), PassRequest):
            return t
    return None


def test_a_steady_silent_body_ahead_is_passed_after_the_wait():
    assert asks(explorer(), PASS_AFTER_S + 1.0, lambda t: 0.06) == pytest.approx(
        PASS_AFTER_S, abs=DT_S)


def test_a_body_that_moves_or_answers_on_the_radio_is_not_passed():
    moving = asks(explorer(), 3 * PASS_AFTER_S, lambda t: 0.02 + (t % 4.0) * PASS_STEADY_M)
    assert moving is None  # it shifts by more than PASS_STEADY_M every few seconds
    alive = asks(explorer(), 2 * PASS_AFTER_S, lambda t: 0.06,
                 detections=[Detection(0.06 + 0.15, math.radians(3.0))])
    assert alive is None
    beside = asks(explorer(), 2 * PASS_AFTER_S, lambda t: 0.06,
                  detections=[Detection(0.2, math.radians(80.0))])  # a neighbour aside
    assert beside == pytest.approx(PASS_AFTER_S, abs=DT_S)
    assert asks(explorer(), 2 * PASS_AFTER_S, lambda t: math.nan) is None  # nothing there


def test_a_held_lane_is_granted_to_nobody_and_closes_no_cycle():
    stations = VertexStations(vertex_fans(load_arena("arena2")))
    stations.lanes.request(9, "v4", "v3")  # robot 9 passes a body on the lane v4 -> v3
    stations.occupy(0, "v4")
    stations.occupy(1, "v3")
    stations.request(0, "v4", "v3", 1.0)  # a swap of the edge's ends: a closed cycle ...
    stations.request(1, "v3", "v4", 2.0)
    assert stations.grant() == []  # ... but one of its lanes is held
    stations.lanes.done(9)
    assert sorted(stations.grant()) == [(0, "v3"), (1, "v4")]


def test_a_pass_next_to_a_vertex_steps_across_with_its_sensor_on_the_incoming_spoke():
    """The nearest a body on its lane can stand to a vertex that stays open is
    ``VERTEX_CLEAR_RADIUS_M`` from its centre (nearer, the station closes the vertex). A
    robot that passes it on the opposite lane and steps square onto the centre line there
    (``Navigator._square_clearance_m`` past the body) keeps ``PASS_MARGIN_M`` from the
    body and still has its centre sensor at least a centimetre outside the incoming
    spoke's inner end, so that it finds and follows that spoke to the centre (stepping
    across a diameter and the margin past the body left it 1.1 cm inside the inner end)."""
    geometry = Simulation(world_spec([Pose2D(0.0, 0.0)])).geometry
    nav = Navigator(calibration(geometry), conventions(geometry), 0.0, 0.1)
    r, offset = geometry.body_radius_m, LANE_OFFSET_M
    body_along_m = math.sqrt(VERTEX_CLEAR_RADIUS_M**2 - offset**2)  # from the vertex centre
    robot_along_m = body_along_m - nav._square_clearance_m
    assert math.hypot(nav._square_clearance_m, offset) >= 2.0 * r + PASS_MARGIN_M - 1e-12
    sensor_m = robot_along_m - geometry.line_sensor_ahead_m
    assert sensor_m >= SPOKE_INNER_RADIUS_M + 0.01, sensor_m


@pytest.mark.parametrize("dies_at_s", [pytest.param(25.6, marks=pytest.mark.slow), 90,
                                       pytest.param(91, marks=pytest.mark.slow)])
def test_a_robot_passes_a_dead_one_and_the_team_completes_the_true_map(dies_at_s):
    """``arena2``, 4 robots: R1 fails at 90 s at the start of its corridor from v3 to v4;
    the robot sent along that edge next passes it (without passing, the run stalls). At
    91 s it stands 0.33 m along that 0.6 m edge, and the opposite lane ends 0.11 m past
    it, before the passer is clear of it: the passer drives on and steps square onto the
    centre line (``Navigator._lane_ended``); a diagonal shift would touch the body. At 25.6 s it stands on the first edge, 0.255 m from ``v2``'s centre
    (just beyond the radius that closes the vertex): stepping across a diameter and a
    margin past it would leave the passer's centre sensor beyond the incoming spoke, and
    it would stop 15 cm off ``v2`` (``Navigator._square_clearance_m``)."""
    spec = load_arena("arena2")
    config = EmbodiedConfig(faults=[parse_fault(f"robot:1@{dies_at_s}")])
    run = EmbodiedExploration(spec, make_minds("incidence-dfs", 4, 0), config, 0)
    result = run.run()
    assert result.completed and result.map_correct, result.ended_because
    assert result.collisions == 0
    passes = [i for i, robot in enumerate(run.robots)
              if any(e.kind is NavEvent.PASSED for e in robot.nav.events)]
    assert passes and 0 not in passes
