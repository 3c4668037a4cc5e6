"""How many robots a connectivity constraint needs to reach every point of an arena
(ground truth, for the verdict of a team that stalled).

A team that keeps every robot linked to the base (``connected``, rule 1 of
:mod:`algorithms.exploration.tether`) can put a robot at a point ``p`` only if a chain of
robots links ``p`` to the base: ``p``'s robot, and a relay at every hop before it. To
explore an edge a robot must stand at every point of it, so a team needs at least as
many robots as the longest such chain (in hops) over the points of the arena:
:func:`robots_needed`. With fewer, no strategy completes the arena, and a stall
(rule 5) is an infeasibility; with as many or more, it is the team's stall, and the
arena may still be explored.

The chains are searched among points on the edges' centre lines every ``SAMPLE_M`` and
at the vertices, linked within the radio range plus ``SAMPLE_M`` (a robot of a true chain
stands within ``SAMPLE_M / 2`` of a sampled point of its edge, so every true link is
found: the count is a lower bound) and, with walls, where the walls do not block the line
between them (:func:`~mjswarm.worlds.wall_sight.wall_blocker`, the base's antenna on its
mast). Bodies stand on lanes 9 cm off the centre lines, and walls near a sampled point
may block a link that a point a few centimetres away would keep: what the 5 cm sampling
shows, not a proof. A ``biconnected`` team needs one more robot, docked at the base
(rule 1).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import networkx as nx
import numpy as np

from mjswarm.arena.geometry import Wall
from mjswarm.worlds.wall_sight import wall_blocker

#: The spacing (m) of the points sampled on the edges' centre lines.
SAMPLE_M = 0.05
#: Pairs of points whose walls are tested at once (bounds the memory of one test).
CHUNK = 2048


def sample_points(pos: Mapping[str, Sequence[float]], edges: Sequence[tuple[str, str]],
                  spacing_m: float = SAMPLE_M) -> np.ndarray:
    """The vertices and points every ``spacing_m`` along each edge, ``(P, 2)`` (m)."""
    points = [np.asarray(p, float) for p in pos.values()]
    for u, v in edges:
        a, b = np.asarray(pos[u], float), np.asarray(pos[v], float)
        n = max(1, math.ceil(math.dist(a, b) / spacing_m))
        points += [a + (b - a) * k / n for k in range(1, n)]
    return np.array(points, float).reshape(-1, 2)


def robots_needed(pos: Mapping[str, Sequence[float]], edges: Sequence[tuple[str, str]],
                  root: str, range_m: float, walls: Sequence[Wall] | None = None,
                  mast_m: float = 0.0, connectivity: str = "connected") -> float:
    """The fewest robots (module docstring) that keep ``connectivity`` with a radio of
    ``range_m`` (m) while one of them stands at any point of any edge of the arena
    (vertices ``pos``, m); ``walls`` block links (None: range alone), the base's antenna
    ``mast_m`` above ``root``. ``math.inf`` when some point cannot be linked at all."""
    points = sample_points(pos, edges)
    base = len(points)
    where = dict(enumerate(points))
    where[base] = np.asarray(pos[root], float)
    xy = np.vstack([points, where[base][None]])
    reach = range_m + SAMPLE_M + 1e-9  # a link at exactly the relaxed range counts
    graph = nx.Graph()
    graph.add_nodes_from(range(len(xy)))
    blocked = None if walls is None else wall_blocker(walls, where, {base: mast_m})
    for start in range(0, len(xy), CHUNK // 8):
        rows = np.arange(start, min(start + CHUNK // 8, len(xy)))
        d2 = ((xy[rows, None] - xy[None]) ** 2).sum(axis=-1)
        i, j = np.nonzero((d2 <= reach**2) & (np.arange(len(xy))[None] > rows[:, None]))
        pairs = np.column_stack([rows[i], j])
        if blocked is not None:
            keep = np.concatenate([~blocked(pairs[k:k + CHUNK])
                                   for k in range(0, len(pairs), CHUNK)] or [np.zeros(0, bool)])
            pairs = pairs[keep]
        graph.add_edges_from(map(tuple, pairs.tolist()))
    hops = nx.single_source_shortest_path_length(graph, base)
    if len(hops) < len(xy):
        return math.inf
    return max(hops.values()) + (1 if connectivity == "biconnected" else 0)
