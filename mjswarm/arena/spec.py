"""Arena specs: a graph of vertex coordinates and edges, the single source of truth.

An :class:`ArenaSpec` is always valid: constructing one runs :func:`validate_arena`,
which raises :class:`~mjswarm.errors.MjswarmError` with one line naming the source and
the problem. Coordinates are metres in the floor plane; the geometry that the spec
implies (lanes, spokes, walls) is in :mod:`mjswarm.arena.geometry`.

File format (JSON or TOML), all keys required except ``description``::

    {"name": "fig9", "description": "...", "root": "v1",
     "vertices": {"v1": [0.0, 0.6], "v2": [0.6, 0.6], ...},
     "edges": [["v1", "v2"], ["v1", "v3"], ...]}

Vertex ids are letters, digits and ``_`` (they become MuJoCo names). Unknown keys are
rejected so that typos do not pass silently. Edge order and orientation are kept as
given (Nagavarapu et al. numbers edges e1, e2, ... in the order listed).
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import networkx as nx
import numpy as np

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

from mjswarm.arena import geometry as geo
from mjswarm.arena.geometry import Point
from mjswarm.errors import MjswarmError

#: Where shipped arenas live: ``models/arenas/<name>.json`` at the repository root.
SHIPPED_DIR = Path(__file__).resolve().parents[2] / "models" / "arenas"

#: Vertex coordinates must lie within this distance of the origin on each axis (m): a
#: lab floor is tens of metres, and MuJoCo's single-precision rendering and the
#: builder's lengths lose their millimetres far beyond a kilometre.
MAX_COORDINATE_M = 1000.0
#: Largest arena (vertices) validated and built: lattice:100x100 validates in about 3 s
#: and 0.7 GB (``/usr/bin/time mjswarm arena show lattice:100x100``), 200x200 in 13 s
#: and 2.1 GB; growing faster than the vertex count.
MAX_VERTICES = 10_000

_REQUIRED_KEYS = ("name", "root", "vertices", "edges")
_OPTIONAL_KEYS = ("description",)
_VERTEX_ID = re.compile(r"[A-Za-z0-9_]+")
_SHIPPED_NAME = re.compile(r"[A-Za-z0-9_-]+")
#: ``ARENA@DEG``: a rotation in degrees (counter-clockwise, about the root)
_ROTATION = re.compile(r"-?(\d+(\.\d*)?|\.\d+)")


@dataclass(frozen=True)
class ArenaSpec:
    """A validated arena graph.

    ``vertices`` maps vertex id to ``(x, y)`` in metres (insertion order kept);
    ``edges`` lists ``(u, v)`` pairs as given; ``root`` is where robots start.
    ``source`` names where the spec came from (file, generator string) for messages
    and is not part of equality.
    """

    name: str
    root: str
    vertices: dict[str, tuple[float, float]]
    edges: list[tuple[str, str]]
    description: str = ""
    source: str = field(default="<spec>", compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "vertices", {k: (float(x), float(y)) for k, (x, y) in self.vertices.items()}
        )
        object.__setattr__(self, "edges", [(u, v) for u, v in self.edges])
        validate_arena(self)

    def __hash__(self) -> int:  # the dict and list fields are not hashable themselves
        return hash(
            (self.name, self.root, tuple(self.vertices.items()), tuple(self.edges), self.description)
        )

    def graph(self) -> nx.Graph:
        """A new networkx graph: node attr ``pos`` = (x, y) m, edge attrs ``length`` (m)
        and ``index`` (0-based position in :attr:`edges`, i.e. e1 is index 0)."""
        g = nx.Graph(name=self.name, root=self.root)
        for vid, pos in self.vertices.items():
            g.add_node(vid, pos=pos)
        for index, (u, v) in enumerate(self.edges):
            g.add_edge(u, v, length=math.dist(self.vertices[u], self.vertices[v]), index=index)
        return g

    def is_tree(self) -> bool:
        """True if the (connected) graph has no cycle, i.e. E = V - 1."""
        return len(self.edges) == len(self.vertices) - 1

    def radius(self) -> int:
        """Hop eccentricity of the root: the most edges on a shortest path from it."""
        return int(nx.eccentricity(self.graph(), v=self.root))

    def total_length(self) -> float:
        """Sum of edge lengths (m), centre line vertex to vertex."""
        return float(sum(math.dist(self.vertices[u], self.vertices[v]) for u, v in self.edges))

    def to_dict(self) -> dict:
        """JSON-able dict in the file format; ``parse_arena_spec`` of it gives an equal spec."""
        return {
            "name": self.name,
            "description": self.description,
            "root": self.root,
            "vertices": {k: [x, y] for k, (x, y) in self.vertices.items()},
            "edges": [[u, v] for u, v in self.edges],
        }

    def summary(self) -> dict:
        """Counts and sizes for ``mjswarm arena show`` (JSON-able)."""
        return {
            "name": self.name,
            "description": self.description,
            "source": self.source,
            "num_vertices": len(self.vertices),
            "num_edges": len(self.edges),
            "root": self.root,
            "radius_hops": self.radius(),
            "is_tree": self.is_tree(),
            "total_edge_length_m": round(self.total_length(), 6),
        }


# ---------------------------------------------------------------- loading


def shipped_arenas() -> list[str]:
    """Names of the arenas shipped in ``models/arenas/``, sorted."""
    return sorted(p.stem for p in SHIPPED_DIR.glob("*.json"))


def load_arena(arena: str | os.PathLike) -> ArenaSpec:
    """Load an arena from a shipped name, a ``.json``/``.toml`` path, or a generator string.

    Generators: see :mod:`mjswarm.arena.generators`. A string is a generator if the text
    before its first ``:`` names one; otherwise a path if it has a suffix or a ``/``;
    otherwise a shipped name. Any of them may end in ``@DEG``: the arena rotated by DEG
    degrees counter-clockwise about its root.
    """
    # Imported here: the generators build ArenaSpecs, so they import this module.
    from mjswarm.arena.generators import GENERATORS, generate, rotated

    text = os.fspath(arena)
    if not isinstance(arena, os.PathLike):
        base, at, degrees = text.rpartition("@")
        if at and _ROTATION.fullmatch(degrees):
            return rotated(load_arena(base), float(degrees), text)
        kind, sep, _ = text.partition(":")
        if sep and kind in GENERATORS:
            return generate(text)
    path = Path(text)
    if isinstance(arena, os.PathLike) or path.suffix or "/" in text or os.sep in text:
        return _load_file(path, text)
    shipped = SHIPPED_DIR / f"{text}.json"
    if _SHIPPED_NAME.fullmatch(text) and shipped.is_file():
        return _load_file(shipped, f"models/arenas/{text}.json")
    raise MjswarmError(
        f"unknown arena {text!r}: not a shipped arena ({', '.join(shipped_arenas())}), "
        f"a .json/.toml file, or a generator ({', '.join(GENERATORS.values())})"
    )


def _load_file(path: Path, shown: str) -> ArenaSpec:
    suffix = path.suffix.lower()
    if suffix not in (".json", ".toml"):
        raise MjswarmError(f"{shown}: unsupported arena file type {suffix!r} (use .json or .toml)")
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MjswarmError(f"{shown}: arena file not found") from None
    except UnicodeDecodeError:
        raise MjswarmError(f"{shown}: arena file is not UTF-8 text") from None
    except OSError as exc:
        raise MjswarmError(f"{shown}: cannot read arena file ({exc.strerror})") from None
    try:
        if suffix == ".json":
            data = json.loads(text, object_pairs_hook=_reject_duplicate_keys)
        else:
            data = tomllib.loads(text)
    except json.JSONDecodeError as exc:
        raise MjswarmError(f"{shown}: invalid JSON: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise MjswarmError(f"{shown}: invalid TOML: {exc}") from None
    except _DuplicateKey as exc:
        raise MjswarmError(f"{shown}: invalid JSON: duplicate key {exc.args[0]!r}") from None
    return parse_arena_spec(data, source=shown)


class _DuplicateKey(Exception):
    pass


def _reject_duplicate_keys(pairs: list[tuple[str, object]]) -> dict:
    seen: dict = {}
    for key, value in pairs:
        if key in seen:
            raise _DuplicateKey(key)
        seen[key] = value
    return seen


# ---------------------------------------------------------------- parsing (types)


def parse_arena_spec(data: dict, source: str = "<dict>") -> ArenaSpec:
    """Check the types of a spec mapping (parsed JSON/TOML) and build a validated spec.

    Raises :class:`MjswarmError` ``"<source>: <problem>"`` on the first problem found.
    """

    def fail(problem: str) -> MjswarmError:
        return MjswarmError(f"{source}: {problem}")

    if not isinstance(data, dict):
        raise fail(f"an arena spec must be a JSON object / TOML table, not {_kind(data)}")
    allowed = _REQUIRED_KEYS + _OPTIONAL_KEYS
    for key in data:
        if key not in allowed:
            raise fail(f"unknown key {key!r} (allowed: {', '.join(allowed)})")
    for key in _REQUIRED_KEYS:
        if key not in data:
            raise fail(f"missing key {key!r}")
    for key in ("name", "root", "description"):
        if key in data and not isinstance(data[key], str):
            raise fail(f"{key!r} must be a string, not {_kind(data[key])}")
    if not data["name"].strip() or "\n" in data["name"]:
        raise fail("'name' must be a non-empty single line")

    vertices = data["vertices"]
    if not isinstance(vertices, dict):
        raise fail(f"'vertices' must map vertex id to [x, y], not {_kind(vertices)}")
    coords: dict[str, tuple[float, float]] = {}
    for vid, xy in vertices.items():
        if not (isinstance(vid, str) and _VERTEX_ID.fullmatch(vid)):
            raise fail(f"vertex id {vid!r} must use only letters, digits and '_'")
        if not (isinstance(xy, (list, tuple)) and len(xy) == 2 and all(map(_is_real, xy))):
            raise fail(f"vertex {vid}: coordinates must be [x, y] numbers in metres, not {xy!r}")
        if not all(math.isfinite(c) for c in xy):
            raise fail(f"vertex {vid}: coordinates must be finite, not {list(xy)!r}")
        coords[vid] = (float(xy[0]), float(xy[1]))

    edges = data["edges"]
    if not isinstance(edges, list):
        raise fail(f"'edges' must be a list of [u, v] pairs, not {_kind(edges)}")
    pairs: list[tuple[str, str]] = []
    for k, e in enumerate(edges, start=1):
        if not (isinstance(e, (list, tuple)) and len(e) == 2 and all(isinstance(x, str) for x in e)):
            raise fail(f"edge {k}: must be a pair of vertex ids [u, v], not {e!r}")
        pairs.append((e[0], e[1]))

    return ArenaSpec(
        name=data["name"],
        root=data["root"],
        vertices=coords,
        edges=pairs,
        description=data.get("description", ""),
        source=source,
    )


def _is_real(x: object) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _kind(x: object) -> str:
    return {dict: "an object", list: "a list", str: "a string"}.get(type(x), type(x).__name__)


# ---------------------------------------------------------------- validation (geometry)

Fail = Callable[[str], MjswarmError]


def validate_arena(spec: ArenaSpec) -> None:
    """Raise :class:`MjswarmError` ``"<source>: <problem>"`` unless ``spec`` is a usable arena.

    Checks, in this order (the first failure is reported): at most MAX_VERTICES
    vertices, each within MAX_COORDINATE_M of the origin on both axes; at least one edge; root is a
    vertex; edges name known vertices, no self-loops, no duplicates (either orientation);
    no two vertices at the same coordinates; connected; every edge at least
    MIN_EDGE_LENGTH_M long; vertices at least MIN_EDGE_LENGTH_M apart; no edge passing
    through (within a corridor half-width of) a third vertex; no two edges crossing;
    consecutive edges at a vertex at least MIN_ANGLE_DEG apart; each wall at least
    MIN_WALL_LENGTH_M long after its setbacks; no wall within VERTEX_OPEN_RADIUS_M of a
    vertex centre; no wall, lane strip or spoke of one edge touching one of another
    edge (except spokes with spokes: they all converge on their vertex by design).
    """

    def fail(problem: str) -> MjswarmError:
        return MjswarmError(f"{spec.source}: {problem}")

    _check_size(spec, fail)
    _check_graph(spec, fail)
    layout = _Layout(spec)
    _check_distances(spec, layout, fail)
    _check_angles(spec, fail)
    walls = geo.corridor_walls(spec)
    _check_wall_lengths(spec, walls, fail)
    _check_vertices_open(layout, walls, fail)
    _check_pieces_apart(spec, walls, fail)


class _Layout:
    """Vertex coordinates as arrays: ``xy[k]`` of ``ids[k]``; edge k is ``eu[k]``-``ev[k]``."""

    def __init__(self, spec: ArenaSpec) -> None:
        self.ids = list(spec.vertices)
        self.xy = np.array([spec.vertices[v] for v in self.ids])
        index = {v: k for k, v in enumerate(self.ids)}
        self.eu = np.array([index[u] for u, _ in spec.edges])
        self.ev = np.array([index[v] for _, v in spec.edges])


def _check_size(spec: ArenaSpec, fail: Fail) -> None:
    """At most MAX_VERTICES vertices, every coordinate within MAX_COORDINATE_M."""
    if len(spec.vertices) > MAX_VERTICES:
        raise fail(f"{len(spec.vertices)} vertices: arenas have at most {MAX_VERTICES}")
    for vid, xy in spec.vertices.items():
        if not all(math.isfinite(c) and abs(c) <= MAX_COORDINATE_M for c in xy):
            raise fail(f"vertex {vid}: coordinates must be finite and within "
                       f"+-{MAX_COORDINATE_M:g} m, not {list(xy)!r}")


def _check_graph(spec: ArenaSpec, fail: Fail) -> None:
    """Edges, root, duplicate coordinates and connectivity."""
    pos = spec.vertices
    if not spec.edges:
        raise fail("the arena has no edges (it needs at least one)")
    if spec.root not in pos:
        raise fail(f"root {spec.root!r} is not a vertex")
    given: dict[frozenset, tuple[str, str]] = {}
    for u, v in spec.edges:
        for x in (u, v):
            if x not in pos:
                raise fail(f"edge {u}-{v} names unknown vertex {x!r}")
        if u == v:
            raise fail(f"edge {u}-{v} is a self-loop")
        key = frozenset((u, v))
        if key in given:
            a, b = given[key]
            raise fail(f"duplicate edge {u}-{v} (already given as {a}-{b})")
        given[key] = (u, v)
    at: dict[tuple[float, float], str] = {}
    for vid, xy in pos.items():
        if xy in at:
            raise fail(f"vertices {at[xy]} and {vid} have the same coordinates {list(xy)}")
        at[xy] = vid
    g = nx.Graph(spec.edges)
    g.add_nodes_from(pos)
    reached = nx.node_connected_component(g, spec.root)
    if len(reached) < len(pos):
        cut = [v for v in pos if v not in reached]
        more = f" and {len(cut) - 5} more" if len(cut) > 5 else ""
        raise fail(
            f"the graph is disconnected: {', '.join(cut[:5])}{more} cannot be reached "
            f"from root {spec.root}"
        )


def _check_distances(spec: ArenaSpec, lay: _Layout, fail: Fail) -> None:
    """Edge lengths, vertex spacing, edges clear of other vertices, no crossings."""
    xy, eu, ev, ids = lay.xy, lay.eu, lay.ev, lay.ids
    length = np.linalg.norm(xy[ev] - xy[eu], axis=1)
    short = np.flatnonzero(length < geo.MIN_EDGE_LENGTH_M)
    if short.size:
        u, v = spec.edges[short[0]]
        raise fail(
            f"edge {u}-{v} is {length[short[0]]:.3f} m long, shorter than a robot can "
            f"follow (MIN_EDGE_LENGTH_M = {geo.MIN_EDGE_LENGTH_M} m)"
        )

    half = geo.MIN_EDGE_LENGTH_M / 2
    pairs = geo.candidate_pairs(np.hstack([xy - half, xy + half]))
    gap = np.linalg.norm(xy[pairs[:, 0]] - xy[pairs[:, 1]], axis=1)
    close = pairs[gap < geo.MIN_EDGE_LENGTH_M]
    if close.size:
        i, j = close[0]
        raise fail(
            f"vertices {ids[i]} and {ids[j]} are {math.dist(xy[i], xy[j]):.3f} m apart, less "
            f"than MIN_EDGE_LENGTH_M = {geo.MIN_EDGE_LENGTH_M} m"
        )

    corridor = geo.CORRIDOR_HALF_WIDTH_M + geo.WALL_THICKNESS_M / 2
    ek, vk = _segment_point_pairs(xy[eu], xy[ev], corridor, xy)
    keep = (vk != eu[ek]) & (vk != ev[ek])
    ek, vk = ek[keep], vk[keep]
    dist = geo.point_segment_distance(xy[vk], xy[eu[ek]], xy[ev[ek]])
    near = np.flatnonzero(dist < corridor)
    if near.size:
        k = near[0]
        u, v = spec.edges[ek[k]]
        where = "through" if dist[k] < 1e-9 else f"{dist[k]:.3f} m from"
        raise fail(
            f"edge {u}-{v} passes {where} vertex {ids[vk[k]]} (edges must keep "
            f"{corridor:.2f} m, a corridor half-width, from other vertices)"
        )

    pairs = geo.candidate_pairs(geo.segment_boxes(xy[eu], xy[ev], 0.0))
    i, j = pairs[:, 0], pairs[:, 1]
    disjoint = (eu[i] != eu[j]) & (eu[i] != ev[j]) & (ev[i] != eu[j]) & (ev[i] != ev[j])
    i, j = i[disjoint], j[disjoint]
    crossing = np.flatnonzero(geo.segments_cross(xy[eu[i]], xy[ev[i]], xy[eu[j]], xy[ev[j]]))
    if crossing.size:
        (p, q), (r, s) = spec.edges[i[crossing[0]]], spec.edges[j[crossing[0]]]
        raise fail(f"edges {p}-{q} and {r}-{s} cross away from a vertex")


def _check_angles(spec: ArenaSpec, fail: Fail) -> None:
    """Consecutive edges around every vertex at least MIN_ANGLE_DEG apart."""
    given = {frozenset(e): e for e in spec.edges}

    def name(u: str, v: str) -> str:
        return "-".join(given[frozenset((u, v))])

    min_angle = math.radians(geo.MIN_ANGLE_DEG)
    for u, fan in geo.vertex_fans(spec).items():
        if len(fan) < 2:
            continue
        for k, (angle, v) in enumerate(fan):
            next_angle, w = fan[(k + 1) % len(fan)]
            sweep = (next_angle - angle) % (2 * math.pi)
            if sweep < min_angle - 1e-9:
                raise fail(
                    f"edges {name(u, v)} and {name(u, w)} meet at {u} at "
                    f"{math.degrees(sweep):.1f} degrees, less than MIN_ANGLE_DEG = "
                    f"{geo.MIN_ANGLE_DEG:g}"
                )


def _check_wall_lengths(spec: ArenaSpec, walls: list[geo.Wall], fail: Fail) -> None:
    """Each wall at least MIN_WALL_LENGTH_M long between its setbacks."""
    for wall in walls:
        u, v = wall.edge
        pu, pv = np.asarray(spec.vertices[u]), np.asarray(spec.vertices[v])
        along = (pv - pu) / np.linalg.norm(pv - pu)
        at_u = float(np.dot(np.asarray(wall.start) - pu, along))
        at_v = float(np.dot(pv - np.asarray(wall.end), along))
        remaining = float(np.linalg.norm(pv - pu)) - at_u - at_v
        if remaining < geo.MIN_WALL_LENGTH_M - 1e-9:
            raise fail(
                f"edge {u}-{v} is too short for a robot to follow at its angles: its "
                f"{wall.side} wall is {remaining:.3f} m after setbacks of {at_u:.3f} m at {u} "
                f"and {at_v:.3f} m at {v} (MIN_WALL_LENGTH_M = {geo.MIN_WALL_LENGTH_M} m)"
            )


def _check_vertices_open(lay: _Layout, walls: list[geo.Wall], fail: Fail) -> None:
    """No wall within VERTEX_OPEN_RADIUS_M of any vertex centre."""
    a = np.array([w.start for w in walls])
    b = np.array([w.end for w in walls])
    hw = geo.WALL_THICKNESS_M / 2
    wk, vk = _segment_point_pairs(a, b, hw + geo.VERTEX_OPEN_RADIUS_M, lay.xy)
    dist = geo.point_segment_distance(lay.xy[vk], a[wk], b[wk]) - hw
    blocked = np.flatnonzero(dist < geo.VERTEX_OPEN_RADIUS_M)
    if blocked.size:
        k = blocked[0]
        wall = walls[wk[k]]
        raise fail(
            f"the {wall.side} wall of edge {wall.edge[0]}-{wall.edge[1]} comes "
            f"{dist[k]:.3f} m from the centre of vertex {lay.ids[vk[k]]} (a robot there must "
            f"see no wall within {geo.VERTEX_OPEN_RADIUS_M:.3f} m)"
        )


def _check_pieces_apart(spec: ArenaSpec, walls: list[geo.Wall], fail: Fail) -> None:
    """No wall, lane strip or spoke of one edge touches one of another edge (as capsules).

    Spoke pairs are exempt: the spokes of a vertex all point at its centre.
    """
    pieces: list[tuple[str, tuple[str, str], Point, Point, float]] = []
    for w in walls:
        pieces.append((f"{w.side} wall", w.edge, w.start, w.end, geo.WALL_THICKNESS_M / 2))
    for s in geo.lane_strips(spec):
        label = f"lane strip for {s.travel[0]}->{s.travel[1]}"
        pieces.append((label, s.edge, s.start, s.end, geo.STRIP_WIDTH_M / 2))
    n_not_spokes = len(pieces)
    for s in geo.vertex_spokes(spec):
        pieces.append((f"spoke at {s.vertex}", s.edge, s.start, s.end, geo.STRIP_WIDTH_M / 2))
    owner_of = {e: k for k, e in enumerate(spec.edges)}
    owner = np.array([owner_of[p[1]] for p in pieces])
    a = np.array([p[2] for p in pieces])
    b = np.array([p[3] for p in pieces])
    hw = np.array([p[4] for p in pieces])
    pairs = geo.candidate_pairs(geo.segment_boxes(a, b, hw))
    i, j = pairs[:, 0], pairs[:, 1]
    keep = (owner[i] != owner[j]) & (i < n_not_spokes)  # i < j: j may be a spoke, i not
    i, j = i[keep], j[keep]
    hits = np.flatnonzero(geo.segment_distance(a[i], b[i], a[j], b[j]) < hw[i] + hw[j])
    if hits.size:
        (lp, ep, *_), (lq, eq, *_) = pieces[i[hits[0]]], pieces[j[hits[0]]]
        raise fail(
            f"the {lp} of edge {ep[0]}-{ep[1]} touches the {lq} of edge {eq[0]}-{eq[1]} "
            "(corridors too close)"
        )


def _segment_point_pairs(
    a: np.ndarray, b: np.ndarray, pad: float, points: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Candidate (segment index, point index) pairs: point inside the segment's box + pad."""
    n = len(a)
    pairs = geo.candidate_pairs(
        np.vstack([geo.segment_boxes(a, b, pad), np.hstack([points, points])])
    )
    seg, pt = pairs[:, 0], pairs[:, 1] - n  # sorted pairs: a segment comes first
    keep = (seg < n) & (pt >= 0)
    return seg[keep], pt[keep]
