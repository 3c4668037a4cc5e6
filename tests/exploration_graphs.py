"""Graphs for the exploration tests, built directly with networkx (node attr ``pos``)."""

from __future__ import annotations

import math

import networkx as nx
import numpy as np

from mjswarm.worlds.loop import LoopFunctions

#: Nagavarapu et al. Fig. 9 (DESIGN notes): coordinates that reproduce every angle of I10(v6).
FIG9_POS = {
    "v1": (0, 1), "v2": (1, 1), "v5": (2, 1), "v7": (3, 1), "v3": (0, 0),
    "v4": (1, 0), "v6": (2, 0), "v8": (3, 0), "v9": (4, 0), "v10": (5, 0),
}
FIG9_EDGES = [
    ("v1", "v2"), ("v1", "v3"), ("v2", "v4"), ("v2", "v5"), ("v3", "v4"), ("v4", "v6"),
    ("v5", "v6"), ("v5", "v7"), ("v6", "v8"), ("v7", "v8"), ("v8", "v9"), ("v9", "v10"),
]


def graph(pos: dict, edges) -> nx.Graph:
    g = nx.Graph()
    for v, p in pos.items():
        g.add_node(v, pos=p)
    g.add_edges_from(edges)
    return g


def fig9() -> nx.Graph:
    return graph(FIG9_POS, FIG9_EDGES)


def lattice(rows: int, cols: int) -> nx.Graph:
    """Square lattice, vertex ``v<row>_<col>`` at (col, row); (0, 0) is a corner."""
    g = nx.grid_2d_graph(rows, cols)
    return graph({f"v{r}_{c}": (c, r) for r, c in g}, [
        (f"v{a[0]}_{a[1]}", f"v{b[0]}_{b[1]}") for a, b in g.edges
    ])


def star(arms: int) -> nx.Graph:
    pos = {"c": (0.0, 0.0)}
    for k in range(arms):
        a = 2 * math.pi * k / arms
        pos[f"l{k}"] = (math.cos(a), math.sin(a))
    return graph(pos, [("c", f"l{k}") for k in range(arms)])


def grid_tree(seed: int) -> tuple[nx.Graph, str]:
    """A random spanning tree of a random grid of 2..5 x 2..6 vertices, random root."""
    rng = np.random.default_rng(seed)
    rows, cols = (int(x) for x in rng.integers(2, [6, 7]))
    g = nx.grid_2d_graph(rows, cols)
    tree = nx.random_spanning_tree(g, seed=seed)
    h = graph({f"{r}_{c}": (c, r) for r, c in g}, [
        (f"{a[0]}_{a[1]}", f"{b[0]}_{b[1]}") for a, b in tree.edges
    ])
    return h, sorted(h)[int(rng.integers(h.number_of_nodes()))]


def planar_graph(seed: int) -> tuple[nx.Graph, str]:
    """A random connected planar graph with cycles: a random spanning tree of a grid plus
    about half of the other grid edges and a diagonal in about a third of the cells
    (never two in one cell, so no crossings; angles >= 45 degrees)."""
    rng = np.random.default_rng(seed)
    rows, cols = (int(x) for x in rng.integers(2, [6, 7]))
    g = nx.grid_2d_graph(rows, cols)
    edges = set(nx.random_spanning_tree(g, seed=seed).edges)
    edges |= {e for e in g.edges if rng.random() < 0.5}
    for r in range(rows - 1):
        for c in range(cols - 1):
            if rng.random() < 0.3:
                edges.add(((r, c), (r + 1, c + 1)) if rng.random() < 0.5 else ((r + 1, c), (r, c + 1)))
    h = graph({f"{r}_{c}": (c, r) for r, c in g}, [
        (f"{a[0]}_{a[1]}", f"{b[0]}_{b[1]}") for a, b in edges
    ])
    return h, sorted(h)[int(rng.integers(h.number_of_nodes()))]


class Probe(LoopFunctions):
    """A test's look at a graph-world run: ``observer(time, robot, vertex, mind)`` after
    each robot's vertex call, in the order the world handled them (tests may read a
    controller's mind; loop functions of the library may not)."""

    def __init__(self, observer) -> None:
        self.observer = observer

    def before_step(self, loop) -> None:
        self._now, self._at = loop.world.time_s, list(loop.world.at)

    def after_step(self, loop) -> None:
        for i in loop.stepped:
            self.observer(self._now, i, self._at[i], loop.controllers[i].strategy)
