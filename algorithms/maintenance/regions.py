"""Circular regions on the plane (Ahmadi & Stone's experiment): union area, candidate centres,
moving towards a point, and the Theorem 1 biconnectivity test on a small graph.

All lengths in metres, areas in square metres. Pure numpy.
"""

from __future__ import annotations

import math
from collections.abc import Hashable, Iterable, Mapping, Sequence

import numpy as np

Point = tuple[float, float]


def union_area(centres: Sequence[Sequence[float]], radius: float) -> float:
    """Exact area of the union of discs of one ``radius`` (m) at ``centres`` (m^2).

    Green's theorem: the union's boundary is made of the arcs of each circle that no
    other disc covers; the area is ``1/2 * sum of the integral of (x dy - y dx)`` over
    those arcs. Coincident discs count once.
    """
    unique = {(float(c[0]), float(c[1])) for c in centres}
    pts = np.array(sorted(unique), float).reshape(-1, 2)
    r = float(radius)
    total = 0.0
    for i, (cx, cy) in enumerate(pts):
        covered: list[tuple[float, float]] = []
        inside = False
        for j, (ox, oy) in enumerate(pts):
            if i == j:
                continue
            d = math.hypot(ox - cx, oy - cy)
            if d >= 2.0 * r:
                continue
            if d == 0.0:  # cannot happen after dedup; kept out of the arc maths
                inside = True
                break
            a = math.atan2(oy - cy, ox - cx)
            h = math.acos(d / (2.0 * r))
            covered.append((a - h, a + h))
        if inside:
            continue
        for t1, t2 in _uncovered_arcs(covered):
            total += 0.5 * (r * r * (t2 - t1)
                            + r * (cx * (math.sin(t2) - math.sin(t1))
                                   - cy * (math.cos(t2) - math.cos(t1))))
    return total


def _uncovered_arcs(covered: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The parts of [0, 2 pi) outside the given angle intervals (each shorter than 2 pi)."""
    if not covered:
        return [(0.0, 2.0 * math.pi)]
    spans: list[tuple[float, float]] = []
    for lo, hi in covered:
        width = hi - lo
        lo %= 2.0 * math.pi
        hi = lo + width
        if hi > 2.0 * math.pi:
            spans += [(lo, 2.0 * math.pi), (0.0, hi - 2.0 * math.pi)]
        else:
            spans.append((lo, hi))
    spans.sort()
    free, at = [], 0.0
    for lo, hi in spans:
        if lo > at:
            free.append((at, lo))
        at = max(at, hi)
    if at < 2.0 * math.pi:
        free.append((at, 2.0 * math.pi))
    return free


def move_towards(point: Sequence[float], target: Sequence[float], d: float) -> Point:
    """``point`` moved ``d`` metres straight towards ``target``, stopping at ``target``.

    Ahmadi & Stone's MOVE(pos, d). Stopping at ``pos`` is our choice (the paper does not say what
    a robot closer than d does). The map is the proximal operator of ``d * |p - pos|``, so
    it never increases the distance between two points: no link is lost by a MOVE, the
    property the paper's removal argument rests on.
    """
    dx, dy = target[0] - point[0], target[1] - point[1]
    dist = math.hypot(dx, dy)
    if dist <= d:
        return float(target[0]), float(target[1])
    return point[0] + dx / dist * d, point[1] + dy / dist * d


def hold_points(centres: Mapping[Hashable, Sequence[float]], spacing_m: float,
                passes: int = 50) -> dict[Hashable, Point]:
    """Where robots with bodies hold (m): centres closer than ``spacing_m`` pushed apart.

    Region centres may come arbitrarily close (MOVE converges on the removed robot's
    centre), but bodies cannot share a point. Our choice, not the paper's (its robots
    are points): each pass pushes every point straight away from every other point closer
    than ``spacing_m`` by half the shortfall, ``(spacing_m - d) / 2`` (a lone pair ends
    exactly ``spacing_m`` apart, symmetric about its midpoint); passes repeat until no
    pair is closer than ``spacing_m`` (to 1 mm) or ``passes`` have run. Coincident points
    split along x, the lower id towards -x (ids are ordered, Assumption 3). Every robot
    computes this from the same table, so all agree. ``spacing_m = 0`` gives the centres.
    """
    held = {k: (float(c[0]), float(c[1])) for k, c in centres.items()}
    for _ in range(passes):
        pushed, crowded = {}, False
        for i, (x, y) in held.items():
            hx, hy = x, y
            for j, (ox, oy) in held.items():
                d = math.hypot(x - ox, y - oy)
                if j == i or d >= spacing_m:
                    continue
                crowded = crowded or d < spacing_m - 1e-3
                ux, uy = ((x - ox) / d, (y - oy) / d) if d > 0.0 else (
                    1.0 if i > j else -1.0, 0.0)
                hx += (spacing_m - d) / 2.0 * ux
                hy += (spacing_m - d) / 2.0 * uy
            pushed[i] = (hx, hy)
        held = pushed
        if not crowded:
            break
    return held


def path_around(start: Sequence[float], goal: Sequence[float],
                 obstacles: Iterable[Sequence[float]], radius_m: float,
                 sides: int = 12) -> list[Point]:
    """Waypoints (m) of a short path from ``start`` to ``goal`` that keeps at least
    ``radius_m`` from every obstacle point, ending at ``goal`` (``start`` not included).

    Visibility graph (our choice for a robot's own known map): the nodes are ``start``,
    ``goal`` and the corners of a regular ``sides``-gon around each obstacle whose edges
    lie 2 % outside its disc; two nodes are joined when the segment between them keeps
    ``radius_m`` from every obstacle; Dijkstra on the lengths. Obstacles whose disc holds
    ``start`` or ``goal`` are ignored (the robot may leave one, or hold next to one). With
    no such path the answer is ``[goal]``.
    """
    a, b = np.asarray(start, float)[:2], np.asarray(goal, float)[:2]
    obs = np.array([o[:2] for o in obstacles], float).reshape(-1, 2)
    if len(obs):
        obs = obs[(np.linalg.norm(obs - a, axis=1) >= radius_m)
                  & (np.linalg.norm(obs - b, axis=1) >= radius_m)]
    angles = np.linspace(0.0, 2.0 * math.pi, sides, endpoint=False)
    ring = 1.02 * radius_m / math.cos(math.pi / sides) * np.stack(
        [np.cos(angles), np.sin(angles)], axis=1)
    nodes = np.concatenate([a[None], b[None], (obs[:, None] + ring[None]).reshape(-1, 2)])
    # distance from every obstacle to every segment between two nodes
    p, q = nodes[:, None, None], nodes[None, :, None]
    seg = q - p
    t = np.clip(np.sum((obs[None, None] - p) * seg, axis=-1)
                / np.maximum(np.sum(seg * seg, axis=-1), 1e-18), 0.0, 1.0)
    gap = np.linalg.norm(p + t[..., None] * seg - obs[None, None], axis=-1)
    free = np.all(gap >= radius_m - 1e-9, axis=-1)
    length = np.linalg.norm(nodes[:, None] - nodes[None], axis=-1)
    best, before = np.full(len(nodes), np.inf), np.full(len(nodes), -1)
    best[0], done = 0.0, np.zeros(len(nodes), bool)
    while not done[1]:
        open_best = np.where(done, np.inf, best)
        u = int(np.argmin(open_best))
        if not np.isfinite(open_best[u]):
            return [(float(b[0]), float(b[1]))]
        done[u] = True
        better = free[u] & ~done & (best[u] + length[u] < best)
        best[better], before[better] = best[u] + length[u][better], u
    path, u = [], 1
    while u != 0:
        path.append((float(nodes[u, 0]), float(nodes[u, 1])))
        u = int(before[u])
    return path[::-1]


def candidate_centres(centres: Sequence[Sequence[float]], link_m: float,
                      samples: int = 72) -> list[Point]:
    """Region centres that make a new robot the neighbour of ``min(2, n)`` of ``centres``.

    The candidates lie on the circles of radius ``link_m`` around the known centres (a
    sum of distances is largest on that boundary): ``samples`` points per circle and the
    pairwise intersection points of the circles (the exact optimum of Ahmadi & Stone's
    criterion for two neighbours). A discretisation: the paper does not say how the new
    robot searches the plane. With no centres the only candidate is none (empty list).
    """
    pts = [tuple(map(float, c[:2])) for c in centres]
    raw: list[Point] = []
    angles = np.linspace(0.0, 2.0 * math.pi, samples, endpoint=False)
    for cx, cy in pts:
        raw += [(cx + link_m * math.cos(a), cy + link_m * math.sin(a)) for a in angles]
    for i in range(len(pts)):
        for j in range(i + 1, len(pts)):
            raw += _circle_intersections(pts[i], pts[j], link_m)
    need = min(2, len(pts))
    eps = 1e-9 * max(1.0, link_m)
    return [p for p in raw
            if sum(math.dist(p, c) <= link_m + eps for c in pts) >= need]


def _circle_intersections(a: Point, b: Point, r: float) -> list[Point]:
    d = math.dist(a, b)
    if d == 0.0 or d > 2.0 * r:
        return []
    h = math.sqrt(max(0.0, r * r - d * d / 4.0))
    mx, my = (a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0
    ux, uy = (b[0] - a[0]) / d, (b[1] - a[1]) / d
    return [(mx - uy * h, my + ux * h), (mx + uy * h, my - ux * h)]


def two_closest_sum(p: Sequence[float], centres: Sequence[Sequence[float]]) -> float:
    """Ahmadi & Stone's placement criterion: the sum of the distances from ``p`` to the two
    closest region centres (to the one centre when there is only one), metres."""
    return float(sum(sorted(math.dist(p, c) for c in centres)[:2]))


def neighbour_graph(centres: Mapping[Hashable, Sequence[float]], link_m: float
                    ) -> dict[Hashable, set]:
    """Adjacency of regions whose centres are at most ``link_m`` apart."""
    ids = list(centres)
    adj: dict[Hashable, set] = {i: set() for i in ids}
    for a in range(len(ids)):
        for b in range(a + 1, len(ids)):
            if math.dist(centres[ids[a]], centres[ids[b]]) <= link_m:
                adj[ids[a]].add(ids[b])
                adj[ids[b]].add(ids[a])
    return adj


def _connected(adj: Mapping[Hashable, set], u: Hashable, v: Hashable,
               without_vertex: Hashable = None, without_edge: bool = False) -> bool:
    seen, stack = {u}, [u]
    while stack:
        x = stack.pop()
        for y in adj[x]:
            if y == without_vertex or y in seen or (without_edge and {x, y} == {u, v}):
                continue
            if y == v:
                return True
            seen.add(y)
            stack.append(y)
    return u == v


def doubly_connected(adj: Mapping[Hashable, set], u: Hashable, v: Hashable) -> bool:
    """Definition 3: two or more internally vertex-disjoint paths join ``u`` and ``v``.

    By Menger's theorem: adjacent vertices need a second path besides the edge; others
    must stay connected after removing any single other vertex.
    """
    if v in adj[u]:
        return _connected(adj, u, v, without_edge=True)
    return _connected(adj, u, v) and all(
        _connected(adj, u, v, without_vertex=w) for w in adj if w not in (u, v))


def biconnected(adj: Mapping[Hashable, Iterable]) -> bool:
    """Theorem 1: biconnected iff two distinct vertices are doubly connected to all others.

    With one vertex, or two joined by an edge, we answer "connected" (networkx's
    convention): that is what Theorem 4 needs of the ex-neighbours' subgraph, since two
    ex-neighbours joined by a link close a loop with the rest of the team.
    """
    graph = {u: set(vs) for u, vs in adj.items()}
    nodes = list(graph)
    if len(nodes) <= 2:
        return len(nodes) < 2 or nodes[1] in graph[nodes[0]]
    good = 0
    for u in nodes:
        if all(doubly_connected(graph, u, v) for v in nodes if v != u):
            good += 1
            if good == 2:
                return True
    return False
