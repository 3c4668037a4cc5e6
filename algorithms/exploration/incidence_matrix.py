"""Seed 003's modified incidence matrix (section 2, section 3.1, Algorithms 1 and 2).

Rows are vertex tags (beacon ids), columns are edges. An entry is ``-theta`` for a
completed or out edge and ``+theta`` for an unexplored one, ``theta`` in (0, 2*pi] being
the incidence angle of the edge at the row's vertex (radians, counter-clockwise from +x).
A completed edge is a column with two non-zero entries, an out edge a column with one
negative entry, an unexplored edge a column with one positive entry. The matrix encodes
the sets of section 2: ``Vc`` (rows), ``Ec``, ``Eo``, ``Eu``; ``Em`` is the robot's own
ordered list, kept by the strategy.

Representation. The matrix is stored sparsely and immutably, by *edge ends*: an end is
``(tag, theta)``, i.e. one non-zero entry. ``rows`` maps each tag to the incidence angles
of all edges at that vertex (its ``I0(vj)`` row, eq. (14)); ``completed`` maps each end
of a completed edge to the other end; ``out`` maps each out end to the robots known to
have selected it (see :meth:`IncidenceMatrix.select`). Every other end of a known row is
unexplored. Algorithm 1 identifies common edges by a common vertex tag and equal
``|theta|``, i.e. by a common end, which is what the dictionary keys do, so merging is a
union of ends with the status rule of Algorithm 1 (a negative entry wins over a positive
one; a completed column replaces a one-entry column). Matrices are never modified; robot
and beacon share one object after a visit (Algorithm 4's ``In(vj) = In(Rk)``).
:meth:`IncidenceMatrix.to_array` gives the dense matrix of the paper.
"""

from __future__ import annotations

from collections import deque

import numpy as np

End = tuple[str, float]

_NOBODY: frozenset[str] = frozenset()

#: Status of an end, ordered by how much is known (statuses only ever increase).
UNKNOWN, UNEXPLORED, OUT, COMPLETED = -1, 0, 1, 2


class IncidenceMatrix:
    """An immutable, sparse modified incidence matrix (see the module docstring).

    ``rows``: tag -> sorted incidence angles of that vertex's edges (radians).
    ``completed``: end -> other end, for both ends of every completed edge.
    ``out``: out end -> letters of the robots known to have selected it. It stands for
    the column order of the out block: Algorithm 4's circular shift moves a just-selected
    column to the front of the out block, so the rightmost out column, the next one
    chosen, is the one selected least. Sets of selectors keep that round-robin through
    merges (a union), where a plain count would lose selections made concurrently.
    """

    __slots__ = ("_n_ends", "completed", "out", "rows")

    def __init__(
        self,
        rows: dict[str, tuple[float, ...]],
        completed: dict[End, End],
        out: dict[End, frozenset[str]],
    ):
        self.rows = rows
        self.completed = completed
        self.out = out
        self._n_ends: int | None = None

    @classmethod
    def initial(cls, tag: str, angles: tuple[float, ...]) -> IncidenceMatrix:
        """``I0(vj)`` of eq. (14): one row, every edge of the vertex unexplored."""
        return cls({tag: angles}, {}, {})

    @classmethod
    def edge(
        cls, end_i: End, angles_i: tuple[float, ...], end_j: End, angles_j: tuple[float, ...]
    ) -> IncidenceMatrix:
        """``I'`` of Algorithm 3: the column of the completed edge ``e_ij`` (with the rows of
        its two vertices, whose other edges are unexplored unless known otherwise)."""
        return cls(
            {end_i[0]: angles_i, end_j[0]: angles_j}, {end_i: end_j, end_j: end_i}, {}
        )

    # -- queries --------------------------------------------------------------------

    def status(self, end: End) -> int:
        """``COMPLETED``, ``OUT``, ``UNEXPLORED`` or ``UNKNOWN`` (vertex not a row)."""
        if end in self.completed:
            return COMPLETED
        if end in self.out:
            return OUT
        return UNEXPLORED if end[0] in self.rows else UNKNOWN

    @property
    def n_ends(self) -> int:
        """Number of non-zero entries the matrix would have if fully explored."""
        if self._n_ends is None:
            self._n_ends = sum(map(len, self.rows.values()))
        return self._n_ends

    def is_complete(self) -> bool:
        """Theorem 1: exploration is complete iff ``Eu`` and ``Eo`` are empty, i.e. every
        end of every known vertex belongs to a completed edge (Remark 5: the rightmost
        column of the ordered matrix is a completed one)."""
        return len(self.completed) == self.n_ends

    def unexplored(self) -> list[End]:
        """``Eu``: unexplored ends, in row order then angle order."""
        completed, out = self.completed, self.out
        return [
            (tag, a)
            for tag, angles in self.rows.items()
            for a in angles
            if (tag, a) not in completed and (tag, a) not in out
        ]

    def unexplored_at(self, tag: str) -> list[float]:
        """Angles of the unexplored edges at vertex ``tag`` (``Em(vj)`` for a beacon)."""
        completed, out = self.completed, self.out
        return [
            a for a in self.rows.get(tag, ()) if (tag, a) not in completed and (tag, a) not in out
        ]

    def completed_edges(self) -> list[tuple[End, End]]:
        """``Ec``: each completed edge once, as its two ends."""
        return [(e, f) for e, f in self.completed.items() if e < f]

    def order(self) -> list[tuple[End, ...]]:
        """Algorithm 2: the columns, completed | out | unexplored, each column a tuple of
        its ends. Completed and unexplored columns keep the order in which the merges met
        them, as Algorithm 2's concatenation does; out columns go from most to least
        selected, so that the rightmost is the next to help (Algorithm 4's shift)."""
        out = sorted(self.out, key=lambda e: (-len(self.out[e]), e))
        return [*self.completed_edges(), *((e,) for e in out), *((e,) for e in self.unexplored())]

    def to_array(self) -> tuple[list[str], list[tuple[End, ...]], np.ndarray]:
        """The dense matrix of section 2: ``(row tags, columns, entries)``; entries are
        ``-theta`` (completed, out) or ``+theta`` (unexplored), radians."""
        tags = list(self.rows)
        index = {t: i for i, t in enumerate(tags)}
        columns = self.order()
        dense = np.zeros((len(tags), len(columns)))
        for j, column in enumerate(columns):
            sign = 1.0 if len(column) == 1 and self.status(column[0]) == UNEXPLORED else -1.0
            for tag, theta in column:
                dense[index[tag], j] = sign * theta
        return tags, columns, dense

    # -- the completed graph Gc -----------------------------------------------------

    def neighbours(self, tag: str) -> list[tuple[float, str]]:
        """Completed edges at ``tag`` as ``(angle at tag, other tag)``, by angle."""
        completed = self.completed
        return [(a, completed[(tag, a)][0]) for a in self.rows[tag] if (tag, a) in completed]

    def distances(self, source: str) -> dict[str, int]:
        """Hop distances from ``source`` over the completed graph ``Gc`` (breadth first)."""
        dist = {source: 0}
        frontier = deque([source])
        while frontier:
            t = frontier.popleft()
            d = dist[t] + 1
            for _, u in self.neighbours(t):
                if u not in dist:
                    dist[u] = d
                    frontier.append(u)
        return dist

    def nearest(self, source: str, targets: set[str]) -> set[str]:
        """The tags of ``targets`` fewest hops from ``source`` over ``Gc``."""
        for layer in self.layers(source):
            found = targets.intersection(layer)
            if found:
                return found
        raise ValueError(f"none of {sorted(targets)} is reachable from {source}")

    def nearest_open(self, source: str) -> list[End]:
        """The unexplored ends fewest hops from ``source`` over ``Gc``; if no end is
        unexplored, the nearest out ends (empty when the exploration is complete)."""
        completed, out, rows = self.completed, self.out, self.rows
        nearest_out: list[End] = []
        for layer in self.layers(source):
            ends = [(t, a) for t in layer for a in rows[t] if (t, a) not in completed]
            unexplored = [e for e in ends if e not in out]
            if unexplored:
                return unexplored
            if not nearest_out:
                nearest_out = ends
        return nearest_out

    def layers(self, source: str):
        """Breadth-first layers of ``Gc`` from ``source``: lists of tags by hop distance."""
        seen = {source}
        layer = [source]
        while layer:
            yield layer
            following = []
            for t in layer:
                for _, u in self.neighbours(t):
                    if u not in seen:
                        seen.add(u)
                        following.append(u)
            layer = following

    def route(self, source: str, target: str) -> list[End]:
        """A shortest path from ``source`` to ``target`` over ``Gc`` (Lemma 1 / Remark 4:
        it exists), as the end to leave by at each vertex on the way. Among equal-length
        paths, the one whose departures have the smallest angles, vertex by vertex."""
        if source == target:
            return []
        parent: dict[str, End | None] = {source: None}
        frontier = deque([source])
        while frontier and target not in parent:
            t = frontier.popleft()
            for a, u in self.neighbours(t):
                if u not in parent:
                    parent[u] = (t, a)
                    frontier.append(u)
        if target not in parent:
            raise ValueError(f"no completed path from {source} to {target}")
        path: list[End] = []
        step = parent[target]
        while step is not None:
            path.append(step)
            step = parent[step[0]]
        path.reverse()
        return path

    # -- updates --------------------------------------------------------------------

    def select(self, end: End, robot: str) -> IncidenceMatrix:
        """Eq. (5) / Algorithm 4 for an edge selected by ``robot`` (its beacon letters): an
        unexplored column is negated (made out); an out column records one more selector
        (see ``out``). A completed edge is left as it is."""
        if end in self.completed or robot in self.out.get(end, ()):
            return self
        selectors = self.out.get(end, _NOBODY) | {robot}
        m = IncidenceMatrix(self.rows, self.completed, {**self.out, end: selectors})
        m._n_ends = self._n_ends
        return m


#: ``I0(Rk)`` of eq. (14): a robot at the start knows nothing.
EMPTY = IncidenceMatrix({}, {}, {})


def merge(a: IncidenceMatrix, b: IncidenceMatrix) -> IncidenceMatrix:
    """Algorithm 1 followed by Algorithm 2's block order: the union of rows and columns
    with copies of common vertices and edges removed.

    A common edge (same vertex tag, same ``|theta|``) takes the more advanced status:
    completed over out over unexplored (Algorithm 1: differing signs become negative; a
    completed column replaces the other copy); a common out edge keeps the selectors of
    both copies. The result is equations (2) and (3) for ``Gc``, ``Eo`` and ``Eu``.
    Merging is commutative in content; the operand with more completed edges is laid out
    first (it is cheaper to copy), and an operand that already contains the other is
    returned as it is (the order inside a block carries no information).
    """
    if a is b or b is EMPTY:
        return a
    if a is EMPTY:
        return b
    if len(a.completed) < len(b.completed):
        a, b = b, a
    if len(b.completed) == 2 and len(b.rows) == 2 and not b.out:
        return _with_column(a, b)
    if _contains(a, b):
        return a
    if len(a.completed) == len(b.completed) and _contains(b, a):
        return b
    completed = a.completed | b.completed
    out = {e: who for e, who in a.out.items() if e not in completed}
    for e, who in b.out.items():
        if e not in completed:
            out[e] = out[e] | who if e in out else who
    return IncidenceMatrix(a.rows | b.rows, completed, out)


def _with_column(a: IncidenceMatrix, column: IncidenceMatrix) -> IncidenceMatrix:
    """``merge(a, column)`` for a one-edge ``I'`` (Algorithm 3's first merge), without
    copying what does not change."""
    end = next(iter(column.completed))
    if end in a.completed and column.rows.keys() <= a.rows.keys():
        return a
    completed = a.completed | column.completed
    rows = a.rows if column.rows.keys() <= a.rows.keys() else a.rows | column.rows
    out = a.out
    if any(e in out for e in column.completed):
        out = {e: who for e, who in out.items() if e not in completed}
    m = IncidenceMatrix(rows, completed, out)
    if rows is a.rows:
        m._n_ends = a._n_ends
    return m


def _contains(a: IncidenceMatrix, b: IncidenceMatrix) -> bool:
    """True if every entry of ``b`` is in ``a`` with at least ``b``'s status."""
    return (
        b.rows.keys() <= a.rows.keys()
        and b.completed.keys() <= a.completed.keys()
        and all(e in a.completed or who <= a.out.get(e, _NOBODY) for e, who in b.out.items())
    )
