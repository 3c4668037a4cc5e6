"""The Acute Angle Test and Algorithm 2 of Kobayashi, Higuchi & Ueno (Sect. III-D).

A robot ``r_i`` connects to ``r_j`` iff the angle ``x_i x_k x_j`` is acute for every other
robot ``r_k`` it detects: no robot lies in the circle ``C_ij`` with diameter ``x_i x_j``.
Run by every robot on what it detects, this builds the Gabriel graph (Gabriel & Sokal)
restricted to the communication range, the paper's reference [20].

Algorithm 2 runs the test only when needed (role just changed, fewer than ``eta_c``
connections, or a detected robot inside ``C_ij`` of a current connection) and otherwise
keeps the connections; :func:`refresh_connections` with ``force_full=True`` is the
every-step baseline of the preliminary simulation (Sect. IV-A).

Choices where the paper is silent:

* "Acute" is strict: ``(x_i - x_k) . (x_j - x_k) > 0``, so a witness on the circle blocks
  the edge (the closed-disc Gabriel graph). ``C_ij`` in line 11 is the open disc.
* A candidate ``r_j`` must also be within the communication range ``range_m`` (d_c) to be
  connected; witnesses are all detected candidates (the paper's ``R_k`` within d_s).
* The cost is counted in angle evaluations (one per witness per tested robot) and circle
  tests (line 11, one per connection per detected robot), besides wall time measured by
  the caller; units are counts.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable, Mapping
from typing import NamedTuple

import numpy as np


class Refresh(NamedTuple):
    """Result of one refresh: the new connection set ``A_i(t+1)`` and what it cost."""

    connections: frozenset
    angle_tests: int
    circle_tests: int


def acute_angle_test(x_i: np.ndarray, x_j: np.ndarray, witnesses: np.ndarray) -> bool:
    """True iff ``angle x_i x_k x_j < 90 deg`` for every row ``x_k`` of ``witnesses`` (m)."""
    if not len(witnesses):
        return True
    dots = ((x_i - witnesses) * (x_j - witnesses)).sum(axis=1)
    return bool(np.all(dots > 0.0))


def refresh_connections(
    x_i: np.ndarray,
    connections: Iterable[Hashable],
    candidates: Mapping[Hashable, np.ndarray],
    *,
    range_m: float,
    eta_c: int,
    force_full: bool,
) -> Refresh:
    """Algorithm 2: robot i's connections for the next timestep.

    Args:
        x_i: robot i's position (m).
        connections: its current AAT connections ``A_i`` (ids).
        candidates: the robots it detects that may be connected (the paper's ``R_k`` =
            ``R_l``: the local leader and explorers within d_s), id -> position (m).
        range_m: communication range d_c (m); farther candidates are never connected.
        eta_c: Algorithm 2's connection threshold (line 6).
        force_full: test every candidate (line 4's role change, a recovering explorer,
            or the every-step baseline).

    Lines 4-16 choose ``R_AAT``; lines 17-27 test it;
    ``A_i(t+1) = R_pass U (A_i minus R_fail)``. Connections that are no longer candidates
    (out of range or no longer detected) are dropped first.
    """
    x_i = np.asarray(x_i, float)
    ids = list(candidates)
    points = np.array([candidates[k] for k in ids], float).reshape(-1, 2)
    index = {k: n for n, k in enumerate(ids)}
    current = [c for c in connections if c in index]
    circle_tests = 0
    if force_full or len(current) < eta_c:
        to_test = set(ids)
    else:
        to_test = set()
        for r in current:
            centre = (x_i + points[index[r]]) / 2.0
            radius = np.linalg.norm(points[index[r]] - x_i) / 2.0
            others = [n for n in range(len(ids)) if ids[n] != r]
            circle_tests += len(others)
            inside = np.linalg.norm(points[others] - centre, axis=1) < radius
            if inside.any():
                to_test.add(r)
                to_test.update(ids[others[n]] for n in np.flatnonzero(inside))
    passed, failed = set(), set()
    angle_tests = 0
    for r in to_test:
        n = index[r]
        witnesses = np.delete(points, n, axis=0)
        angle_tests += len(witnesses)
        in_range = np.linalg.norm(points[n] - x_i) <= range_m
        (passed if in_range and acute_angle_test(x_i, points[n], witnesses) else failed).add(r)
    return Refresh(frozenset(passed | (set(current) - failed)), angle_tests, circle_tests)


def gabriel_graph(points: np.ndarray, range_m: float = np.inf) -> set[frozenset]:
    """The Gabriel graph of ``points`` (m), computed centrally by brute force, keeping edges
    no longer than ``range_m``: ``{i, j}`` is an edge iff no other point lies in the closed
    disc centred at the midpoint of ``x_i x_j`` with radius ``|x_i - x_j| / 2``.
    For tests and metrics (the robots use :func:`refresh_connections`)."""
    points = np.asarray(points, float).reshape(-1, 2)
    n = len(points)
    edges = set()
    for i in range(n):
        for j in range(i + 1, n):
            half = np.linalg.norm(points[i] - points[j]) / 2.0
            if 2.0 * half > range_m:
                continue
            mid = (points[i] + points[j]) / 2.0
            d = np.linalg.norm(points - mid, axis=1)
            d[[i, j]] = np.inf
            if np.all(d > half):
                edges.add(frozenset((i, j)))
    return edges
