"""Arena specs: shipped arenas, generators, validation messages, geometry, `arena show`."""

from __future__ import annotations

import itertools
import json
import math

import networkx as nx
import numpy as np
import pytest

from mjswarm.arena import (
    SHIPPED_DIR,
    ArenaSpec,
    corridor_walls,
    incidence_angle,
    lane_strips,
    load_arena,
    parse_arena_spec,
    shipped_arenas,
    vertex_spokes,
)
from mjswarm.arena import geometry as geo
from mjswarm.arena.generators import compact_cells, lattice_adjacencies, max_lattice_edges
from mjswarm.cli import main
from mjswarm.errors import MjswarmError

EXPECTED = {  # arena: (V, E, is tree)
    "arena1": (8, 9, False),
    "arena2": (13, 12, True),
    "fig9": (10, 12, False),
    "tree1": (13, 12, True),
    "tree2": (13, 12, True),
    "tree3": (13, 12, True),
    "tree4": (13, 12, True),
    "lattice:4x4": (16, 24, False),
    "lattice:10x10": (100, 180, False),
}
SHIPPED = [a for a in EXPECTED if ":" not in a]


# ---------------------------------------------------------------- shipped arenas


def test_every_shipped_arena_is_expected():
    assert shipped_arenas() == sorted(SHIPPED)


@pytest.mark.parametrize("arena", list(EXPECTED))
def test_arena_loads_with_right_size_and_tree_ness(arena):
    spec = load_arena(arena)
    n_v, n_e, tree = EXPECTED[arena]
    g = spec.graph()
    assert (len(spec.vertices), len(spec.edges), spec.is_tree()) == (n_v, n_e, tree)
    assert (g.number_of_nodes(), g.number_of_edges()) == (n_v, n_e)
    assert nx.is_tree(g) == tree and nx.is_connected(g)
    hops = nx.single_source_shortest_path_length(g, spec.root)
    assert spec.radius() == max(hops.values())
    if ":" not in arena:
        assert spec.name == arena and spec.description


def test_fig9_matches_the_paper():
    spec = load_arena("fig9")
    s = 0.6
    grid = {"v1": (0, 1), "v2": (1, 1), "v5": (2, 1), "v7": (3, 1), "v3": (0, 0),
            "v4": (1, 0), "v6": (2, 0), "v8": (3, 0), "v9": (4, 0), "v10": (5, 0)}
    assert spec.root == "v1"
    assert spec.vertices.keys() == grid.keys()
    for k, (x, y) in grid.items():
        assert spec.vertices[k] == pytest.approx((x * s, y * s))
    order = "v1-v2 v1-v3 v2-v4 v2-v5 v3-v4 v4-v6 v5-v6 v5-v7 v6-v8 v7-v8 v8-v9 v9-v10"
    assert spec.edges == [tuple(e.split("-")) for e in order.split()]
    assert incidence_angle(spec, "v6", "v4") == pytest.approx(math.pi)  # e46 points -x
    assert incidence_angle(spec, "v6", "v5") == pytest.approx(math.pi / 2)  # e56
    assert incidence_angle(spec, "v6", "v8") == pytest.approx(0.0)  # e68
    assert {d["index"] for *_, d in spec.graph().edges(data=True)} == set(range(12))


def test_trees_go_from_path_like_to_star_like():
    radii = [load_arena(f"tree{k}").radius() for k in range(1, 5)]
    degrees = [max(d for _, d in load_arena(f"tree{k}").graph().degree()) for k in range(1, 5)]
    assert radii == sorted(radii, reverse=True) and len(set(radii)) == 4
    assert radii[0] == 12 and degrees[0] == 2  # tree1 is a path from its root
    assert degrees == sorted(degrees) and degrees[-1] >= 4


def test_shipped_path_and_pathlike_give_the_same_spec():
    assert load_arena(SHIPPED_DIR / "fig9.json") == load_arena("fig9")
    assert load_arena(str(SHIPPED_DIR / "fig9.json")) == load_arena("fig9")


# ---------------------------------------------------------------- geometry


def _rect(a, b, half_width):
    """Corners of the rectangle around segment a-b (flat ends), counter-clockwise."""
    a, b = np.asarray(a), np.asarray(b)
    d = (b - a) / np.linalg.norm(b - a)
    n = np.array([-d[1], d[0]]) * half_width
    return np.array([a - n, b - n, b + n, a + n])


def _rects_overlap(p, q):
    """Separating-axis test for two convex quadrilaterals (touching counts as overlap)."""
    for poly in (p, q):
        for k in range(4):
            edge = poly[(k + 1) % 4] - poly[k]
            axis = np.array([-edge[1], edge[0]])
            if (p @ axis).max() < (q @ axis).min() or (q @ axis).max() < (p @ axis).min():
                return False
    return True


def _point_rect_distance(p, a, b, half_width):
    a, b, p = np.asarray(a), np.asarray(b), np.asarray(p)
    length = np.linalg.norm(b - a)
    d = (b - a) / length
    s, t = np.dot(p - a, d), _cross(d, p - a)
    return math.hypot(max(0.0, abs(s - length / 2) - length / 2), max(0.0, abs(t) - half_width))


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


GEOMETRY_ARENAS = list(EXPECTED) + ["random-graph:20:28:1", "random-tree:25:4"]
#: The pairwise rectangle test is quadratic; lattice:10x10 repeats lattice:4x4's local
#: configurations, so it only runs with -m slow.
RECTANGLE_ARENAS = [
    pytest.param(a, marks=pytest.mark.slow) if a == "lattice:10x10" else a
    for a in GEOMETRY_ARENAS
]


@pytest.mark.parametrize("arena", GEOMETRY_ARENAS)
def test_vertex_centres_see_no_wall(arena):
    """A robot at a vertex centre sees no wall within IR range + radius (0.10 + 0.075 m)."""
    spec = load_arena(arena)
    hw = geo.WALL_THICKNESS_M / 2
    nearest = min(
        _point_rect_distance(p, w.start, w.end, hw)
        for p in spec.vertices.values()
        for w in corridor_walls(spec)
    )
    assert nearest > 0.10 + 0.075


@pytest.mark.parametrize("arena", GEOMETRY_ARENAS)
def test_walls_strips_and_spokes_are_laid_out_by_convention(arena):
    spec = load_arena(arena)
    pos = {k: np.asarray(v) for k, v in spec.vertices.items()}

    def frame(u, v, p):  # (along-edge distance from u, signed offset to the left)
        d = (pos[v] - pos[u]) / np.linalg.norm(pos[v] - pos[u])
        return float(np.dot(np.asarray(p) - pos[u], d)), float(_cross(d, np.asarray(p) - pos[u]))

    walls = corridor_walls(spec)
    assert [w.edge for w in walls] == [e for e in spec.edges for _ in range(2)]
    for w in walls:
        u, v = w.edge
        (s0, t0), (s1, t1) = frame(u, v, w.start), frame(u, v, w.end)
        sign = 1 if w.side == "left" else -1
        assert t0 == pytest.approx(sign * 0.20) and t1 == pytest.approx(sign * 0.20)
        length = float(np.linalg.norm(pos[v] - pos[u]))
        assert s0 >= 0.22 - 1e-9 and length - s1 >= 0.22 - 1e-9
        assert s1 - s0 >= geo.MIN_WALL_LENGTH_M - 1e-9
    for lane in lane_strips(spec):
        u, v = lane.travel
        (s0, t0), (s1, t1) = frame(u, v, lane.start), frame(u, v, lane.end)
        assert t0 == pytest.approx(0.09) and t1 == pytest.approx(0.09)  # left of travel
        assert s0 >= 0.16 - 1e-9 and s1 > s0
        assert float(np.linalg.norm(pos[v] - pos[u])) - s1 >= 0.16 - 1e-9
    for spoke in vertex_spokes(spec):
        u = spoke.vertex
        v = spoke.edge[1] if spoke.edge[0] == u else spoke.edge[0]
        assert frame(u, v, spoke.start) == pytest.approx((0.03, 0.0), abs=1e-9)
        assert frame(u, v, spoke.end) == pytest.approx((0.12, 0.0), abs=1e-9)


@pytest.mark.parametrize("arena", RECTANGLE_ARENAS)
def test_pieces_of_different_edges_never_touch_as_rectangles(arena):
    spec = load_arena(arena)
    pieces = [("wall", w.edge, _rect(w.start, w.end, geo.WALL_THICKNESS_M / 2))
              for w in corridor_walls(spec)]
    pieces += [("lane", s.edge, _rect(s.start, s.end, geo.STRIP_WIDTH_M / 2))
               for s in lane_strips(spec)]
    pieces += [("spoke", s.edge, _rect(s.start, s.end, geo.STRIP_WIDTH_M / 2))
               for s in vertex_spokes(spec)]
    for (k1, e1, r1), (k2, e2, r2) in itertools.combinations(pieces, 2):
        # Spokes of one vertex all point at its centre, so they may meet there.
        near = np.linalg.norm(r1.mean(0) - r2.mean(0)) < 3.0
        if e1 != e2 and (k1, k2) != ("spoke", "spoke") and near:
            assert not _rects_overlap(r1, r2), (k1, e1, k2, e2)


@pytest.mark.parametrize("seed", range(25))
def test_candidate_pairs_match_brute_force(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(0, 120))
    scale = 10.0 ** rng.uniform(-1, 2.5)
    lo = rng.uniform(-scale, scale, (n, 2))
    size = rng.exponential(scale / 10, (n, 2)) * (rng.random((n, 1)) < 0.9)  # some points
    boxes = np.hstack([lo, lo + size])
    brute = [
        (i, j)
        for i, j in itertools.combinations(range(n), 2)
        if boxes[i, 0] <= boxes[j, 2] and boxes[j, 0] <= boxes[i, 2]
        and boxes[i, 1] <= boxes[j, 3] and boxes[j, 1] <= boxes[i, 3]
    ]
    assert geo.candidate_pairs(boxes).tolist() == [list(p) for p in brute]


def test_segment_distance_matches_sampling():
    rng = np.random.default_rng(7)
    a, b, c, d = (rng.uniform(-1, 1, (400, 2)) for _ in range(4))
    got = geo.segment_distance(a, b, c, d)
    t = np.linspace(0, 1, 801)[:, None, None]
    p = a + t * (b - a)  # (801, 400, 2) samples on a-b
    sampled = geo.point_segment_distance(p, c, d).min(axis=0)
    assert np.all(got <= sampled + 1e-12)
    assert np.all(sampled - got < 2.0 / 800 * np.linalg.norm(b - a, axis=1) + 1e-12)
    crossing = geo.segments_cross(a, b, c, d)
    assert crossing.any() and np.all(got[crossing] == 0) and np.all(got[~crossing] > 0)


def test_wall_setback_formula():
    # at 90 degrees the offset lines meet 0.21 m out: the clear radius (0.255 m) rules
    assert geo.wall_setback(math.pi / 2) == geo.VERTEX_CLEAR_RADIUS_M == 0.255
    assert geo.wall_setback(math.radians(75)) == pytest.approx(
        0.21 / math.tan(math.radians(37.5)) + 0.02)
    assert geo.wall_setback(2 * math.pi) == geo.wall_setback(math.pi) == 0.255
    assert geo.wall_setback(math.pi / 4) == pytest.approx(0.21 / math.tan(math.pi / 8) + 0.02)
    assert geo.lane_setback(math.pi / 2) == 0.16


@pytest.mark.parametrize("seed", range(20))
def test_setbacks_keep_neighbouring_edges_apart(seed):
    """Two edges at any allowed angle: facing walls and facing lanes do not touch."""
    rng = np.random.default_rng(seed)
    theta = rng.uniform(math.radians(geo.MIN_ANGLE_DEG), math.pi)
    d1, d2 = np.array([1.0, 0.0]), np.array([math.cos(theta), math.sin(theta)])
    for offset, half, setback in (
        (0.20, geo.WALL_THICKNESS_M / 2, geo.wall_setback(theta)),
        (0.09, geo.STRIP_WIDTH_M / 2, geo.lane_setback(theta)),
    ):
        n1, n2 = np.array([0.0, 1.0]), np.array([math.sin(theta), -math.cos(theta)])
        r1 = _rect(setback * d1 + offset * n1, 3 * d1 + offset * n1, half)
        r2 = _rect(setback * d2 + offset * n2, 3 * d2 + offset * n2, half)
        assert not _rects_overlap(r1, r2), math.degrees(theta)


def test_45_degree_star_is_a_valid_arena():
    """The minimum angle is usable: 8 arms 1 m long at 45 degrees validate."""
    vertices = {"c": (0.0, 0.0)}
    for k in range(8):
        vertices[f"t{k}"] = (math.cos(k * math.pi / 4), math.sin(k * math.pi / 4))
    spec = ArenaSpec("star8", "c", vertices, [("c", f"t{k}") for k in range(8)])
    assert spec.radius() == 1


def test_incidence_angle_is_in_0_2pi_and_rejects_non_edges():
    spec = load_arena("tree4")
    for u, v in spec.edges:
        for a, b in ((u, v), (v, u)):
            angle = incidence_angle(spec, a, b)
            assert 0 <= angle < 2 * math.pi
            (xa, ya), (xb, yb) = spec.vertices[a], spec.vertices[b]
            assert (math.cos(angle), math.sin(angle)) == pytest.approx(
                ((xb - xa) / math.dist((xa, ya), (xb, yb)), (yb - ya) / math.dist((xa, ya), (xb, yb)))
            )
    with pytest.raises(KeyError):
        incidence_angle(spec, "v8", "v9")


# ---------------------------------------------------------------- validation

BASE = {"name": "t", "root": "a", "vertices": {"a": [0, 0], "b": [1, 0], "c": [1, 1]},
        "edges": [["a", "b"], ["b", "c"]]}


def _spec(vertices, edges, root="a", **extra):
    return {"name": "t", "root": root, "vertices": vertices, "edges": edges, **extra}


BAD_SPECS = {
    "not an object": ([1, 2], "must be a JSON object"),
    "unknown key": ({**BASE, "egdes": []}, "unknown key 'egdes'"),
    "missing key": ({k: v for k, v in BASE.items() if k != "edges"}, "missing key 'edges'"),
    "name type": ({**BASE, "name": 3}, "'name' must be a string"),
    "vertices type": ({**BASE, "vertices": [[0, 0]]}, "'vertices' must map vertex id"),
    "coordinate type": (
        _spec({"a": [0, "x"], "b": [1, 0]}, [["a", "b"]]), "coordinates must be [x, y] numbers"
    ),
    "coordinate bool": (
        _spec({"a": [0, True], "b": [1, 0]}, [["a", "b"]]), "coordinates must be [x, y] numbers"
    ),
    "three coordinates": (
        _spec({"a": [0, 0, 0], "b": [1, 0]}, [["a", "b"]]), "coordinates must be [x, y]"
    ),
    "non-finite": (_spec({"a": [0, math.inf], "b": [1, 0]}, [["a", "b"]]), "must be finite"),
    "vertex id": (_spec({"a b": [0, 0], "b": [1, 0]}, [["a b", "b"]]), "vertex id 'a b'"),
    "edges type": ({**BASE, "edges": "a-b"}, "'edges' must be a list"),
    "edge shape": ({**BASE, "edges": [["a", "b", "c"]]}, "edge 1: must be a pair"),
    "no edges": ({**BASE, "edges": []}, "no edges"),
    "root": ({**BASE, "root": "zz"}, "root 'zz' is not a vertex"),
    "unknown vertex": ({**BASE, "edges": [["a", "b"], ["b", "z"]]}, "unknown vertex 'z'"),
    "self-loop": ({**BASE, "edges": [["a", "b"], ["c", "c"]]}, "edge c-c is a self-loop"),
    "duplicate edge": (
        {**BASE, "edges": [["a", "b"], ["b", "c"], ["b", "a"]]},
        "duplicate edge b-a (already given as a-b)",
    ),
    "duplicate coordinates": (
        _spec({"a": [0, 0], "b": [1, 0], "c": [1.0, 0.0]}, [["a", "b"], ["a", "c"]]),
        "vertices b and c have the same coordinates",
    ),
    "disconnected": (
        _spec({"a": [0, 0], "b": [1, 0], "c": [5, 5]}, [["a", "b"]]),
        "disconnected: c cannot be reached from root a",
    ),
    "short edge": (
        _spec({"a": [0, 0], "b": [0.4, 0]}, [["a", "b"]]),
        "edge a-b is 0.400 m long, shorter than a robot can follow",
    ),
    "close vertices": (
        _spec({"a": [0, 0], "b": [1, 0], "c": [1, 1], "d": [0.3, 0.2]},
              [["a", "b"], ["b", "c"], ["c", "d"]]),
        "vertices a and d are 0.361 m apart",
    ),
    "through a vertex": (
        _spec({"a": [0, 0], "b": [2, 0], "c": [1, 0]}, [["a", "b"], ["a", "c"]]),
        "edge a-b passes through vertex c",
    ),
    "near a vertex": (
        _spec({"a": [0, 0], "b": [2, 0], "c": [1, 0.1]}, [["a", "b"], ["a", "c"]]),
        "edge a-b passes 0.100 m from vertex c",
    ),
    "crossing": (
        _spec({"a": [0, 0], "b": [2, 0], "c": [1, -1], "d": [1, 1]},
              [["a", "b"], ["c", "d"], ["b", "d"]]),
        "edges a-b and c-d cross away from a vertex",
    ),
    "min angle": (
        _spec({"a": [0, 0], "b": [2, 0], "c": [2 * math.cos(0.5236), 2 * math.sin(0.5236)]},
              [["a", "b"], ["a", "c"]]),
        "edges a-b and a-c meet at a at 30.0 degrees, less than MIN_ANGLE_DEG = 45",
    ),
    "short wall": (
        _spec({"a": [0, 0], "b": [0.8, 0], "c": [0.8 * math.cos(0.8727), 0.8 * math.sin(0.8727)]},
              [["a", "b"], ["a", "c"]]),
        "edge a-b is too short for a robot to follow at its angles: its left wall is 0.075 m",
    ),
    "wall at a vertex": (
        _spec({"a": [0, 0], "b": [3, 0], "w": [1, 0.25], "c": [1, 1.5], "d": [3, 1.5]},
              [["a", "b"], ["w", "c"], ["c", "d"], ["d", "b"]]),
        "the left wall of edge a-b comes 0.040 m from the centre of vertex w",
    ),
    "corridors touch": (
        _spec({"a": [0, 0], "b": [3, 0], "c": [1, 0.41], "d": [2.4, 0.41], "e": [1, 1.6],
               "f": [-0.8, 1.6], "g": [-0.8, 0]},
              [["a", "b"], ["c", "d"], ["c", "e"], ["e", "f"], ["f", "g"], ["g", "a"]]),
        "the left wall of edge a-b touches the right wall of edge c-d",
    ),
}


@pytest.mark.parametrize("case", list(BAD_SPECS))
def test_bad_spec_is_rejected_with_its_message(case):
    data, words = BAD_SPECS[case]
    with pytest.raises(MjswarmError) as err:
        parse_arena_spec(data, source="bad.json")
    message = str(err.value)
    assert message.startswith("bad.json: ") and "\n" not in message
    assert words in message


BAD_FILES = {
    "bad.json": ('{"name": "x",', "bad.json: invalid JSON"),
    "dup.json": ('{"name": "x", "name": "y"}', "dup.json: invalid JSON: duplicate key 'name'"),
    "nan.json": (
        (
            '{"name": "x", "root": "a", "vertices": {"a": [NaN, 0], "b": [1, 0]}, '
            '"edges": [["a", "b"]]}'
        ),
        "nan.json: vertex a: coordinates must be finite",
    ),
    "bad.toml": ('name = "x"\nroot = \n', "bad.toml: invalid TOML"),
    "arena.yaml": ("name: x\n", "unsupported arena file type '.yaml'"),
}


@pytest.mark.parametrize("filename", list(BAD_FILES))
def test_bad_file_is_rejected_with_its_message(tmp_path, filename):
    text, words = BAD_FILES[filename]
    (tmp_path / filename).write_text(text)
    with pytest.raises(MjswarmError) as err:
        load_arena(tmp_path / filename)
    assert words in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize(
    ("arena", "words"),
    [
        ("no_such_arena", "unknown arena 'no_such_arena'"),
        ("missing/arena.json", "missing/arena.json: arena file not found"),
        ("lattice:4", "bad arena generator 'lattice:4': expected lattice:RxC"),
        ("lattice:3x3:abc", "SPACING 'abc' is not a number"),
        ("lattice:1x1", "a lattice needs at least 2 vertices"),
        ("lattice:4x4:0.5", "too short for a robot to follow"),
        ("random-tree:x:1", "expected random-tree:E:SEED"),
        ("random-tree:0:1", "a tree needs at least 1 edge"),
        ("random-graph:6:4:1", "needs at least 5 edges"),
        ("random-graph:6:8:1", "at most 7 edges fit 6 vertices"),
        ("random-graph:1:0:1", "at least 2 vertices"),
    ],
)
def test_bad_arena_argument_is_rejected(arena, words):
    with pytest.raises(MjswarmError, match=None) as err:
        load_arena(arena)
    assert words in str(err.value) and "\n" not in str(err.value)


# ---------------------------------------------------------------- round trips


@pytest.mark.parametrize("arena", list(EXPECTED) + ["random-graph:15:20:7"])
def test_spec_round_trips_through_dict_and_json(arena):
    spec = load_arena(arena)
    assert parse_arena_spec(spec.to_dict()) == spec
    assert hash(parse_arena_spec(spec.to_dict())) == hash(spec)
    assert parse_arena_spec(json.loads(json.dumps(spec.to_dict()))) == spec


def test_toml_spec_loads_like_json(tmp_path):
    spec = load_arena("arena1")
    lines = [f"name = {json.dumps(spec.name)}", f"root = {json.dumps(spec.root)}",
             "edges = [" + ", ".join(f'["{u}", "{v}"]' for u, v in spec.edges) + "]",
             f"description = {json.dumps(spec.description)}", "[vertices]"]
    lines += [f"{k} = [{x!r}, {y!r}]" for k, (x, y) in spec.vertices.items()]
    (tmp_path / "arena1.toml").write_text("\n".join(lines) + "\n")
    loaded = load_arena(str(tmp_path / "arena1.toml"))
    assert loaded == spec and list(loaded.vertices) == list(spec.vertices)


def test_graph_attributes():
    spec = load_arena("tree4")
    g = spec.graph()
    assert list(g.nodes) == list(spec.vertices)
    for u, v, data in g.edges(data=True):
        assert data["length"] == pytest.approx(math.dist(spec.vertices[u], spec.vertices[v]))
        assert g.nodes[u]["pos"] == spec.vertices[u]
    assert spec.total_length() == pytest.approx(sum(d["length"] for *_, d in g.edges(data=True)))


# ---------------------------------------------------------------- generators


def test_lattice_layout():
    spec = load_arena("lattice:3x4:0.75")
    assert spec.root == "v0_0" and spec.vertices["v0_0"] == (0.0, 0.0)
    assert spec.vertices["v2_3"] == pytest.approx((3 * 0.75, 2 * 0.75))
    g = spec.graph()
    assert nx.is_isomorphic(g, nx.grid_2d_graph(3, 4))
    assert all(d["length"] == pytest.approx(0.75) for *_, d in g.edges(data=True))


@pytest.mark.parametrize("n_edges", range(5, 31))
def test_random_tree_is_a_deterministic_valid_tree(n_edges):
    specs = [load_arena(f"random-tree:{n_edges}:{seed}") for seed in range(4)]
    for seed, spec in enumerate(specs):
        g = spec.graph()
        assert nx.is_tree(g) and g.number_of_edges() == n_edges
        assert load_arena(f"random-tree:{n_edges}:{seed}").to_dict() == spec.to_dict()
    assert len({json.dumps(s.to_dict()["edges"]) for s in specs}) > 1


def _random_graph_cases(count=60):
    rng = np.random.default_rng(2024)
    for _ in range(count):
        n_v = int(rng.integers(2, 30))
        n_e = int(rng.integers(n_v - 1, max_lattice_edges(n_v) + 1))
        yield n_v, n_e, int(rng.integers(0, 10_000))


@pytest.mark.parametrize(("n_v", "n_e", "seed"), list(_random_graph_cases()))
def test_random_graph_is_deterministic_planar_and_connected(n_v, n_e, seed):
    text = f"random-graph:{n_v}:{n_e}:{seed}"
    spec = load_arena(text)
    g = spec.graph()
    assert (g.number_of_nodes(), g.number_of_edges()) == (n_v, n_e)
    assert nx.is_connected(g) and nx.check_planarity(g)[0]
    assert load_arena(text) == spec and spec.name == text


@pytest.mark.parametrize("n_v", range(2, 41))
def test_random_graph_reaches_the_lattice_maximum(n_v):
    spec = load_arena(f"random-graph:{n_v}:{max_lattice_edges(n_v)}:{n_v}")
    assert len(spec.edges) == max_lattice_edges(n_v)


def _fixed_polyominoes(n):
    shapes = {frozenset([(0, 0)])}
    for _ in range(n - 1):
        grown = set()
        for shape in shapes:
            for (x, y), (dx, dy) in itertools.product(shape, ((1, 0), (-1, 0), (0, 1), (0, -1))):
                cell = (x + dx, y + dy)
                if cell not in shape:
                    new = shape | {cell}
                    mx, my = min(c[0] for c in new), min(c[1] for c in new)
                    grown.add(frozenset((cx - mx, cy - my) for cx, cy in new))
        shapes = grown
    return shapes


def test_max_lattice_edges_against_brute_force():
    for n in range(1, 9):
        best = max(len(lattice_adjacencies(sorted(s))) for s in _fixed_polyominoes(n))
        assert max_lattice_edges(n) == best, n
    for n in range(1, 400):
        assert len(lattice_adjacencies(compact_cells(n))) == max_lattice_edges(n), n


# ---------------------------------------------------------------- CLI


def test_cli_arena_show(capsys):
    assert main(["arena", "show", "fig9"]) == 0
    out = capsys.readouterr().out
    for line in ("name         fig9", "vertices     10", "edges        12", "root         v1",
                 "radius       6 hops from the root", "tree         no",
                 "total length 7.200 m"):
        assert line in out


def test_cli_arena_show_json(capsys, tmp_path):
    assert main(["arena", "show", "tree1", "--json", "-"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data == load_arena("tree1").summary()
    assert (data["num_vertices"], data["num_edges"], data["is_tree"]) == (13, 12, True)
    assert data["radius_hops"] == 12 and data["total_edge_length_m"] == pytest.approx(7.2)
    assert main(["arena", "show", "lattice:4x4", "--json", str(tmp_path / "s.json")]) == 0
    assert "vertices     16" in capsys.readouterr().out
    assert json.loads((tmp_path / "s.json").read_text())["num_edges"] == 24


@pytest.mark.parametrize("arena", ["nope", "random-graph:4:9:1", "missing.toml"])
def test_cli_arena_show_bad_input(capsys, arena):
    assert main(["arena", "show", arena]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith("mjswarm: error: ") and captured.err.count("\n") == 1
