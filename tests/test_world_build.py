"""Building big worlds: robots attached in groups give the world one attach per robot gives."""

import warnings

import numpy as np
import pytest

from mjswarm.core import world as world_module
from mjswarm.core.simulation import Simulation
from mjswarm.core.world import FloorStrip, Pose2D, WallSegment, attach_robots, world_spec


def _flat(spec, template, poses, group=None):
    """The reference: one attach per robot, straight into the world."""
    for i, pose in enumerate(poses):
        world_module._attach_one(spec.worldbody, template, i, pose)


def _spec(poses):
    return world_spec(poses, [FloorStrip((0.0, 0.0), (2.0, 0.0))], [WallSegment((0.0, 0.5), (2.0, 0.5))])


@pytest.mark.parametrize("n, group", [(1, 1), (7, 3), (20, 4), (70, None)])
def test_grouped_attach_gives_the_same_mjcf_and_model(monkeypatch, n, group):
    rng = np.random.default_rng(n)
    poses = [Pose2D(*rng.uniform(-3, 3, 2), rng.uniform(-3, 3)) for _ in range(n)]
    monkeypatch.setattr(world_module, "attach_robots",
                        lambda s, t, p: attach_robots(s, t, p, group))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the empty-prefix warning stays silent
        grouped = _spec(poses)
        with world_module.quiet_empty_prefix():  # as export_mjcf saves
            grouped_xml = grouped.to_xml() if group is None else None
        a = Simulation(grouped).model
    monkeypatch.setattr(world_module, "attach_robots", _flat)
    flat = _spec(poses)
    b = Simulation(flat).model
    if grouped_xml is not None:
        assert grouped_xml == flat.to_xml()
    fields = [k for k in dir(a) if not k.startswith("_") and isinstance(getattr(a, k, None), np.ndarray)]
    assert len(fields) > 100
    for k in fields:
        assert np.array_equal(getattr(a, k), getattr(b, k), equal_nan=True), k
    assert [a.body(i).name for i in range(a.nbody)] == [b.body(i).name for i in range(b.nbody)]


def test_other_mujoco_warnings_still_pass(capfd):
    import mujoco

    with world_module.quiet_empty_prefix():
        mujoco.mju_warningText  # noqa: B018 (the handler is installed, nothing raised)
        handler = mujoco.get_mju_user_warning()
        handler("Attaching a spec with an empty prefix may prevent ...")
        handler("something else")
    assert mujoco.get_mju_user_warning() is None
    err = capfd.readouterr().err
    assert "something else" in err and "empty prefix" not in err


def test_geom_robot_is_each_robots_subtree():
    sim = Simulation(_spec([Pose2D(0.3 * i, 0.0) for i in range(5)]))
    m = sim.model
    for g in range(m.ngeom):
        name = m.geom(g).name
        b = m.geom_bodyid[g]
        while m.body_parentid[b] != 0:
            b = m.body_parentid[b]
        expected = int(np.flatnonzero(sim.robot_bodies == b)[0]) if b in sim.robot_bodies else -1
        assert sim.geom_robot[g] == expected, name


@pytest.mark.parametrize("physics, sensing", [("kinematic", "auto"), ("dynamic", "grid")])
def test_compiling_without_sensors_gives_the_same_model(physics, sensing):
    """Grid sensing compiles with MuJoCo's sensors off (they would cast every rangefinder
    against every geom once): the model is the one compiled with them on, and the
    caller's spec keeps its flags."""
    import mujoco

    spec = _spec([Pose2D(0.3 * i, 0.2 * (i % 3), 0.5 * i) for i in range(6)])
    a = Simulation(spec, physics=physics, sensing=sensing).model
    assert spec.option.disableflags == 0
    b = spec.compile()
    b.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
    for k in [k for k in dir(a) if not k.startswith("_") and isinstance(getattr(a, k, None), np.ndarray)]:
        assert np.array_equal(getattr(a, k), getattr(b, k), equal_nan=True), k
    assert a.opt.disableflags == b.opt.disableflags


def test_a_big_world_has_room_for_every_body_pair_of_the_broadphase(monkeypatch):
    """MuJoCo's collision stage takes an int per pair of bodies from the arena, near or
    not (``mj_collision``'s ``nmaxpairs``): 10,000 dynamic robots ran out of a 2.6 GB arena
    of 256 KB a robot. A world above the threshold sizes its arena for both."""
    monkeypatch.setattr(world_module, "SIZED_ARENA_FROM_ROBOTS", 4)
    spec = world_spec([Pose2D(i, 0.0) for i in range(5)])
    bodies = len(spec.bodies)
    assert bodies == 1 + 5 * 3  # the world, and each robot's chassis and two wheels
    assert spec.memory == (world_module.ARENA_BYTES_PER_ROBOT * 5
                           + world_module.BROADPHASE_BYTES_PER_PAIR * bodies * (bodies - 1) // 2)
    assert world_spec([Pose2D(i, 0.0) for i in range(4)]).memory == -1  # MuJoCo's default
