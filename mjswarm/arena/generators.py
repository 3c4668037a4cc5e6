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
"""

from __future__ import annotations

import math
import re

import networkx as nx
import numpy as np

from mjswarm.arena.spec import ArenaSpec
from mjswarm.errors import MjswarmError

#: Default lattice spacing (m), also used by the random generators.
LATTICE_SPACING_M = 0.6

#: Generator name -> usage, for help and error messages.
GENERATORS = {
    "lattice": "lattice:RxC[:SPACING]",
    "random-tree": "random-tree:E:SEED",
    "random-graph": "random-graph:V:E:SEED",
}

_PATTERNS = {
    "lattice": re.compile(r"lattice:(\d+)x(\d+)(?::([^:]+))?"),
    "random-tree": re.compile(r"random-tree:(\d+):(\d+)"),
    "random-graph": re.compile(r"random-graph:(\d+):(\d+):(\d+)"),
}
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
    vertices, edges, seed = map(int, match.groups())
    return random_graph(vertices, edges, seed)


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
