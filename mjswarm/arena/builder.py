"""Arena spec -> MuJoCo world.

Turns the geometry of :mod:`mjswarm.arena.geometry` (lane strips, vertex spokes,
corridor walls) into floor strips and walls for :func:`mjswarm.core.world.world_spec`, adds a
named site ``vertex:<id>`` at every vertex centre (for recordings and tests; robots never
read sites), and places robots. This is the only module of :mod:`mjswarm.arena` that
imports MuJoCo.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import mujoco

from mjswarm.arena.geometry import (
    STRIP_WIDTH_M,
    WALL_HEIGHT_M,
    WALL_THICKNESS_M,
    corridor_walls,
    lane_strips,
    vertex_spokes,
)
from mjswarm.arena.spec import ArenaSpec
from mjswarm.errors import MjswarmError, one_line
from mjswarm.core.robot import DEFAULT_ROBOT_XML
from mjswarm.core.world import FloorStrip, Pose2D, WallSegment, quiet_empty_prefix, world_spec

VERTEX_SITE_PREFIX = "vertex:"


def arena_primitives(spec: ArenaSpec) -> tuple[list[FloorStrip], list[WallSegment]]:
    """Floor strips (lanes, then spokes) and walls of an arena."""
    strips = [FloorStrip(s.start, s.end, STRIP_WIDTH_M) for s in lane_strips(spec)]
    strips += [FloorStrip(s.start, s.end, STRIP_WIDTH_M) for s in vertex_spokes(spec)]
    walls = [WallSegment(w.start, w.end, WALL_THICKNESS_M, WALL_HEIGHT_M)
             for w in corridor_walls(spec)]
    return strips, walls


def arena_world_spec(
    spec: ArenaSpec, poses: Sequence[Pose2D] = (), robot_xml: str = str(DEFAULT_ROBOT_XML)
) -> mujoco.MjSpec:
    """The MuJoCo world of an arena with robots at ``poses`` (uncompiled)."""
    strips, walls = arena_primitives(spec)
    world = world_spec(poses, strips, walls, robot_xml=robot_xml, margin_m=0.6)
    world.modelname = f"mjswarm_{spec.name}"
    for vid, (x, y) in spec.vertices.items():
        world.worldbody.add_site(
            name=f"{VERTEX_SITE_PREFIX}{vid}", pos=[x, y, 0.003], size=[0.01, 0.01, 0.01],
            rgba=[0.9, 0.1, 0.1, 0.6], group=5,
        )
    return world


def export_mjcf(spec: ArenaSpec, out: str | Path, poses: Sequence[Pose2D] = ()) -> Path:
    """Write a standalone MJCF of the arena, with robots at ``poses``, to ``out``.

    Nothing is written if the world does not compile.
    """
    world = arena_world_spec(spec, poses)
    try:
        with quiet_empty_prefix():
            world.compile()
    except ValueError as exc:
        raise MjswarmError(f"arena {spec.name} does not compile: {one_line(exc)}") from None
    out = Path(out)
    if not out.parent.is_dir():
        raise MjswarmError(f"output directory does not exist: {out.parent}")
    with quiet_empty_prefix():  # robots attached in groups (world.attach_robots)
        out.write_text(world.to_xml())
    return out
