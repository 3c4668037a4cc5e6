"""The kinematic tier: fidelity to the dynamic tier, the contact rule,
determinism and bad input. The covering walk of fig9 and the shipped figures (arena1 with
two robots, the main job) in both tiers are slow; the lap of arena1 is their fast
representative."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from scipy.spatial import cKDTree

from mjswarm.arena import load_arena
from mjswarm.cli import main
from mjswarm.core.kinematic import OVERLAP_TOL_M
from mjswarm.core.simulation import Simulation
from mjswarm.core.world import COLLISION_GROUP, Pose2D, WallSegment, world_spec
from mjswarm.errors import MjswarmError
from mjswarm.experiments.exploration import EmbodiedConfig, EmbodiedExploration
from mjswarm.experiments.minds import make_minds
from mjswarm.worlds.loop import LoopFunctions

#: how far apart (m) the two tiers' paths of one robot may lie (Hausdorff distance);
#: measured 0.0125 m on arena1 and 0.0154 m on fig9
PATH_BOUND_M = 0.03


class Trail(LoopFunctions):
    """Every robot's true position after every tick."""

    def __init__(self) -> None:
        self.xy: list[np.ndarray] = []

    def after_step(self, loop) -> None:
        self.xy.append(loop.world.true_poses()[:, :2].copy())


def explore(arena: str, robots: int, physics: str):
    run = EmbodiedExploration(load_arena(arena), make_minds("incidence-dfs", robots),
                              EmbodiedConfig(physics=physics), 0)
    trail = Trail()
    run.loop.add(trail)
    return run.run(), np.array(trail.xy)


def hausdorff_m(a: np.ndarray, b: np.ndarray) -> float:
    return max(cKDTree(a).query(b)[0].max(), cKDTree(b).query(a)[0].max())


def on_arena(path: np.ndarray, spec) -> np.ndarray:
    """The stretch of a path on the arena (the depot lies below it)."""
    ys = [y for _, y in spec.vertices.values()]
    return path[path[:, 1] >= min(ys) - 0.2]


def agree(arena: str, robots: int) -> None:
    (dyn, a), (kin, b) = explore(arena, robots, "dynamic"), explore(arena, robots, "kinematic")
    assert dyn.completed and kin.completed and kin.map_correct
    assert (kin.makespan, kin.total_traversals) == (dyn.makespan, dyn.total_traversals)
    assert kin.collisions == dyn.collisions == 0
    assert kin.sim_time_s == pytest.approx(dyn.sim_time_s, rel=0.05)
    spec = load_arena(arena)
    for i in range(robots):
        assert hausdorff_m(on_arena(a[:, i], spec), on_arena(b[:, i], spec)) < PATH_BOUND_M


def test_a_lap_of_arena1_agrees_with_the_dynamic_tier():
    """One robot walks every edge of arena1: same walk, paths within PATH_BOUND_M."""
    agree("arena1", 1)


@pytest.mark.slow
def test_shipped_arena1_figures_are_equal_in_both_tiers():
    agree("arena1", 2)


@pytest.mark.slow
def test_a_covering_walk_of_fig9_agrees_with_the_dynamic_tier():
    agree("fig9", 1)


@pytest.mark.slow
def test_the_main_job_is_equal_in_both_tiers():
    agree("arena2", 4)


# ---------------------------------------------------------------------------- contacts
def two_robots(gap_m: float, physics: str = "kinematic") -> Simulation:
    """Two robots on one line, facing each other, ``gap_m`` between their centres."""
    return Simulation(world_spec([Pose2D(0.0, 0.0, 0.0), Pose2D(gap_m, 0.0, math.pi)]),
                      physics=physics)


def footprint_gap_m(sim: Simulation) -> float:
    drive = sim._drive
    c = drive.footprints(sim.poses())
    return float(np.hypot(*(c[0] - c[1])) - 2.0 * drive.footprint_radius_m)


def test_robots_driving_into_each_other_stop_touching_and_count_one_event():
    sim = two_robots(0.5)
    gaps = []
    for _ in range(200):  # 4 s at 0.1 m/s each: they would meet after about 1.7 s
        sim.set_velocity(np.array([0.1, 0.1]), np.zeros(2))
        sim.step()
        gaps.append(footprint_gap_m(sim))
    assert min(gaps) >= -OVERLAP_TOL_M
    assert gaps[-1] < 0.01  # they came close: stopped by each other, not before
    assert len(sim.collisions.events) == 1
    before = sim.poses()
    sim.step()
    assert np.array_equal(sim.poses(), before)  # both stand
    assert np.all(sim.readings()["wheel_speed"] == 0.0)
    for _ in range(50):  # backing away is free
        sim.set_velocity(np.array([-0.1, -0.1]), np.zeros(2))
        sim.step()
    assert footprint_gap_m(sim) > 0.05
    assert len(sim.collisions.events) == 1


def test_the_dynamic_tier_counts_the_same_crash():
    """The scenario above has teeth: MuJoCo's contacts see the crash too."""
    sim = two_robots(0.5, "dynamic")
    for _ in range(200):
        sim.set_velocity(np.array([0.1, 0.1]), np.zeros(2))
        sim.step()
    assert len(sim.collisions.events) >= 1


def test_a_robot_driving_into_a_wall_stops_at_it():
    wall = WallSegment((0.4, -1.0), (0.4, 1.0))
    sim = Simulation(world_spec([Pose2D(0.0, 0.0, 0.1)], walls=[wall]), physics="kinematic")
    drive = sim._drive
    face_m = 0.4 - wall.thickness_m / 2.0
    for _ in range(300):
        sim.set_velocity(np.array([0.1]), np.zeros(1))
        sim.step()
        reach = drive.footprints(sim.poses())[0, 0] + drive.footprint_radius_m
        assert reach <= face_m + OVERLAP_TOL_M
    assert reach > face_m - 0.01  # it drove up to the wall
    assert sim.collisions.events == []  # walls are no robot-robot contact


@pytest.mark.parametrize("seed", [0, 1, 2, pytest.param(3, marks=pytest.mark.slow),
                                  pytest.param(4, marks=pytest.mark.slow),
                                  pytest.param(5, marks=pytest.mark.slow)])
def test_no_move_ever_deepens_an_overlap_in_a_random_crowd(seed):
    """Property: 12 robots with random commands in a walled 1.2 m box for 6 s never
    overlap each other or a wall (they start apart)."""
    rng = np.random.default_rng(seed)
    side = 1.2
    walls = [WallSegment(a, b) for a, b in [((0, 0), (side, 0)), ((side, 0), (side, side)),
                                              ((side, side), (0, side)), ((0, side), (0, 0))]]
    poses = [Pose2D(0.2 + 0.27 * (k % 4), 0.25 + 0.35 * (k // 4), rng.uniform(-math.pi, math.pi))
             for k in range(12)]
    sim = Simulation(world_spec(poses, walls=walls), physics="kinematic", seed=seed)
    drive = sim._drive
    r = drive.footprint_radius_m
    for tick in range(300):
        if tick % 25 == 0:
            v, w = rng.uniform(-0.2, 0.2, 12), rng.uniform(-2.0, 2.0, 12)
        sim.set_velocity(v, w)
        sim.step()
        c = drive.footprints(sim.poses())
        d = np.hypot(*(c[:, None] - c[None]).transpose(2, 0, 1))[np.triu_indices(12, 1)]
        assert d.min() >= 2 * r - OVERLAP_TOL_M
        inner = 0.01  # half a wall's thickness
        assert c.min() >= inner + r - OVERLAP_TOL_M and c.max() <= side - inner - r + OVERLAP_TOL_M
    assert sim.collisions.events  # the crowd did bump


def wall_depth(discs, centre, axes, half, radius_m):
    """How far (m) each disc (centres (K, 2), radius ``radius_m``) reaches into its
    rectangle (negative: the gap); one rectangle (centre, unit axes as rows, half sizes)
    per disc. The reference for ``WallGrid``."""
    local = np.abs(np.einsum("kij,kj->ki", axes, discs - centre)) - half
    outside = np.hypot(np.maximum(local[:, 0], 0.0), np.maximum(local[:, 1], 0.0))
    inside = np.minimum(local.max(axis=1), 0.0)
    return radius_m - (outside + inside)


@pytest.mark.parametrize("seed", range(6))
def test_the_wall_grid_finds_every_deeper_wall_overlap(seed):
    """``WallGrid.deeper`` (one compiled pass over a grid of walls) against every wall of
    ``arena2`` by the reference ``wall_depth``: discs scattered over the arena and beyond it,
    each moved a few millimetres, many of them into or out of a wall."""
    from mjswarm.arena.builder import arena_world_spec

    sim = Simulation(arena_world_spec(load_arena("arena2"), [Pose2D(0.0, 0.0, 0.0)]),
                     physics="kinematic")
    grid = sim._drive._walls
    rng = np.random.default_rng(seed)
    centre, axes, half, r = grid.centre, grid.axes, grid.half, grid.radius_m
    near = rng.integers(len(centre), size=4000)  # about a random wall, and anywhere
    local = rng.uniform(-1.0, 1.0, (4000, 2)) * (half[near] + r + 0.01)
    now = centre[near] + np.einsum("kij,ki->kj", axes[near], local)
    lo, hi = centre.min(axis=0) - 0.5, centre.max(axis=0) + 0.5
    now = np.concatenate([now, rng.uniform(lo, hi, (1000, 2))])
    before = now + rng.normal(0.0, 0.003, now.shape)
    brute = np.zeros(len(now), bool)
    for w in range(len(centre)):
        walls = np.full(len(now), w)
        deep = wall_depth(now, centre[walls], axes[walls], half[walls], r)
        was = wall_depth(before, centre[walls], axes[walls], half[walls], r)
        brute |= deep > np.maximum(was, 0.0) + OVERLAP_TOL_M
    assert 100 < brute.sum() < len(now) - 100
    assert np.array_equal(grid.deeper(before, now), brute)


@pytest.mark.parametrize("seed", range(6))
def test_the_robot_overlaps_are_every_overlapping_pair(seed):
    """``KinematicDrive._robot_overlaps`` (one compiled pass over cells of a disc's
    diameter) against every pair by numpy: the same pairs in the same order, the same
    verdicts, on a crowd of 400 discs in a 3 m square, each moved a few millimetres."""
    sim = Simulation(world_spec([Pose2D(0.0, 0.0, 0.0)]), physics="kinematic")
    drive = sim._drive
    rng = np.random.default_rng(seed)
    now = rng.uniform(-1.5, 1.5, (400, 2))
    before = now + rng.normal(0.0, 0.003, now.shape)
    reach = 2.0 * drive.footprint_radius_m
    i, j = np.triu_indices(len(now), 1)
    depth = reach - np.linalg.norm(now[i] - now[j], axis=1)
    was = reach - np.linalg.norm(before[i] - before[j], axis=1)
    overlap = depth > 0.0
    pairs, deeper = drive._robot_overlaps(before, now)
    assert len(pairs) > 50
    assert np.array_equal(pairs, np.column_stack([i, j])[overlap])
    assert np.array_equal(deeper, (depth > np.maximum(was, 0.0) + OVERLAP_TOL_M)[overlap])
    assert deeper.any() and not deeper.all()


def test_same_seed_same_trajectory():
    def run():
        sim = Simulation(world_spec([Pose2D(0.1 * k, 0.2 * k, k) for k in range(4)]),
                         physics="kinematic", wheel_slip=0.05, seed=7)
        rng = np.random.default_rng(1)
        out = []
        for _ in range(100):
            sim.set_velocity(rng.uniform(-0.2, 0.2, 4), rng.uniform(-1, 1, 4))
            sim.step()
            out.append((sim.poses(), sim.readings().copy()))
        return out
    for (pa, ra), (pb, rb) in zip(run(), run()):
        assert np.array_equal(pa, pb) and ra.tobytes() == rb.tobytes()


def test_the_footprint_covers_every_collision_geom_of_the_robot():
    sim = Simulation(world_spec([Pose2D(0.3, -0.2, 0.7)]), physics="kinematic")
    m, d, drive = sim.model, sim.data, sim._drive
    centre = drive.footprints(sim.poses())[0]
    mine = np.flatnonzero((sim.geom_robot == 0) & (m.geom_group == COLLISION_GROUP))
    chassis = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "r0/chassis")
    mine = mine[mine != chassis]  # the footprint itself
    assert len(mine) >= 4  # wheels, battery, caster
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    for g in mine:
        box = m.geom_aabb[g]  # centre and half sizes in the geom's frame: its corners
        # bound the geom (conservatively)
        corners = box[:3] + signs * box[3:]
        world = d.geom_xpos[g] + corners @ d.geom_xmat[g].reshape(3, 3).T
        assert np.hypot(*(world[:, :2] - centre).T).max() <= drive.footprint_radius_m + 1e-9


def test_kinematic_wheels_follow_the_motor_filter():
    """Step 1: from rest, a wheel command u reaches u (1 - exp(-t / tau)) after t."""
    sim = Simulation(world_spec([Pose2D(0.0, 0.0)]), physics="kinematic")
    tau = sim.model.actuator_dynprm[sim._actuators[0, 0], 0]
    sim.set_velocity(4.0 * sim.geometry.wheel_radius_m, 0.0)  # 4 rad/s on both wheels
    sim.step(5)
    t = sim.time_s - sim.model.opt.timestep  # the speed of the last physics step
    assert sim.readings()["wheel_speed"][0, 0] == pytest.approx(4.0 * (1 - math.exp(-t / tau)))


# ---------------------------------------------------------------------------- bad input
def test_bad_physics_is_one_clear_error():
    spec = world_spec([Pose2D(0.0, 0.0)])
    with pytest.raises(MjswarmError, match="physics must be one of dynamic, kinematic"):
        Simulation(spec, physics="warp")
    with pytest.raises(MjswarmError, match="ray caster"):
        Simulation(world_spec([Pose2D(0.0, 0.0)]), physics="kinematic", sensing="mujoco")


def test_unsupported_walls_are_named():
    spec = world_spec([Pose2D(0.0, 0.0)])
    spec.worldbody.add_geom(name="pillar", type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                            size=[0.05, 0.05, 0], pos=[1.0, 0.0, 0.05])
    with pytest.raises(MjswarmError, match="'pillar' is a mjGEOM_CYLINDER"):
        Simulation(spec, physics="kinematic")


def test_cli_physics_only_applies_to_the_embodied_world(capsys):
    assert main(["explore", "--arena", "fig9", "--robots", "2", "--world", "graph",
                 "--physics", "kinematic"]) == 2
    assert "--physics" in capsys.readouterr().err
