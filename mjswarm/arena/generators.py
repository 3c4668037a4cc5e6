"""Arena generators: lattices and seeded random trees / planar graphs.

Every generator is a deterministic function of its arguments (randomness from
``numpy.random.default_rng(seed)``) and returns a validated :class:`ArenaSpec` whose
``name`` and ``source`` are the canonical generator string.

``lattice:RxC[:SPACING]``
    R rows (along y) by C columns (along x), SPACING metres apart (default
    ``LATTICE_SPACING_M`` = 0.6 m). Vertex ``v<row>_<col>`` sits at
    ``(col * SPACING, row * SPACING)``; the root is the corner ``v0_0`` at the origin.
    Edges are listed row by row, each vertex giving its edge to the right, then up.

``random-graph:V:E:SEED``
    A connected planar graph drawn on the square lattice (spacing 0.6 m), so every
    geometric rule holds by construction (angles are multiples of 90 degrees, edges
    0.6 m). First a random lattice animal of V cells is grown from the origin (Eden
    growth: a frontier cell is added with probability proportional to
    ``(occupied neighbours) ** c``, c = 0 first; if the animal has fewer than E
    lattice adjacencies, it is regrown with c = 1, 2, ... and finally replaced by the
    most compact shape, V cells filled row by row ``ceil(sqrt(V))`` wide). Then a
    random spanning tree of its adjacencies (Kruskal on uniform random weights) plus
    E - (V - 1) further adjacencies drawn uniformly. Vertices are ``v0``, ``v1``, ...
    in growth order, root ``v0`` at the origin. Impossible when E < V - 1 or when E
    exceeds the most edges V lattice points can have, 2V - ceil(2 sqrt V) (Harary and
    Harborth 1976); both raise :class:`MjswarmError`. Denser planar graphs exist with
    other angles, but this generator does not make them.

``random-tree:E:SEED``
    ``random-graph:(E+1):E:SEED``: a random tree with E edges on the lattice.

Generators beyond the square lattice (vertices whose edges are 45 to 120 degrees apart,
for the stress grid, ``python -m mjswarm.experiments.stress``). Where a length has a default it is the smallest multiple of
``DEFAULT_STEP_M`` for which every rule of :mod:`mjswarm.arena.spec` holds, found by
asking the validator, not by a formula:

``fan:N:DEG[:LEN]``
    A star: centre ``c`` with N edges DEG degrees apart (the first along +x) to leaves
    ``l0``, ``l1``, ... LEN metres out (default: the smallest valid). Root ``l0``, so the
    robots reach the acute vertex along an edge.
``wheel:N[:R]``
    N rim vertices ``r0``.. at radius R metres (default: the smallest valid) around a
    centre ``c``: spokes ``c``-``ri`` and rim edges ``ri``-``r(i+1)``. N from 4 (45 degrees
    at the rim) to 8 (45 degrees at the centre). Root ``r0``.
``hex:RxC[:SPACING]``
    A honeycomb of R by C hexagons (:func:`networkx.hexagonal_lattice_graph`), edges
    SPACING metres long (default 0.6), 120 degrees apart; vertices ``v<i>_<j>``, root the
    first vertex networkx lists.
``tri:RxC[:SPACING]``
    A triangular lattice (:func:`networkx.triangular_lattice_graph`: R rows, C
    triangles a row), 60 degrees between edges, SPACING metres (default: the smallest
    valid). Root ``v0_0``.
``random-planar:V:SEED``
    A random connected planar graph with arbitrary angles: V points drawn in a square by
    rejection (at least the validator's shortest edge apart), their Delaunay
    triangulation (:class:`scipy.spatial.Delaunay`), then edges dropped in a seeded order
    while the validator rejects the graph and the edge it names can go without
    disconnecting it. Root ``v0``.

Any arena name may end in ``@DEG`` to rotate it by DEG degrees counter-clockwise about its
root (:func:`rotated`, applied by :func:`mjswarm.arena.load_arena`).
"""

from __future__ import annotations

import math
import re

import networkx as nx
import numpy as np

from mjswarm.arena import geometry

from mjswarm.arena.spec import MAX_VERTICES, ArenaSpec
from mjswarm.errors import MjswarmError

#: Default lattice spacing (m), also used by the random generators.
LATTICE_SPACING_M = 0.6

#: Generator name -> usage, for help and error messages.
GENERATORS = {
    "lattice": "lattice:RxC[:SPACING]",
    "random-tree": "random-tree:E:SEED",
    "random-graph": "random-graph:V:E:SEED",
    "fan": "fan:N:DEG[:LEN]",
    "wheel": "wheel:N[:R]",
    "hex": "hex:RxC[:SPACING]",
    "tri": "tri:RxC[:SPACING]",
    "random-planar": "random-planar:V:SEED",
}

_NUMBER = r"(\d+(?:\.\d*)?|\.\d+)"
_PATTERNS = {
    "lattice": re.compile(r"lattice:(\d+)x(\d+)(?::([^:]+))?"),
    "random-tree": re.compile(r"random-tree:(\d+):(\d+)"),
    "random-graph": re.compile(r"random-graph:(\d+):(\d+):(\d+)"),
    "fan": re.compile(rf"fan:(\d+):{_NUMBER}(?::{_NUMBER})?"),
    "wheel": re.compile(rf"wheel:(\d+)(?::{_NUMBER})?"),
    "hex": re.compile(rf"hex:(\d+)x(\d+)(?::{_NUMBER})?"),
    "tri": re.compile(rf"tri:(\d+)x(\d+)(?::{_NUMBER})?"),
    "random-planar": re.compile(r"random-planar:(\d+):(\d+)"),
}
#: Step (m) of the searches for the smallest valid default length, and their limit.
DEFAULT_STEP_M = 0.05
_LONGEST_DEFAULT_M = 5.0
_NEIGHBOURS = ((1, 0), (-1, 0), (0, 1), (0, -1))
#: Compactness exponents tried by the Eden growth before the compact fallback.
_COMPACTNESS = (0, 1, 2, 4, 8)


def generate(text: str) -> ArenaSpec:
    """Build the arena a generator string describes (see the module docstring)."""
    kind = text.partition(":")[0]
    if kind not in GENERATORS:
        raise MjswarmError(
            f"unknown arena generator {kind!r} (known: {', '.join(GENERATORS.values())})"
        )
    match = _PATTERNS[kind].fullmatch(text)
    if match is None:
        raise MjswarmError(
            f"bad arena generator {text!r}: expected {GENERATORS[kind]} (whole numbers"
            + (", SPACING in metres)" if kind == "lattice" else ")")
        )
    counts = [int(g) for g in match.groups()[:2] if g is not None and g.isdigit()]
    size = counts[0] * counts[1] if "x" in text else counts[0]  # RxC, else V, E or N
    if size > MAX_VERTICES:
        raise MjswarmError(f"{text}: about {size} vertices; arenas have at most "
                           f"{MAX_VERTICES}")
    if kind == "lattice":
        rows, cols, spacing = match.groups()
        if spacing is None:
            return lattice(int(rows), int(cols))
        try:
            value = float(spacing)
        except ValueError:
            raise MjswarmError(
                f"bad arena generator {text!r}: SPACING {spacing!r} is not a number (metres)"
            ) from None
        return lattice(int(rows), int(cols), value)
    if kind == "random-tree":
        edges, seed = map(int, match.groups())
        return random_tree(edges, seed)
    if kind == "random-graph":
        vertices, edges, seed = map(int, match.groups())
        return random_graph(vertices, edges, seed)
    if kind == "random-planar":
        vertices, seed = map(int, match.groups())
        return random_planar(vertices, seed)
    *counts, length = match.groups()
    length = None if length is None else float(length)
    if kind == "fan":
        return fan(int(counts[0]), float(counts[1]), length)
    if kind == "wheel":
        return wheel(int(counts[0]), length)
    return (hex_lattice if kind == "hex" else tri_lattice)(int(counts[0]), int(counts[1]), length)


def lattice(rows: int, cols: int, spacing: float = LATTICE_SPACING_M) -> ArenaSpec:
    """A rows x cols square lattice, ``spacing`` metres apart, root at corner ``v0_0``."""
    text = f"lattice:{rows}x{cols}" + (f":{spacing:g}" if spacing != LATTICE_SPACING_M else "")
    if rows < 1 or cols < 1 or rows * cols < 2:
        raise MjswarmError(f"{text}: a lattice needs at least 2 vertices (R, C >= 1)")
    if not (math.isfinite(spacing) and spacing > 0):
        raise MjswarmError(f"{text}: SPACING must be a positive number of metres")
    vertices = {
        f"v{r}_{c}": (round(c * spacing, 9), round(r * spacing, 9))
        for r in range(rows)
        for c in range(cols)
    }
    edges = []
    for r in range(rows):
        for c in range(cols):
            if c + 1 < cols:
                edges.append((f"v{r}_{c}", f"v{r}_{c + 1}"))
            if r + 1 < rows:
                edges.append((f"v{r}_{c}", f"v{r + 1}_{c}"))
    return ArenaSpec(
        name=text,
        root="v0_0",
        vertices=vertices,
        edges=edges,
        description=f"{rows} x {cols} square lattice, {spacing:g} m spacing, root at corner v0_0",
        source=text,
    )


def random_tree(edges: int, seed: int) -> ArenaSpec:
    """A random tree with ``edges`` edges on the square lattice (see the module docstring)."""
    if edges < 1:
        raise MjswarmError(f"random-tree:{edges}:{seed}: a tree needs at least 1 edge")
    return _lattice_graph(edges + 1, edges, seed, f"random-tree:{edges}:{seed}")


def random_graph(vertices: int, edges: int, seed: int) -> ArenaSpec:
    """A random connected planar graph on the square lattice (see the module docstring)."""
    return _lattice_graph(vertices, edges, seed, f"random-graph:{vertices}:{edges}:{seed}")


def max_lattice_edges(vertices: int) -> int:
    """Most edges among ``vertices`` points of the square lattice: 2V - ceil(2 sqrt V)."""
    return 2 * vertices - (math.isqrt(4 * vertices - 1) + 1)


def compact_cells(n: int) -> list[tuple[int, int]]:
    """``n`` lattice cells filled row by row, ceil(sqrt(n)) wide: a shape with the most
    adjacencies, :func:`max_lattice_edges` (checked by brute force in the tests)."""
    width = math.isqrt(n - 1) + 1
    return [(k % width, k // width) for k in range(n)]


def lattice_adjacencies(cells: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Index pairs ``(i, j)``, ``i < j``, of cells one lattice step apart, sorted."""
    where = {cell: k for k, cell in enumerate(cells)}
    pairs = []
    for k, (x, y) in enumerate(cells):
        for nb in ((x + 1, y), (x, y + 1)):
            if nb in where:
                pairs.append((min(k, where[nb]), max(k, where[nb])))
    return sorted(pairs)


def _lattice_graph(n_vertices: int, n_edges: int, seed: int, text: str) -> ArenaSpec:
    if n_vertices < 2:
        raise MjswarmError(f"{text}: a random graph needs at least 2 vertices")
    if n_edges < n_vertices - 1:
        raise MjswarmError(
            f"{text}: a connected graph on {n_vertices} vertices needs at least "
            f"{n_vertices - 1} edges"
        )
    most = max_lattice_edges(n_vertices)
    if n_edges > most:
        raise MjswarmError(
            f"{text}: at most {most} edges fit {n_vertices} vertices on the square lattice "
            "this generator uses (2V - ceil(2 sqrt V))"
        )
    rng = np.random.default_rng(seed)
    cells = _cells_with_adjacencies(n_vertices, n_edges, rng)
    adjacent = lattice_adjacencies(cells)
    weights = rng.random(len(adjacent))
    g = nx.Graph()
    for (i, j), w in zip(adjacent, weights):
        g.add_edge(i, j, weight=w)
    tree = {tuple(sorted(e)) for e in nx.minimum_spanning_edges(g, data=False)}
    rest = [e for e in adjacent if e not in tree]
    extra = rng.choice(len(rest), size=n_edges - len(tree), replace=False)
    chosen = sorted(tree | {rest[k] for k in extra})
    kind = "tree" if n_edges == n_vertices - 1 else "planar graph"
    return ArenaSpec(
        name=text,
        root="v0",
        vertices={
            f"v{k}": (x * LATTICE_SPACING_M, y * LATTICE_SPACING_M)
            for k, (x, y) in enumerate(cells)
        },
        edges=[(f"v{i}", f"v{j}") for i, j in chosen],
        description=(
            f"random {kind} ({n_vertices} vertices, {n_edges} edges, seed {seed}) on the "
            f"square lattice, {LATTICE_SPACING_M:g} m spacing, root v0 at the origin"
        ),
        source=text,
    )


def _cells_with_adjacencies(n: int, need: int, rng: np.random.Generator) -> list[tuple[int, int]]:
    """A random lattice animal of ``n`` cells with at least ``need`` adjacencies."""
    for compactness in _COMPACTNESS:
        cells = _eden_growth(n, compactness, rng)
        if len(lattice_adjacencies(cells)) >= need:
            return cells
    return compact_cells(n)


def _eden_growth(n: int, compactness: float, rng: np.random.Generator) -> list[tuple[int, int]]:
    """Grow ``n`` cells from the origin; a frontier cell with k occupied neighbours is
    added with probability proportional to ``k ** compactness``."""
    cells = [(0, 0)]
    occupied = {(0, 0)}
    frontier: dict[tuple[int, int], int] = {}
    while len(cells) < n:
        x, y = cells[-1]
        for dx, dy in _NEIGHBOURS:
            nb = (x + dx, y + dy)
            if nb not in occupied:
                frontier[nb] = frontier.get(nb, 0) + 1
        candidates = sorted(frontier)
        weights = np.array([frontier[c] for c in candidates], float) ** compactness
        cell = candidates[rng.choice(len(candidates), p=weights / weights.sum())]
        del frontier[cell]
        occupied.add(cell)
        cells.append(cell)
    return cells


# ---------------------------------------------------------------- beyond the square lattice


def fan(n: int, degrees: float, length: float | None = None) -> ArenaSpec:
    """A star of ``n`` edges ``degrees`` apart (see the module docstring)."""
    text = f"fan:{n}:{degrees:g}" + ("" if length is None else f":{length:g}")
    last_gap = 360.0 - (n - 1) * degrees
    if n < 2 or degrees < geometry.MIN_ANGLE_DEG or last_gap < geometry.MIN_ANGLE_DEG - 1e-9:
        raise MjswarmError(f"{text}: needs N >= 2 edges at least {geometry.MIN_ANGLE_DEG:g} "
                           "degrees apart all round (DEG >= 45 and 360 - (N-1) DEG >= 45)")

    def build(r: float) -> ArenaSpec:
        leaves = {f"l{k}": _polar(r, math.radians(k * degrees)) for k in range(n)}
        return ArenaSpec(text, "l0", {"c": (0.0, 0.0), **leaves},
                         [("c", leaf) for leaf in leaves],
                         f"{n} edges {degrees:g} degrees apart from centre c, {r:g} m long",
                         text)

    return _with_length(text, build, length)


def wheel(n: int, radius: float | None = None) -> ArenaSpec:
    """A rim of ``n`` vertices with spokes to a centre (see the module docstring)."""
    text = f"wheel:{n}" + ("" if radius is None else f":{radius:g}")
    if not 4 <= n <= 8:
        raise MjswarmError(f"{text}: N must be 4..8 (rim angles (N-2) 90/N degrees and "
                           "centre angles 360/N degrees must be at least 45)")

    def build(r: float) -> ArenaSpec:
        rim = {f"r{k}": _polar(r, 2 * math.pi * k / n) for k in range(n)}
        edges = [("c", f"r{k}") for k in range(n)] + [(f"r{k}", f"r{(k + 1) % n}")
                                                     for k in range(n)]
        return ArenaSpec(text, "r0", {"c": (0.0, 0.0), **rim}, edges,
                         f"wheel: {n} rim vertices at {r:g} m around centre c", text)

    return _with_length(text, build, radius)


def hex_lattice(rows: int, cols: int, spacing: float | None = None) -> ArenaSpec:
    """A honeycomb of ``rows`` x ``cols`` hexagons (see the module docstring)."""
    text = f"hex:{rows}x{cols}" + ("" if spacing is None else f":{spacing:g}")
    if rows < 1 or cols < 1:
        raise MjswarmError(f"{text}: needs R, C >= 1 hexagons")
    graph = nx.hexagonal_lattice_graph(rows, cols, with_positions=True)
    return _networkx_arena(text, graph, LATTICE_SPACING_M if spacing is None else spacing,
                           "honeycomb lattice")


def tri_lattice(rows: int, cols: int, spacing: float | None = None) -> ArenaSpec:
    """A triangular lattice (see the module docstring)."""
    text = f"tri:{rows}x{cols}" + ("" if spacing is None else f":{spacing:g}")
    if rows < 1 or cols < 1:
        raise MjswarmError(f"{text}: needs R, C >= 1")
    graph = nx.triangular_lattice_graph(rows, cols, with_positions=True)
    return _with_length(text, lambda d: _networkx_arena(text, graph, d, "triangular lattice"),
                        spacing)


def random_planar(n_vertices: int, seed: int) -> ArenaSpec:
    """A random planar graph with arbitrary angles (see the module docstring)."""
    text = f"random-planar:{n_vertices}:{seed}"
    if n_vertices < 3:
        raise MjswarmError(f"{text}: needs at least 3 vertices")
    rng = np.random.default_rng(seed)
    for _ in range(_PLANAR_TRIES):
        spec = _pruned_delaunay(text, n_vertices, seed, rng)
        if spec is not None:
            return spec
    raise MjswarmError(f"{text}: no valid arena in {_PLANAR_TRIES} point sets")


def _pruned_delaunay(text: str, n: int, seed: int, rng: np.random.Generator):
    """One try of :func:`random_planar`: None if pruning would disconnect the graph."""
    gap = 1.5 * geometry.MIN_EDGE_LENGTH_M
    side = gap * math.sqrt(2.0 * n)
    points: list[np.ndarray] = []
    while len(points) < n:
        p = rng.uniform(0.0, side, 2)
        if all(np.linalg.norm(p - q) >= gap for q in points):
            points.append(p)
    pts = np.round(np.array(points) - points[0], 4)
    from scipy.spatial import Delaunay  # heavy: imported when first needed

    triangles = Delaunay(pts).simplices
    pairs = sorted({tuple(sorted((int(a), int(b)))) for t in triangles
                    for a, b in ((t[0], t[1]), (t[1], t[2]), (t[0], t[2]))})
    edges = [(f"v{pairs[k][0]}", f"v{pairs[k][1]}") for k in rng.permutation(len(pairs))]
    vertices = {f"v{k}": (float(x), float(y)) for k, (x, y) in enumerate(pts)}
    while True:
        try:
            return ArenaSpec(text, "v0", vertices, edges,
                             f"random planar graph, {n} vertices, seed {seed}", text)
        except MjswarmError as exc:
            drop = _removable_edge(str(exc), edges)
            if drop is None:
                return None
            edges.pop(drop)


def rotated(spec: ArenaSpec, degrees: float, text: str) -> ArenaSpec:
    """``spec`` rotated by ``degrees`` counter-clockwise about its root, named ``text``."""
    cx, cy = spec.vertices[spec.root]
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    vertices = {v: (round(cx + c * (x - cx) - s * (y - cy), 9),
                    round(cy + s * (x - cx) + c * (y - cy), 9))
                for v, (x, y) in spec.vertices.items()}
    return ArenaSpec(text, spec.root, vertices, spec.edges,
                     f"{spec.description} (rotated {degrees:g} degrees about {spec.root})", text)


def _polar(r: float, angle: float) -> tuple[float, float]:
    return (round(r * math.cos(angle), 9), round(r * math.sin(angle), 9))


def _with_length(text: str, build, length: float | None) -> ArenaSpec:
    """``build(length)``, or with the smallest valid multiple of DEFAULT_STEP_M."""
    if length is not None:
        if not (math.isfinite(length) and length > 0):
            raise MjswarmError(f"{text}: lengths must be positive numbers of metres")
        return build(length)
    for k in range(1, round(_LONGEST_DEFAULT_M / DEFAULT_STEP_M) + 1):
        try:
            return build(round(k * DEFAULT_STEP_M, 9))
        except MjswarmError:
            continue
    raise MjswarmError(f"{text}: no length up to {_LONGEST_DEFAULT_M:g} m makes a valid arena")


def _networkx_arena(text: str, graph: nx.Graph, spacing: float, kind: str) -> ArenaSpec:
    """A networkx lattice with unit edges and ``pos`` attributes, scaled to ``spacing``."""
    if not (math.isfinite(spacing) and spacing > 0):
        raise MjswarmError(f"{text}: SPACING must be a positive number of metres")
    name = {node: f"v{node[0]}_{node[1]}" for node in graph}
    vertices = {name[node]: (round(x * spacing, 9), round(y * spacing, 9))
                for node, (x, y) in sorted(graph.nodes(data="pos"))}
    edges = sorted((name[a], name[b]) if a < b else (name[b], name[a]) for a, b in graph.edges)
    return ArenaSpec(text, next(iter(vertices)), vertices, edges,
                     f"{kind}, edges {spacing:g} m", text)


_VERTEX_IN_MESSAGE = re.compile(r"\bv\d+\b")
#: Point sets :func:`random_planar` tries before it gives up.
_PLANAR_TRIES = 50


def _removable_edge(message: str, edges: list[tuple[str, str]]) -> int | None:
    """Index of an edge to drop after the validator's ``message``: one it names (the
    last first), else one at a vertex it names, that is no bridge; None if every
    candidate is one."""
    named = _VERTEX_IN_MESSAGE.findall(message)
    pairs = [set(p) for p in zip(named, named[1:])]
    bridges = {frozenset(e) for e in nx.bridges(nx.Graph(edges))}
    candidates = [k for p in reversed(pairs) for k, e in enumerate(edges) if set(e) == p]
    candidates += [k for k, e in enumerate(edges) if set(e) & set(named)]
    return next((k for k in candidates if frozenset(edges[k]) not in bridges), None)
