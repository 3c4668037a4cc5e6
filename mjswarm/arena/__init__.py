"""Arenas: graph specs (vertex coordinates + edges), generators and their geometry.

Pure Python (no MuJoCo): the MuJoCo builder turns these specs into MJCF.

>>> spec = load_arena("fig9")
>>> len(spec.vertices), len(spec.edges), spec.root
(10, 12, 'v1')
"""

from mjswarm.arena.generators import (
    GENERATORS,
    LATTICE_SPACING_M,
    generate,
    lattice,
    random_graph,
    random_tree,
)
from mjswarm.arena.geometry import (
    LaneStrip,
    Spoke,
    Wall,
    corridor_walls,
    incidence_angle,
    lane_strips,
    vertex_spokes,
)
from mjswarm.arena.spec import (
    SHIPPED_DIR,
    ArenaSpec,
    load_arena,
    parse_arena_spec,
    shipped_arenas,
    validate_arena,
)

__all__ = [
    "GENERATORS",
    "LATTICE_SPACING_M",
    "SHIPPED_DIR",
    "ArenaSpec",
    "LaneStrip",
    "Spoke",
    "Wall",
    "corridor_walls",
    "generate",
    "incidence_angle",
    "lane_strips",
    "lattice",
    "load_arena",
    "parse_arena_spec",
    "random_graph",
    "random_tree",
    "shipped_arenas",
    "validate_arena",
    "vertex_spokes",
]
