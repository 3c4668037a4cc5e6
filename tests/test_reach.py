"""How many robots an arena needs under a connectivity constraint
(mjswarm.experiments.reach): exact on corridors, monotone in the range, never fewer with
walls, one more for a docked robot; its soundness against completed runs is checked in
tests/test_connected_exploration.py."""

from __future__ import annotations

import math

import pytest

from mjswarm.arena import load_arena
from mjswarm.arena.geometry import corridor_walls
from mjswarm.core.radio import BASE_MAST_M
from mjswarm.experiments.reach import SAMPLE_M, robots_needed, sample_points


def needed(arena: str, range_m: float, walls: bool = False, connectivity: str = "connected"):
    spec = load_arena(arena)
    return robots_needed(spec.vertices, spec.edges, spec.root, range_m,
                         corridor_walls(spec) if walls else None, BASE_MAST_M, connectivity)


@pytest.mark.parametrize("range_m", [0.5, 0.7, 1.0, 1.3, 2.0, 3.5])
def test_a_corridor_needs_a_chain_as_long_as_its_length_over_the_range(range_m):
    """lattice:1x6 is a straight 3 m corridor from its root: k robots on it reach k R,
    so it needs ceil(L / R); the count, relaxed by the sampling (links within
    R + SAMPLE_M), lies between that and ceil(L / (R + SAMPLE_M))."""
    spec = load_arena("lattice:1x6")
    length = max(math.dist(spec.vertices[spec.root], p) for p in spec.vertices.values())
    low, high = (math.ceil(length / r - 1e-9) for r in (range_m + SAMPLE_M, range_m))
    assert low <= needed("lattice:1x6", range_m) <= high


@pytest.mark.parametrize("arena", ["arena2", "tree1", "hex:2x2", "random-planar:10:3",
                                   "random-graph:10:13:1"])
def test_more_range_never_needs_more_robots_and_walls_never_fewer(arena):
    spec = load_arena(arena)
    far = max(math.dist(spec.vertices[spec.root], p) for p in sample_points(spec.vertices,
                                                                          spec.edges))
    counts = [needed(arena, r) for r in (0.6, 0.9, 1.4, 2.2, far)]
    assert counts == sorted(counts, reverse=True) and counts[-1] == 1 and counts[0] > 1
    for r in (0.9, 1.4):
        assert needed(arena, r, walls=True) >= needed(arena, r)
        assert needed(arena, r, connectivity="biconnected") == needed(arena, r) + 1


def test_the_points_cover_every_edge_at_the_spacing():
    spec = load_arena("arena2")
    points = sample_points(spec.vertices, spec.edges)
    for u, v in spec.edges:
        a, b = spec.vertices[u], spec.vertices[v]
        on = [p for p in points if abs(math.dist(a, p) + math.dist(p, b) - math.dist(a, b)) < 1e-9]
        gaps = sorted(math.dist(a, p) for p in on)
        assert max(b_ - a_ for a_, b_ in zip(gaps, gaps[1:])) <= SAMPLE_M + 1e-9
