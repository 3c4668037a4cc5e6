"""Building a MuJoCo world of N robots on a floor with line strips and walls.

Everything is assembled with :class:`mujoco.MjSpec`: the robot template (see
:mod:`mjswarm.core.robot`) is attached once per robot with the name prefix ``r<i>/``, so robot
``i``'s sensors are ``r<i>/line_left`` ... and its actuators ``r<i>/wheel_left`` ...
Many robots are attached in groups (:func:`attach_robots`): MuJoCo 4.0's ``MjSpec``
re-serialises the whole spec on every attach, so attaching N robots one by one into the
world costs O(N^2) (1000 robots 7 s, 3000 robots about 3 minutes); each group of about
sqrt(N) robots is attached into a small spec of its own, and the group, one frame, is
attached into the world, which gives the same world (the same MJCF, the same compiled
model) in O(N^1.5).

Geom groups follow mujoco_menagerie (``models/spark_v.xml``): collision geoms (robots'
bodies, walls, the floor) in ``COLLISION_GROUP`` 3, visual-only geoms in 2. Floor marks
(line strips) are thin boxes in ``STRIP_GROUP`` 1 with ``contype = conaffinity = 0``: the
rangefinders see them (rays test every group) but the wheels never touch them. The arena builder
(:mod:`mjswarm.arena.builder`) turns a graph spec into these primitives; tests and the
benchmark use them directly.
"""

from __future__ import annotations

import contextlib
import math
import sys
import warnings
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from mjswarm.errors import MjswarmError
from mjswarm.core.robot import DEFAULT_ROBOT_XML, ROOT_BODY, load_robot_spec

#: Physics timestep (s) and integrator used for every world (``models/scene.xml`` too).
PHYSICS_TIMESTEP_S = 0.002
PHYSICS_INTEGRATOR = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
#: Geom group of everything that collides (robots, walls, floor): what blocks line of sight.
COLLISION_GROUP = 3
#: Geom group of the floor marks (line strips).
STRIP_GROUP = 1
FLOOR_RGBA = (0.92, 0.92, 0.90, 1.0)
STRIP_RGBA = (0.05, 0.05, 0.05, 1.0)
WALL_RGBA = (0.55, 0.35, 0.25, 1.0)


@dataclass(frozen=True)
class Pose2D:
    """A planar pose: position (m) and heading ``yaw`` (rad, CCW from +x)."""

    x: float
    y: float
    yaw: float = 0.0


@dataclass(frozen=True)
class FloorStrip:
    """A straight line strip on the floor, from ``start`` to ``end`` (m, m)."""

    start: tuple[float, float]
    end: tuple[float, float]
    width_m: float = 0.02
    thickness_m: float = 0.002


@dataclass(frozen=True)
class WallSegment:
    """A straight wall whose centre line runs from ``start`` to ``end`` (m)."""

    start: tuple[float, float]
    end: tuple[float, float]
    thickness_m: float = 0.02
    height_m: float = 0.10


def _segment_frame(start: Sequence[float], end: Sequence[float]) -> tuple[np.ndarray, float, float]:
    """Midpoint, half-length (m) and yaw (rad) of a 2-D segment."""
    a, b = np.asarray(start, float), np.asarray(end, float)
    delta = b - a
    length = float(np.hypot(*delta))
    if not math.isfinite(length) or length <= 0.0:
        raise MjswarmError(f"degenerate segment from {tuple(a)} to {tuple(b)}")
    return (a + b) / 2.0, length / 2.0, math.atan2(delta[1], delta[0])


def yaw_quat(yaw: float) -> list[float]:
    """Unit quaternion (w, x, y, z) of a rotation by ``yaw`` (rad) about +z."""
    return [math.cos(yaw / 2.0), 0.0, 0.0, math.sin(yaw / 2.0)]


def world_spec(
    poses: Sequence[Pose2D],
    strips: Iterable[FloorStrip] = (),
    walls: Iterable[WallSegment] = (),
    robot_xml: str = str(DEFAULT_ROBOT_XML),
    timestep_s: float = PHYSICS_TIMESTEP_S,
    margin_m: float = 1.0,
    floor_points: Sequence[tuple[float, float]] = (),
) -> mujoco.MjSpec:
    """An uncompiled world: floor, strips, walls and one robot per pose (``r0`` ...).

    The floor is a plane covering every robot, strip, wall and ``floor_points`` (m) plus
    ``margin_m``.
    Callers may add more elements (vertex sites, say) before compiling.
    """
    if timestep_s <= 0.0:
        raise MjswarmError(f"physics timestep must be positive, got {timestep_s}")
    strips, walls = list(strips), list(walls)
    robot = load_robot_spec(robot_xml)
    spec = mujoco.MjSpec()
    spec.modelname = "mjswarm_world"
    spec.copy_during_attach = True
    spec.option.timestep = timestep_s
    spec.option.integrator = PHYSICS_INTEGRATOR
    spec.visual.global_.offwidth = 1280
    spec.visual.global_.offheight = 960

    points = [(p.x, p.y) for p in poses] + [tuple(p) for p in floor_points]
    points += [pt for s in strips for pt in (s.start, s.end)]
    points += [pt for w in walls for pt in (w.start, w.end)]
    xy = np.array(points, float).reshape(-1, 2) if points else np.zeros((1, 2))
    centre = (xy.min(axis=0) + xy.max(axis=0)) / 2.0
    half = (xy.max(axis=0) - xy.min(axis=0)) / 2.0 + margin_m
    spec.worldbody.add_light(pos=[centre[0], centre[1], 5.0], dir=[0, 0, -1], type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL)
    spec.worldbody.add_geom(
        name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, pos=[centre[0], centre[1], 0.0],
        size=[half[0], half[1], 0.05], rgba=FLOOR_RGBA, group=COLLISION_GROUP,
    )
    for i, strip in enumerate(strips):
        mid, half_len, yaw = _segment_frame(strip.start, strip.end)
        spec.worldbody.add_geom(
            name=f"strip{i}", type=mujoco.mjtGeom.mjGEOM_BOX, group=STRIP_GROUP,
            contype=0, conaffinity=0, rgba=STRIP_RGBA,
            pos=[mid[0], mid[1], strip.thickness_m / 2.0], quat=yaw_quat(yaw),
            size=[half_len, strip.width_m / 2.0, strip.thickness_m / 2.0],
        )
    for i, wall in enumerate(walls):
        mid, half_len, yaw = _segment_frame(wall.start, wall.end)
        spec.worldbody.add_geom(
            name=f"wall{i}", type=mujoco.mjtGeom.mjGEOM_BOX, rgba=WALL_RGBA,
            group=COLLISION_GROUP,
            pos=[mid[0], mid[1], wall.height_m / 2.0], quat=yaw_quat(yaw),
            size=[half_len, wall.thickness_m / 2.0, wall.height_m / 2.0],
        )
    attach_robots(spec, robot.body(ROOT_BODY), poses)
    if len(poses) > SIZED_ARENA_FROM_ROBOTS:
        bodies = len(spec.bodies)
        spec.memory = (ARENA_BYTES_PER_ROBOT * len(poses)
                       + BROADPHASE_BYTES_PER_PAIR * bodies * (bodies - 1) // 2)
    return spec


#: Robot counts above which a world's MjData arena (contacts, constraints, the solver's
#: stack) gets an explicit size. MuJoCo's own default grows with the square of the degrees
#: of freedom (1000 robots 3.0 GB, 3000 robots 24 GB, 10,000 robots 270 GB: past what it can
#: allocate, and the world does not compile); the worlds of the benchmarks and tests, up to
#: 1000 robots, keep MuJoCo's default, and so every result they had.
SIZED_ARENA_FROM_ROBOTS = 1000
#: The explicit arena per robot (bytes): 1000 robots driving in the bench world use 36 KB
#: each at most (``MjData.maxuse_arena``), five contacts a robot; this leaves room for seven
#: times as many (a robot in a crowd touches its neighbours too).
ARENA_BYTES_PER_ROBOT = 256 * 1024
#: MuJoCo's broadphase takes room on the arena for every pair of bodies (an int each:
#: ``mj_collision``'s ``nmaxpairs``), whether or not they are near: 10,000 robots, 30,001
#: bodies, 1.8 GB more (address space: only the pairs found are written).
BROADPHASE_BYTES_PER_PAIR = 4


#: Robot counts up to which :func:`attach_robots` attaches robot by robot.
GROUP_FROM_ROBOTS = 64


def attach_robots(spec: mujoco.MjSpec, template: mujoco.MjsBody, poses: Sequence[Pose2D],
                  group: int | None = None) -> None:
    """Attach ``template`` to ``spec``'s world body once per pose, robot ``i`` under the
    name prefix ``r<i>/`` in a frame at its pose, in order.

    From ``GROUP_FROM_ROBOTS`` robots on (or whenever ``group`` is given) robots are
    attached ``group`` at a time (default about sqrt(N)): into a frame of a fresh small
    spec, and that frame into ``spec`` with an empty prefix (its names already carry
    theirs). MuJoCo warns that an empty prefix "may prevent the model from being saved
    correctly"; the names are unique, and ``tests/test_world_build.py`` checks that the
    saved MJCF and the compiled model equal those of one attach per robot.
    """
    n = len(poses)
    if group is None:
        if n < GROUP_FROM_ROBOTS:
            for i, pose in enumerate(poses):
                _attach_one(spec.worldbody, template, i, pose)
            return
        group = max(1, math.isqrt(n))
    with quiet_empty_prefix():
        for start in range(0, n, group):
            part = mujoco.MjSpec()
            part.copy_during_attach = True
            frame = part.worldbody.add_frame()
            for i in range(start, min(n, start + group)):
                _attach_one(frame, template, i, poses[i])
            spec.worldbody.attach_frame(frame, "", "")


#: The start of MuJoCo's warning on attaching with an empty prefix.
EMPTY_PREFIX_WARNING = "Attaching a spec with an empty prefix"


@contextlib.contextmanager
def quiet_empty_prefix() -> Iterator[None]:
    """Within: MuJoCo's warning about an empty attach prefix is dropped (both as printed
    by ``mju_warning`` and as a Python warning); every other warning passes as before."""
    previous = mujoco.get_mju_user_warning()

    def handler(message: str) -> None:
        if message.startswith(EMPTY_PREFIX_WARNING):
            return
        if previous is not None:
            previous(message)
        else:  # what MuJoCo's default handler prints
            sys.stderr.write(f"WARNING: {message}\n\n")

    mujoco.set_mju_user_warning(handler)
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", EMPTY_PREFIX_WARNING, UserWarning)
            yield
    finally:
        mujoco.set_mju_user_warning(previous)


def _attach_one(parent: mujoco.MjsBody | mujoco.MjsFrame, template: mujoco.MjsBody, i: int,
                pose: Pose2D) -> None:
    frame = parent.add_frame(pos=[pose.x, pose.y, 0.0], quat=yaw_quat(pose.yaw))
    frame.attach_body(template, f"r{i}/", "")
