"""Arena generators beyond the square lattice, and rotation (the arenas of the stress grid)."""

from __future__ import annotations

import math

import networkx as nx
import pytest

from mjswarm.arena import load_arena
from mjswarm.arena.geometry import vertex_fans
from mjswarm.errors import MjswarmError


def smallest_gap_deg(spec, vertex: str) -> float:
    angles = [a for a, _ in vertex_fans(spec)[vertex]]
    if len(angles) < 2:
        return 360.0
    gaps = [(b - a) % (2 * math.pi) for a, b in zip(angles, angles[1:] + angles[:1])]
    return math.degrees(min(gaps))


@pytest.mark.parametrize("text,vertex,angle", [
    ("fan:3:45", "c", 45.0), ("fan:8:45", "c", 45.0), ("fan:4:60:1.2", "c", 60.0),
    ("wheel:4", "r0", 45.0), ("wheel:6", "r0", 60.0), ("wheel:8", "c", 45.0),
    ("hex:2x3", "v1_1", 120.0), ("tri:2x3", "v1_1", 60.0),
])
def test_generators_make_the_angles_they_say(text, vertex, angle):
    spec = load_arena(text)
    assert spec.name == text and nx.is_connected(spec.graph())
    assert smallest_gap_deg(spec, vertex) == pytest.approx(angle, abs=1e-6)
    assert load_arena(text) == spec  # deterministic


@pytest.mark.parametrize("n", [5, 8, 12, 20])
@pytest.mark.parametrize("seed", range(8))
def test_random_planar_graphs_are_valid_planar_and_not_axis_aligned(n, seed):
    spec = load_arena(f"random-planar:{n}:{seed}")
    g = spec.graph()
    assert nx.is_connected(g) and nx.check_planarity(g)[0]
    assert len(spec.vertices) == n and len(spec.edges) >= n - 1
    angles = [math.degrees(a) for fan in vertex_fans(spec).values() for a, _ in fan]
    assert any(abs(a / 15 - round(a / 15)) > 0.05 for a in angles)


@pytest.mark.parametrize("text", ["lattice:3x3", "fig9", "wheel:6"])
def test_rotation_keeps_lengths_and_angles_and_the_root(text):
    spec = load_arena(text)
    turned = load_arena(f"{text}@37.5")
    assert turned.name == f"{text}@37.5" and turned.edges == spec.edges
    assert turned.vertices[spec.root] == pytest.approx(spec.vertices[spec.root])
    for u, v in spec.edges:
        assert math.dist(*(turned.vertices[w] for w in (u, v))) == pytest.approx(
            math.dist(*(spec.vertices[w] for w in (u, v))))
    for v in spec.vertices:
        assert smallest_gap_deg(turned, v) == pytest.approx(smallest_gap_deg(spec, v))


@pytest.mark.parametrize("text,message", [
    ("wheel:3", "N must be 4..8"), ("wheel:9", "N must be 4..8"),
    ("fan:2:30", "at least 45"), ("fan:8:50", "at least 45"),
    ("fan:3:45:0.3", "fan:3:45:0.3"), ("hex:0x2", "R, C >= 1"),
    ("random-planar:2:0", "at least 3"), ("wheel:x", "expected wheel:N"),
])
def test_bad_parameters_are_one_line(text, message):
    with pytest.raises(MjswarmError, match=message) as err:
        load_arena(text)
    assert "\n" not in str(err.value)
