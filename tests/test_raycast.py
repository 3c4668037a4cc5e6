"""Grid ray casting equals MuJoCo's: ``mj_ray`` per ray, and plain rangefinders per robot.

The O(N) sensing (:mod:`mjswarm.core.raycast`, ``Simulation(sensing="grid")``) must give the
readings MuJoCo's own rangefinders give on the same states, within 1e-9. Random
states put robots anywhere on an arena with walls and strips, against walls, against and
inside each other, and some tipped over or upside down (their line sensors miss the floor
and take the ``mj_ray`` fallback).
"""

from __future__ import annotations

import math

import mujoco
import numba
import numpy as np
import pytest

from mjswarm.arena import load_arena
from mjswarm.arena.builder import arena_world_spec
from mjswarm.core.bearing import BearingSensor
from mjswarm.errors import MjswarmError
from mjswarm.core.raycast import RayCaster, Rays
from mjswarm.core.sight import LineOfSight
from mjswarm.core.simulation import GRID_SENSING_MIN_ROBOTS, Simulation
from mjswarm.core.world import COLLISION_GROUP, Pose2D, world_spec

ROBOTS = 12
TOLERANCE = 1e-9


def arena_sims(robots: int = ROBOTS) -> tuple[Simulation, Simulation]:
    """The same arena2 world twice: grid sensing and MuJoCo's sensors."""
    spec = load_arena("arena2")
    poses = [Pose2D(0.3 * i, -1.0, 0.0) for i in range(robots)]
    return (Simulation(arena_world_spec(spec, poses), sensing="grid"),
            Simulation(arena_world_spec(spec, poses), sensing="mujoco"))


def random_state(sim: Simulation, rng: np.random.Generator, tipped: float = 0.2) -> tuple[np.ndarray, np.ndarray]:
    """Robots in clusters around random points of the arena (so they touch and overlap),
    random headings, random wheel angles and speeds, a share of them tipped at random."""
    m = sim.model
    qpos, qvel = sim.data.qpos.copy(), np.zeros(m.nv)
    xy = sim.rays.data.geom_xpos[m.geom_type == mujoco.mjtGeom.mjGEOM_BOX][:, :2]  # strips, walls
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    centres = rng.uniform(lo, hi, (3, 2))
    for i in range(sim.n):
        adr = sim._qpos_adr[i]
        qpos[adr:adr + 2] = centres[i % 3] + rng.normal(0.0, 0.15, 2)
        qpos[adr + 2] = 0.025
        if rng.random() < tipped:
            quat = rng.normal(size=4)
            qpos[adr + 3:adr + 7] = quat / np.linalg.norm(quat)
            qpos[adr + 2] = rng.uniform(0.0, 0.1)
        else:
            yaw = rng.uniform(-math.pi, math.pi)
            qpos[adr + 3:adr + 7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
    qpos[sim._wheel_qpos_adr.ravel()] = rng.uniform(-50.0, 50.0, sim._wheel_qpos_adr.size)
    qvel[sim._wheel_dof_adr.ravel()] = rng.uniform(-8.0, 8.0, sim._wheel_dof_adr.size)
    return qpos, qvel


def assert_same_readings(a: np.ndarray, b: np.ndarray) -> None:
    for field in ("line", "ir", "encoder", "wheel_speed", "battery"):
        np.testing.assert_allclose(a[field], b[field], rtol=0, atol=TOLERANCE, equal_nan=True,
                                   err_msg=field)


@pytest.mark.parametrize("seed", range(8))
def test_grid_readings_equal_mujoco_rangefinders_on_random_states(seed):
    grid, plain = arena_sims()
    rng = np.random.default_rng(seed)
    for _ in range(5):
        qpos, qvel = random_state(grid, rng)
        grid.set_state(qpos, qvel)
        plain.set_state(qpos, qvel)
        assert_same_readings(grid.readings(), plain.readings())
    seen = grid.readings()
    assert np.isfinite(seen["ir"]).any() and np.isnan(seen["ir"]).any()  # both cases occur


def test_grid_readings_equal_mujoco_rangefinders_while_stepping():
    """Physics does not depend on sensing, so both worlds step identically; the readings
    after each tick (state before the last substep, wheel states included) must agree."""
    grid, plain = arena_sims()
    rng = np.random.default_rng(11)
    qpos, qvel = random_state(grid, rng, tipped=0.0)
    grid.set_state(qpos, qvel)
    plain.set_state(qpos, qvel)
    for tick in range(25):
        v, w = rng.uniform(-0.2, 0.2, grid.n), rng.uniform(-2.0, 2.0, grid.n)
        for sim in (grid, plain):
            sim.set_velocity(v, w)
            sim.step()
        assert_same_readings(grid.readings(), plain.readings())
    np.testing.assert_array_equal(grid.data.qpos, plain.data.qpos)


def test_line_sensors_of_tipped_robots_use_the_fallback():
    grid, plain = arena_sims(robots=3)
    qpos, qvel = grid.data.qpos.copy(), np.zeros(grid.model.nv)
    adr = grid._qpos_adr[1]
    qpos[adr + 2] = 0.2
    qpos[adr + 3:adr + 7] = (0.0, 1.0, 0.0, 0.0)  # upside down, line sensors look up
    grid.set_state(qpos, qvel)
    plain.set_state(qpos, qvel)
    assert np.isnan(grid.readings()["line"][1]).all()  # nothing above the arena
    assert_same_readings(grid.readings(), plain.readings())


@pytest.mark.parametrize("seed", range(4))
def test_ray_caster_equals_mj_ray(seed):
    """Random rays of random lengths from near the robots, all groups and the collision
    group only:
    the nearest hit within the length and its geom are mj_ray's."""
    grid, _ = arena_sims()
    rng = np.random.default_rng(100 + seed)
    grid.set_state(*random_state(grid, rng))
    m, d = grid.model, grid.data
    count = 400
    robot = rng.integers(0, grid.n, count)
    origin = d.xpos[grid.robot_bodies][robot] + rng.normal(0.0, 0.08, (count, 3))
    direction = rng.normal(size=(count, 3))
    direction *= rng.uniform(0.2, 3.0, (count, 1)) / np.linalg.norm(direction, axis=1, keepdims=True)
    rays = Rays(origin, direction, rng.uniform(0.0, 1.5, count), grid.robot_bodies[robot])
    geomid = np.zeros(1, np.int32)
    for group in (None, (np.arange(6) == COLLISION_GROUP).astype(np.uint8)):
        dist, geom = grid.rays.cast(rays, group)
        for k in range(count):
            ref = mujoco.mj_ray(m, d, origin[k], direction[k], group, 1, int(rays.exclude_body[k]), geomid)
            want = (ref, geomid[0]) if 0 <= ref <= rays.length[k] else (-1.0, -1)
            assert dist[k] == pytest.approx(want[0], abs=TOLERANCE) and geom[k] == want[1], k
        assert (geom >= 0).sum() > count // 4  # the rays do hit things


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs two numba threads")
def test_ray_caster_answers_the_same_on_two_threads():
    grid, _ = arena_sims()
    rng = np.random.default_rng(7)
    grid.set_state(*random_state(grid, rng))
    count = 2000
    robot = rng.integers(0, grid.n, count)
    origin = grid.data.xpos[grid.robot_bodies][robot] + rng.normal(0.0, 0.08, (count, 3))
    direction = rng.normal(size=(count, 3))
    rays = Rays(origin, direction, rng.uniform(0.0, 1.5, count), grid.robot_bodies[robot])
    one = grid.rays.cast(rays)
    two = RayCaster(grid.model, grid.data, grid.robot_bodies, grid.geom_robot, threads=2).cast(rays)
    assert (one[1] >= 0).sum() > count // 4
    assert all(np.array_equal(a, b) for a, b in zip(one, two))  # bit for bit


def test_bearing_line_of_sight_equals_mj_ray():
    grid, _ = arena_sims()
    rng = np.random.default_rng(5)
    grid.set_state(*random_state(grid, rng, tipped=0.0))
    k, p = np.nonzero(~np.eye(grid.n, dtype=bool))
    poses = grid.poses()
    fast = grid.sight(k, p)
    geomid = np.zeros(1, np.int32)
    collision = (np.arange(6) == COLLISION_GROUP).astype(np.uint8)
    for i, j, seen in zip(k, p, fast):
        start = np.array([poses[i, 0], poses[i, 1], 0.06])
        vec = np.array([poses[j, 0] - poses[i, 0], poses[j, 1] - poses[i, 1], 0.0])
        mujoco.mj_ray(grid.model, grid.data, start, vec, collision, 1,
                      int(grid.robot_bodies[i]), geomid)
        assert seen == (geomid[0] >= 0 and grid.geom_robot[geomid[0]] == j)
    assert fast.any() and not fast.all()
    assert all(set(seen) <= set(range(grid.n)) for seen in BearingSensor(grid).read())


def test_line_of_sight_is_cast_once_per_state_and_equals_a_fresh_cast():
    grid, _ = arena_sims()
    rng = np.random.default_rng(6)
    grid.set_state(*random_state(grid, rng, tipped=0.0))
    k, p = np.nonzero(~np.eye(grid.n, dtype=bool))
    some = rng.permutation(len(k))[: len(k) // 3]
    first = grid.sight(k[some], p[some])
    cast = grid.sight.rays_cast
    assert cast == len(some)
    full = grid.sight(k, p)  # only the other two thirds are cast
    assert grid.sight.rays_cast == len(k) and np.array_equal(full[some], first)
    assert np.array_equal(full, LineOfSight(grid)(k, p))
    assert np.array_equal(grid.sight(k[some][::-1], p[some][::-1]), first[::-1])
    assert grid.sight.rays_cast == len(k)
    grid.set_velocity(np.full(grid.n, 0.2), np.linspace(-2, 2, grid.n))
    grid.step(5)  # a new state: answers are cast again
    moved = grid.sight(k, p)
    assert grid.sight.rays_cast == 2 * len(k)
    assert np.array_equal(moved, LineOfSight(grid)(k, p)) and not np.array_equal(moved, full)


def test_auto_sensing_switches_to_the_grid_for_large_teams():
    small = Simulation(world_spec([Pose2D(0.3 * i, 0, 0) for i in range(GRID_SENSING_MIN_ROBOTS - 1)]))
    large = Simulation(world_spec([Pose2D(0.3 * i, 0, 0) for i in range(GRID_SENSING_MIN_ROBOTS)]))
    assert (small.sensing, large.sensing) == ("mujoco", "grid")


def test_bad_sensing_and_unsupported_geoms_are_one_line_errors():
    with pytest.raises(MjswarmError, match="sensing must be one of"):
        Simulation(world_spec([Pose2D(0, 0, 0)]), sensing="magic")
    spec = world_spec([Pose2D(0, 0, 0)])
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.05, 0.1, 0], pos=[1, 1, 0.1])
    with pytest.raises(MjswarmError, match="CAPSULE.*sensing='mujoco'"):
        Simulation(spec, sensing="grid")
    spec = world_spec([Pose2D(0, 0, 0), Pose2D(0.3, 0, np.pi)])
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.05, 0.1, 0], pos=[1, 1, 0.1])
    sim = Simulation(spec, sensing="mujoco")  # MuJoCo's rangefinders see capsules,
    sim.step()
    assert [set(seen) for seen in BearingSensor(sim).read()] == [{1}, {0}]  # and its line of sight
    with pytest.raises(MjswarmError, match="CAPSULE"):
        sim.rays  # the grid caster does not
    with pytest.raises(MjswarmError, match="threads must be"):
        RayCaster(sim.model, sim.data, sim.robot_bodies, sim.geom_robot, threads=0)
    with pytest.raises(MjswarmError, match="cell size"):
        sim = Simulation(world_spec([Pose2D(0, 0, 0)]), sensing="grid")
        RayCaster(sim.model, sim.data, sim.robot_bodies, sim.geom_robot, cell_m=0.0)
