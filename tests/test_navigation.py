"""Sensor-only navigation on shipped arenas, checked against ground truth.

One robot drives a scripted closed walk that traverses every edge in both directions
(an Eulerian circuit of the directed arena graph). At each vertex the script picks,
among the incidence angles the robot *measured*, the one nearest the true direction of
the next edge (what an exploration strategy would do with its own angles), so the robot's
own sensing decides where it goes; ground truth only checks the outcome.
"""

from __future__ import annotations

import itertools
import math

import networkx as nx
import numpy as np
import pytest

from algorithms.navigation import Navigator, NavigatorState
from algorithms.navigation.driving import Navigating
from algorithms.navigation.motions import Turn
from mjswarm.arena import incidence_angle, lane_strips, load_arena
from mjswarm.arena.builder import arena_world_spec
from mjswarm.worlds.loop import Loop
from mjswarm.worlds.navigation import calibration, conventions
from mjswarm.core.simulation import Simulation
from mjswarm.worlds.sparkworld import SparkWorld
from mjswarm.core.world import Pose2D

SPEED_M_S = 0.1
ARRIVAL_TOLERANCE_M = 0.02
ANGLE_TOLERANCE_DEG = 4.0
MAX_TICKS_PER_LEG = 50 * 120  # two simulated minutes


def angle_error_deg(a: float, b: float) -> float:
    return abs(math.degrees(math.remainder(a - b, 2.0 * math.pi)))


def run_walk(name: str, legs: int | None = None) -> dict:
    """Drive the covering walk of arena ``name``; return what was measured per vertex."""
    spec = load_arena(name)
    graph = spec.graph()
    walk = [spec.root] + [v for _, v in nx.eulerian_circuit(graph.to_directed(), source=spec.root)]
    walk = walk[: legs + 1] if legs else walk
    x, y = spec.vertices[spec.root]
    sim = Simulation(arena_world_spec(spec, [Pose2D(x, y, 0.0)]))
    nav = Navigator(calibration(sim.geometry), conventions(sim.geometry), 0.0, SPEED_M_S)
    driver = Loop(SparkWorld(sim), {0: Navigating(nav)})
    nav.begin_at_vertex()
    record = {"angle_errors": [], "arrival_errors": [], "edge_times": [], "spec": spec}

    def run_until_at_vertex() -> float:
        on_edge_ticks = 0
        for _ in range(MAX_TICKS_PER_LEG):
            if nav.state is NavigatorState.AT_VERTEX:
                return on_edge_ticks * sim.control_dt_s
            assert nav.state is not NavigatorState.LOST, nav.events[-1]
            on_edge_ticks += nav.state is NavigatorState.ON_EDGE
            driver.step()
        raise AssertionError(f"robot did not reach a vertex; events {nav.events[-3:]}")

    for here, there in itertools.pairwise(walk):
        record["edge_times"].append(run_until_at_vertex())
        pose = sim.poses()[0]
        record["arrival_errors"].append(math.dist(pose[:2], spec.vertices[here]))
        truth = sorted(incidence_angle(spec, here, w) for w in graph[here])
        measured = nav.edge_angles
        assert len(measured) == len(truth), (here, measured, truth)
        for t in truth:
            record["angle_errors"].append(min(angle_error_deg(m, t) for m in measured))
        wanted = incidence_angle(spec, here, there)
        nav.depart(min(measured, key=lambda a: angle_error_deg(a, wanted)))
    record["edge_times"].append(run_until_at_vertex())
    pose = sim.poses()[0]
    record["arrival_errors"].append(math.dist(pose[:2], spec.vertices[walk[-1]]))
    record["walk"] = walk
    return record


@pytest.mark.parametrize("name", ["arena1", "fig9"])
def test_covering_walk_reaches_every_vertex(name):
    record = run_walk(name)
    spec = record["spec"]
    assert len(record["walk"]) - 1 == 2 * len(spec.edges)  # every edge, both ways
    assert max(record["arrival_errors"]) < ARRIVAL_TOLERANCE_M
    assert max(record["angle_errors"]) < ANGLE_TOLERANCE_DEG


@pytest.mark.parametrize("name", ["fig9", "lattice:2x3:0.9"])
def test_time_per_edge_matches_length_and_speed(name):
    """Time spent following a lane = the lane strip's length / commanded speed, edge by
    edge (the robot picks the strip up where it starts and leaves it where it ends)."""
    record = run_walk(name, legs=4)
    lanes = {strip.travel: math.dist(strip.start, strip.end)
             for strip in lane_strips(record["spec"])}
    walk = record["walk"]
    for (u, v), t in zip(itertools.pairwise(walk), record["edge_times"][1:]):
        assert t * SPEED_M_S == pytest.approx(lanes[(u, v)], abs=0.03)


def test_measured_angles_are_in_the_robots_own_frame():
    """A robot whose compass says 90 degrees where the world says 0 measures everything
    rotated by 90 degrees: angles are the robot's, not the world's."""
    spec = load_arena("fig9")
    x, y = spec.vertices[spec.root]
    sim = Simulation(arena_world_spec(spec, [Pose2D(x, y, 0.0)]))
    nav = Navigator(calibration(sim.geometry), conventions(sim.geometry), math.pi / 2, SPEED_M_S)
    driver = Loop(SparkWorld(sim), {0: Navigating(nav)})
    nav.begin_at_vertex()
    while nav.state is not NavigatorState.AT_VERTEX:
        driver.step()
    truth = [incidence_angle(spec, "v1", w) + math.pi / 2 for w in ("v2", "v3")]
    errors = [min(angle_error_deg(m, t) for m in nav.edge_angles) for t in truth]
    assert np.max(errors) < 3.0


@pytest.mark.parametrize("arena, drive_m", [
    *(("lattice:2x2:1.5", d) for d in ("turned", 0.05, 0.3, "corridor", 0.7, 1.2, math.inf)),
    ("hex:2x2", "corridor")])
def test_a_robot_turned_back_part_way_arrives_where_it_left_by_the_edge_it_left_along(
        arena, drive_m):
    """Rule 6's walks back (:meth:`Navigator.turn_back`): turned back while leaving (having
    only turned on its centre: it scans there and never drives off it; or 5 cm out),
    short of its corridor (0.3 m), just in its corridor (without room for a U-turn: back
    along the spoke it left by, on a vertex with edges 90 and 120 degrees apart), on its
    lane (0.7 m, and 1.2 m, past the wall's end at the far vertex of a 1.5 m edge) or
    arriving there (a second into its arrival), the robot is back on the centre it left,
    measures the same edges, and reports the edge it left along as the one it came by.
    Short of room for a U-turn it never goes farther from the centre than it was when it
    turned, or than the point of its spoke from which it finds the spoke facing the centre
    (clear of a robot waiting where the opposite lane's wall ends)."""
    spec = load_arena(arena)
    x, y = spec.vertices[spec.root]
    sim = Simulation(arena_world_spec(spec, [Pose2D(x, y, 0.0)]))
    nav = Navigator(calibration(sim.geometry), conventions(sim.geometry), 0.0, SPEED_M_S)
    driver = Loop(SparkWorld(sim), {0: Navigating(nav)})
    nav.begin_at_vertex()
    while nav.state is not NavigatorState.AT_VERTEX:
        driver.step()
    first = list(nav.edge_angles)
    assert len(first) == 2
    nav.depart(first[0])
    start = nav.odometry.distance_m
    if drive_m == "corridor":
        while not nav.in_corridor:
            driver.step()
        assert not nav.room_to_turn
    while drive_m == "turned" and isinstance(nav._plan[0][0], Turn):
        driver.step()
    while (drive_m not in ("corridor", "turned") and nav.odometry.distance_m - start < drive_m
           and nav.state is not NavigatorState.ARRIVING):
        driver.step()
    for _ in range(50 if nav.state is NavigatorState.ARRIVING else 0):
        driver.step()
        assert nav.state in (NavigatorState.LEAVING, NavigatorState.ON_EDGE,
                             NavigatorState.ARRIVING), nav.events[-1]
    short_of_room = not nav.room_to_turn and nav.state is not NavigatorState.ARRIVING
    turned_at_m = math.dist(sim.poses()[0][:2], (x, y))
    spoke_point_m = (nav.conv.spoke_inner_radius_m + nav.conv.strip_width_m
                     + nav.cal.line_ahead_m)
    farthest_m = 0.0
    nav.turn_back()
    for _ in range(MAX_TICKS_PER_LEG):
        if nav.state is NavigatorState.AT_VERTEX:
            break
        assert nav.state is not NavigatorState.LOST, nav.events[-1]
        driver.step()
        farthest_m = max(farthest_m, math.dist(sim.poses()[0][:2], (x, y)))
    else:
        raise AssertionError(f"not back at the vertex; events {nav.events[-3:]}")
    if drive_m == "turned":
        assert farthest_m < nav.conv.strip_width_m / 2.0, farthest_m
    elif short_of_room:
        assert farthest_m <= max(turned_at_m, spoke_point_m) + 0.01, (farthest_m, turned_at_m)
    assert math.dist(sim.poses()[0][:2], (x, y)) < ARRIVAL_TOLERANCE_M
    assert angle_error_deg(nav.arrived_angle, first[0]) < ANGLE_TOLERANCE_DEG
    assert len(nav.edge_angles) == len(first)
    assert max(min(angle_error_deg(a, b) for a in nav.edge_angles) for b in first) < ANGLE_TOLERANCE_DEG


def test_leaving_a_vertex_takes_its_own_lane_not_the_corner_of_a_neighbours():
    """Edges 45 degrees apart (``wheel:4@8`` at ``r3``): where the lane towards ``r0``
    starts, the end of the lane arriving from ``c`` is within a side sensor's reach. A
    robot leaving towards ``r0`` whose left sensor finds that corner keeps seeking
    (a robot that followed it would be lost); its centre sensor on its own lane ends
    the seek. Positions in the true frame, the robot's odometry set to it."""
    spec = load_arena("wheel:4@8")
    sim = Simulation(arena_world_spec(spec, [Pose2D(*spec.vertices["r3"], 0.0)]))
    cal, conv = calibration(sim.geometry), conventions(sim.geometry)
    angle = incidence_angle(spec, "r3", "r0")
    nav = Navigator(cal, conv, angle, SPEED_M_S)
    nav.odometry.x, nav.odometry.y = spec.vertices["r3"]
    nav.edge_angles = [incidence_angle(spec, "r3", w) for w in ("r0", "c", "r2")]
    ours = nav._own_lane(angle)
    strips = {s.travel: s for s in lane_strips(spec)}
    own, theirs = strips[("r3", "r0")], strips[("c", "r3")]
    u = np.array([math.cos(angle), math.sin(angle)])
    n = np.array([-u[1], u[0]])

    def at(sensor_xy, side_m):  # the pose that puts the sensor ``side_m`` left there
        xy = np.asarray(sensor_xy) - cal.line_ahead_m * u - side_m * n
        nav.odometry.x, nav.odometry.y = xy
        return nav.odometry

    corner = np.asarray(theirs.end) - 0.001 * _unit(theirs.start, theirs.end)
    assert ours(at(corner, cal.line_spacing_m), (True, False, False)) is False
    start = np.asarray(own.start) + 0.001 * u
    assert ours(at(start, 0.0), (False, True, False)) is True
    assert ours(at(start, 0.0), (True, True, False)) is True


@pytest.mark.parametrize("across_mm", [-12.0, 0.0, 12.0])
def test_leaving_a_vertex_does_not_take_a_neighbours_spoke_for_its_lane(across_mm):
    """Edges 45 degrees apart (``wheel:4@8`` at ``r2``): leaving towards ``c``, the right
    sensor ends the sidestep a few millimetres beside the outer end of the spoke towards
    ``r1``, 45 degrees to the left. A sensor on that spoke (anywhere across its 30 mm
    strip) is not on the lane sought (with slip 0.05 a robot that took it for its lane
    would follow it off the vertex and be lost); a sensor on the lane's start is."""
    spec = load_arena("wheel:4@8")
    sim = Simulation(arena_world_spec(spec, [Pose2D(*spec.vertices["r2"], 0.0)]))
    cal, conv = calibration(sim.geometry), conventions(sim.geometry)
    centre = np.asarray(spec.vertices["r2"])
    angle = incidence_angle(spec, "r2", "c")
    nav = Navigator(cal, conv, angle, SPEED_M_S)
    nav.odometry.x, nav.odometry.y = centre
    nav.edge_angles = [incidence_angle(spec, "r2", w) for w in ("c", "r1", "r3")]
    ours = nav._own_lane(angle)
    u = np.array([math.cos(angle), math.sin(angle)])
    n = np.array([-u[1], u[0]])

    def at(sensor_xy, side_m):  # the pose, heading along the edge, that puts the sensor there
        xy = np.asarray(sensor_xy) - cal.line_ahead_m * u - side_m * n
        nav.odometry.x, nav.odometry.y = xy
        return nav.odometry

    spoke = incidence_angle(spec, "r2", "r1")
    along, normal = np.array([math.cos(spoke), math.sin(spoke)]), np.array([-math.sin(spoke), math.cos(spoke)])
    on_spoke = centre + (conv.spoke_radius_m - 0.002) * along + across_mm / 1000.0 * normal
    assert ours(at(on_spoke, -cal.line_spacing_m), (False, False, True)) is False
    own = {s.travel: s for s in lane_strips(spec)}[("r2", "c")]
    start = np.asarray(own.start) + 0.001 * u
    assert ours(at(start, 0.0), (False, True, False)) is True


def _unit(p, q):
    d = np.asarray(q, float) - np.asarray(p, float)
    return d / np.linalg.norm(d)
