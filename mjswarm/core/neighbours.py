"""Pairs of robots within a range: one k-d tree per set of positions, shared by every asker.

Every control tick the bearing sensor (:mod:`mjswarm.core.bearing`) and the radio
(:mod:`mjswarm.core.radio`) each ask which robots lie within their range (1 m both, in the
bench) of one another, at the same positions. :meth:`Neighbours.pairs` answers, for
positions ``xy`` (metres, one row per robot) and a range ``r`` (metres): every pair
``(k, l)``, ``k < l``, with ``sum((xy[k] - xy[l])**2) <= r**2`` in float64 (inclusive),
sorted by ``k``, then ``l``. A k-d tree (``scipy.spatial.cKDTree.query_pairs``, itself
inclusive) proposes the pairs within ``r`` enlarged by ``CANDIDATE_SLACK`` relative and the
exact test decides, so the tree's own rounding cannot add or lose a pair at exactly ``r``.
Below ``TREE_FROM_ROBOTS`` robots every pair is a candidate instead (the same exact test,
the pairs in the same order): for the main job's 4 robots that costs 5 us a search where
the tree costs 17 us (``python benchmarks/neighbours_bench.py``: the two meet between 128
and 256 robots).

The tree is built once per distinct positions (compared by their bytes: about 2 us for 1000
robots, where building the tree takes about 55 us and querying it 110 us; midpoint splits
without shrinking the nodes to their points, which build and query 1000 robots about 40 us
faster than scipy's default and propose the same pairs) and each range's answer is kept
until the positions change, so the second asker at the same positions costs a comparison.
"""

from __future__ import annotations

import numpy as np

#: relative enlargement of the k-d tree's search radius over the range (the exact test decides)
CANDIDATE_SLACK = 1e-9
#: From this many robots the k-d tree proposes the candidate pairs; below it, every pair.
TREE_FROM_ROBOTS = 128


class Neighbours:
    """Pairs within a range at given positions, remembered for the last positions asked."""

    def __init__(self) -> None:
        self._key: tuple = ()  # the last positions: their shape and bytes
        self._columns = np.empty((0, 0))  # their coordinates, one row per axis
        self._tree = None  # a scipy.spatial.cKDTree, built on the first query
        self._answers: dict[float, np.ndarray] = {}  # range (m) -> its pairs at ``_key``
        #: every pair of ``n`` robots: ``(n, k, l, kl)``, ``kl`` the pairs as rows
        self._every: tuple[int, np.ndarray, np.ndarray, np.ndarray] = _every_pair(0)

    def pairs(self, xy: np.ndarray, range_m: float) -> np.ndarray:
        """Every pair ``(k, l)``, ``k < l``, of rows of ``xy`` (finite, metres) at most
        ``range_m`` (metres) apart (module docstring), shape (M, 2), int64, sorted."""
        xy = np.asarray(xy, float)
        key = (xy.shape, xy.tobytes())
        if key != self._key:
            self._key, self._columns = key, xy.T.copy()
            self._tree, self._answers = None, {}
        found = self._answers.get(range_m)
        if found is None:
            found = self._answers[range_m] = self._search(range_m)
        return found

    def _search(self, range_m: float) -> np.ndarray:
        """:meth:`pairs` at the remembered positions: the candidates in key order (every
        pair, or the tree's), then the exact test (coordinates summed in order, as
        ``sum(axis=-1)`` does)."""
        columns = self._columns
        n = columns.shape[1]
        if n < 2:
            return np.empty((0, 2), np.int64)
        pairs = None
        if n < TREE_FROM_ROBOTS:
            if self._every[0] != n:
                self._every = _every_pair(n)
            _, k, l, pairs = self._every
        else:
            if self._tree is None:
                from scipy.spatial import cKDTree  # heavy: imported when first needed

                self._tree = cKDTree(columns.T, balanced_tree=False, compact_nodes=False)
            near = self._tree.query_pairs(range_m * (1.0 + CANDIDATE_SLACK), output_type="ndarray")
            k, l = np.divmod(np.sort(near[:, 0] * n + near[:, 1]), n)
        gap = (columns[0][k] - columns[0][l]) ** 2
        for column in columns[1:]:
            gap += (column[k] - column[l]) ** 2
        within = gap <= range_m**2
        if pairs is not None:  # every pair: one row pick
            return pairs[within]
        return np.column_stack([k[within], l[within]])


def _every_pair(n: int) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
    """Every pair ``(k, l)``, ``k < l``, of ``n`` robots in key order: ``(n, k, l, kl)``,
    ``kl`` the same pairs as the rows of one (M, 2) array."""
    k, l = np.triu_indices(n, 1)
    return n, k, l, np.column_stack([k, l])
