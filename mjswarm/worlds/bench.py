"""The benchmark's world: N Spark V robots in rows, each on its own floor strip with a
wall on its left (:mod:`mjswarm.experiments.bench` measures the loop on it)."""

from __future__ import annotations

import math

from mjswarm.core.robot import DEFAULT_ROBOT_XML
from mjswarm.core.simulation import Simulation
from mjswarm.core.world import FloorStrip, Pose2D, WallSegment, world_spec
from mjswarm.errors import MjswarmError

#: Distance between rows, and between robots in a row (m).
ROW_SPACING_M = 0.5
COLUMN_SPACING_M = 0.6


def bench_world(n: int, robot_xml: str = str(DEFAULT_ROBOT_XML), sensing: str = "auto",
                physics: str = "dynamic") -> Simulation:
    """N robots in a near-square grid, each on a strip with a wall on its left."""
    if n < 1:
        raise MjswarmError(f"robot count must be >= 1, got {n}")
    cols = math.ceil(math.sqrt(n))
    rows = math.ceil(n / cols)
    row_len = cols * COLUMN_SPACING_M + 2.0
    poses = [Pose2D((i % cols) * COLUMN_SPACING_M, (i // cols) * ROW_SPACING_M) for i in range(n)]
    strips = [FloorStrip((-0.5, r * ROW_SPACING_M), (row_len, r * ROW_SPACING_M)) for r in range(rows)]
    walls = [
        WallSegment((-0.5, r * ROW_SPACING_M + 0.13), (row_len, r * ROW_SPACING_M + 0.13))
        for r in range(rows)
    ]
    return Simulation(world_spec(poses, strips, walls, robot_xml=robot_xml), sensing=sensing,
                      physics=physics)
