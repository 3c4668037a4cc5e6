"""Nagavarapu et al.'s modified incidence matrix (section 2, section 3.1, Algorithms 1 and 2).

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

Bit sets. Each robot writes its matrices in a :class:`Numbering` of its own, which
gives every tag and every end a bit position. A matrix itself is a handful of integers
used as bit sets over those positions (its known rows, their ends, the completed ends, the
out ends, the blocked ends) and, for the selections, one bit set of end positions for each
robot of the team, so Algorithm 1's union (equations (2) and (3)) is a few ``|`` and the
containment test a few ``&``, however large the matrix. A position is a function of who
wrote the entry: robot ``r`` of a team of ``K`` writes its ``c``-th entry at ``c * K + r``,
so the numberings of one team agree wherever they name the same entry and a matrix read
from a teammate's beacon keeps its bits. A vertex's row (``I0(vj)`` of eq. (14), with the
positions of its ends) is one immutable :class:`Row` value, made by the robot that drops
the beacon and held by reference in every numbering that knows the vertex; eq. (5)'s
negation by robot ``r`` sets the end's bit in ``r``'s selection set, whose place is the
same in every numbering. Reading a teammate's matrix (:meth:`Numbering.learn`) copies
into the robot's numbering only the rows and the other ends of completed ends new to it;
nothing a numbering holds that can change is reachable from another robot. ``rows``,
``completed`` and ``out`` are built from the bits when asked for, in numbering order.
Matrices of numberings of no team (built directly, e.g. by a test) are merged after
renumbering one.

Blocked ends (ours: a body that cannot be passed). An end is *blocked* when
the vertex at its far end is closed: a robot stopped for good in that vertex's area,
and the station there answers every request for it with
:class:`~algorithms.exploration.entry.EntryBlocked`. The robot that asked marks the end
it asked for (:meth:`IncidenceMatrix.block`); blocked marks are one more bit set over the
end positions, merged by union like the others (robots carry them beacon to beacon), and
orthogonal to the status: an unexplored, out or completed end may be blocked (a
completed edge into a vertex that closed later). A blocked end is never a candidate (not
in ``Eu`` nor ``Eo`` for selection), and no route over ``Gc`` leaves by one. The *reach*
of a vertex ``s`` is the set of known vertices reachable from ``s`` over ``Gc`` without
leaving by a blocked end (:meth:`IncidenceMatrix.reach`).

Theorem 1 with blocked ends (the rule). Exploration is complete for a robot at ``s`` iff
its reach holds the root and every end of every vertex of its reach is completed or
blocked. Without blocked ends the reach is every known vertex (Lemma 1: ``Gc`` is
connected) and this is Theorem 1's test exactly. With them, the declared map is the
completed graph of the reach: when vertices are closed from the start it is exactly the
part of the graph reachable from the root without entering a closed vertex (every
vertex of that part is found, by Theorem 1's argument applied to it, and every edge out
of it ends blocked); a vertex that closed during the run may leave in the map edges
completed before it closed (true edges, beyond that part). A robot cut off from the root
(beyond a vertex that closed behind it, or the root itself closed) never declares: when
every end of its reach is completed or blocked (:meth:`IncidenceMatrix.reach_finished`)
its reach is the whole of its component of the graph without the closed vertices (no
end of it leads anywhere else), which no robot can enter or leave any more; it has
finished that part and stops (``CUT_OFF``). Only the team can tell that nothing is left
(no robot knows whether others, cut off elsewhere, still work): the embodied
experiment's rule for that is ``team_cut_off`` in ``mjswarm.experiments.metrics``. The bit set is 0 in every
run without closed vertices, and every query then takes the path without blocked ends.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from algorithms.exploration.beacon_ids import parse_beacon_id, robot_letters

End = tuple[str, float]

_NOBODY: frozenset[str] = frozenset()
#: The most robots whose selections a numbering without owner records.
_ANYONE = 26
#: ``IncidenceMatrix._moved`` when every completed end has its first-written other end.
_UNMOVED: Mapping[int, End] = MappingProxyType({})

#: Status of an end, ordered by how much is known (statuses only ever increase).
UNKNOWN, UNEXPLORED, OUT, COMPLETED = -1, 0, 1, 2


@dataclass(frozen=True, slots=True)
class Row:
    """One vertex's row ``I0(vj)`` of eq. (14) as numbered: its tag, the tag's position
    ``at`` and bit, the incidence angles as written, and for each edge at the vertex
    ``(angle, end position, end bit)`` in the same order (``ends``), with the ends' names
    and positions and the bits of all of them (``mask``). Written once, by whoever first
    writes the tag (in a team, the robot that drops the beacon); every numbering that
    learns the vertex holds this same value."""

    tag: str
    at: int
    bit: int
    angles: tuple[float, ...]
    ends: tuple[tuple[float, int, int], ...]
    names: tuple[End, ...]
    positions: tuple[int, ...]
    mask: int

    @classmethod
    def numbered(cls, tag: str, at: int, angles: tuple[float, ...], first: int,
                 step: int) -> Row:
        """The row of ``tag`` at position ``at`` whose ``k``-th end has position
        ``first + k * step``."""
        positions = tuple(range(first, first + len(angles) * step, step))
        ends = tuple((a, i, 1 << i) for a, i in zip(angles, positions))
        mask = 0
        for _, _, bit in ends:
            mask |= bit
        return cls(tag, at, 1 << at, angles, ends, tuple((tag, a) for a in angles),
                   positions, mask)


class Numbering:
    """Bit positions of the tags and ends written by one robot's matrices, or by matrices
    built directly, and the slots of the robots' selections (see the module docstring).
    Entries are added, never changed or removed.

    A *team* numbering (``owner``: the letters of the robot whose numbering it is, one of
    ``team`` robots) gives every entry a position that is a function of who wrote it, so
    that the numberings of one team agree wherever they name the same entry. Robot ``r``
    (0-based, :func:`~algorithms.exploration.beacon_ids.parse_beacon_id`) writes at the
    positions ``c * team + r``: its tag of sequence ``s`` at ``c = s - 1`` and the ends of
    its rows in the order it drops them (the ``k``-th end of a row at its ``base + k``,
    ``base`` being the number of ends of the robot's earlier rows), so a vertex may have
    any number of edges. Its selections are bit ``i`` of the ``r``-th of a matrix's
    selection sets, ``i`` being the selected end. The dropping robot makes the vertex's
    :class:`Row` record; a teammate learns it from the matrices it merges (:meth:`learn`).
    The paper does not say how the columns are numbered. A numbering without owner
    numbers its entries in the order they are written (a team of one) and gives the
    robots selection slots in the order they first select, at most ``_ANYONE`` of them.

    A tag names one vertex with one row of angles (the row its beacon got when dropped);
    writing a tag again with other angles raises ``ValueError``. The other end of a
    completed end is recorded as first written here (``other``, the recorded ends being
    ``linked``); a matrix that knows another one (a re-dropped beacon gives a vertex a
    second tag) keeps it in ``IncidenceMatrix._moved``. ``tangled`` holds the ends for
    which two other ends were seen, the only ends whose other ends :meth:`learn` compares
    with a teammate's besides the ends where a new edge shows a disagreement.
    """

    __slots__ = ("drawn", "end_at", "end_index", "index", "letters", "linked", "other", "owner",
                 "nobody", "row_at", "rows", "slots", "tag_mask", "tangled", "team")

    def __init__(self, owner: str | None = None, team: int = 1) -> None:
        #: letters of the robot whose team numbering this is (None: positions in order),
        #: its 0-based index, and the team size
        self.owner, self.team = owner, team
        self.index = 0 if owner is None else parse_beacon_id(f"{owner}1")[0]
        if not 0 <= self.index < team:
            raise ValueError(f"robot {owner} is not one of a team of {team}")
        #: the number of ends of the rows written here
        self.drawn = 0
        #: tag -> its row, position -> row, and the bits of all tags
        self.rows: dict[str, Row] = {}
        self.row_at: dict[int, Row] = {}
        self.tag_mask = 0
        #: end -> position, and position -> end
        self.end_index: dict[End, int] = {}
        self.end_at: dict[int, End] = {}
        #: end position -> the other end of its completed edge, as first written here;
        #: the bits of those ends, and of the ends seen with two other ends
        self.other: dict[int, End] = {}
        self.linked = self.tangled = 0
        #: selections: robot letters -> slot and slot -> letters; no robot's selections
        #: (one bit set of end positions a slot)
        self.letters = [] if owner is None else [robot_letters(r) for r in range(team)]
        self.slots = {robot: r for r, robot in enumerate(self.letters)}
        self.nobody = (0,) * (_ANYONE if owner is None else team)

    def row(self, tag: str, angles: tuple[float, ...]) -> Row:
        """The row of ``tag``, numbering it if new (in a team numbering only the owner's
        tags are new: a teammate's row is learned, else ``KeyError``)."""
        row = self.rows.get(tag)
        if row is not None:
            if row.angles != angles:
                raise ValueError(f"vertex {tag} written with two rows, "
                                 f"{row.angles} and {angles}")
            return row
        if self.owner is None:
            at = len(self.rows)
        else:
            r, s = parse_beacon_id(tag)
            if r != self.index:
                raise KeyError(f"vertex {tag} of a teammate is not numbered here")
            at = (s - 1) * self.team + r
        row = Row.numbered(tag, at, angles, self._next(len(angles)), self.team)
        self._add(row)
        return row

    def _next(self, count: int) -> int:
        """The position of the first of ``count`` new ends written here."""
        first = self.drawn * self.team + self.index
        self.drawn += count
        return first

    def _add(self, row: Row) -> None:
        self.rows[row.tag] = self.row_at[row.at] = row
        self.tag_mask |= row.bit
        self.end_index.update(zip(row.names, row.positions))
        self.end_at.update(zip(row.positions, row.names))

    def end(self, end: End) -> int:
        """The position of ``end``, numbering it if new (in a team numbering, an end of a
        row not written here raises ``KeyError``)."""
        i = self.end_index.get(end)
        if i is None:
            if self.owner is not None:
                raise KeyError(f"{end} is no end of a vertex numbered here")
            i = self.end_index[end] = self._next(1)
            self.end_at[i] = end
        return i

    def link(self, i: int, other: End) -> bool:
        """Record ``other`` as the other end of end ``i`` unless one is recorded; whether
        the recorded one is ``other`` (if not, both are tangled)."""
        if self.other.setdefault(i, other) == other:
            self.linked |= 1 << i
            return True
        self.tangled |= (1 << i) | (1 << self.end_index.get(other, i))
        return False

    def slot(self, robot: str) -> int:
        """The slot of robot ``robot``'s selections: its index in a team; in a numbering
        without owner, the order of the robots' first selections."""
        r = self.slots.get(robot)
        if r is None:
            if self.owner is not None or len(self.letters) == len(self.nobody):
                raise ValueError(f"robot {robot} has no slot in the numbering of {self.owner}")
            r = self.slots[robot] = len(self.letters)
            self.letters.append(robot)
        return r

    def learn(self, m: IncidenceMatrix) -> IncidenceMatrix:
        """``m``, a matrix of a teammate's team numbering, written in this one: the same
        bits, once the rows new here are taken over (they have the same positions) and the
        other ends of its completed ends reconciled (:meth:`_reconcile`). Only what is new
        here is looked at; selections need nothing (their positions are arithmetic)."""
        there = m.numbering
        new = m._tags & ~self.tag_mask
        if new:
            row_at = there.row_at
            for at in _positions(new):
                self._add(row_at[at])
        return IncidenceMatrix._of(self, m._tags, m._ends, m._completed, m._out,
                                   m._selections, self._reconcile(m), m._first, m._blocked)

    def _reconcile(self, m: IncidenceMatrix) -> Mapping[int, End]:
        """Record the other ends of ``m``'s completed ends new here (as ``m`` knows them);
        the ends whose other end in ``m`` is not the one recorded here (``m``'s
        ``_moved`` in this numbering). Compared are the ends tangled in either numbering
        or moved in ``m``, and an end whose recorded other end a new edge contradicts.
        The paper is silent on tags of one vertex. Not compared (a known gap): an edge
        both of whose vertices were re-dropped, completed by two robots in crossing order
        (``u1``-``v2`` by one, ``u2``-``v1`` by the other), where this numbering and
        ``m``'s each hold one pairing untangled; the pairing recorded here is kept, a true
        edge of the same two vertices under other tags. Closing it means comparing every
        common completed end, the per-end work this comparison avoids."""
        there, done, moved_m = m.numbering, m._completed, m._moved
        marks = there.tangled & done
        for i in moved_m:
            marks |= 1 << i
        self.tangled |= marks
        suspects = self.tangled & done & self.linked
        new = done & ~self.linked
        if new:
            suspects |= self._link_all(new, moved_m, there.other)
        if not suspects:
            return _UNMOVED
        moved = {}
        for i in _positions(suspects):
            e = moved_m.get(i) or there.other[i]
            if e != self.other[i]:
                moved[i] = e
        return moved or _UNMOVED

    def _link_all(self, new: int, moved: Mapping[int, End], theirs: Mapping[int, End]) -> int:
        """Record the other ends of the completed ends ``new``, none linked here, as a
        teammate knows them (``moved``, else ``theirs``); the bits of the ends linked here
        whose recorded other end a new edge contradicts (both ends become tangled). Only
        other ends that are not new can contradict."""
        ends = _positions(new)
        found = [moved.get(i) or theirs[i] for i in ends] if moved else [
            theirs[i] for i in ends]
        self.other.update(zip(ends, found))
        partners = list(map(self.end_index.__getitem__, found))
        suspects = 0
        if not set(partners).issubset(ends):
            for i, j in zip(ends, partners):
                if self.linked >> j & 1 and self.other[j] != self.end_at[i]:
                    suspects |= 1 << j
                    self.tangled |= (1 << i) | (1 << j)
        self.linked |= new
        return suspects


def _positions(bits: int) -> list[int]:
    """Positions of the set bits of ``bits``, lowest first."""
    found = []
    while bits:
        low = bits & -bits
        found.append(low.bit_length() - 1)
        bits ^= low
    return found


class IncidenceMatrix:
    """An immutable, sparse modified incidence matrix (see the module docstring).

    ``rows``: tag -> sorted incidence angles of that vertex's edges (radians).
    ``completed``: end -> other end, for both ends of every completed edge.
    ``out``: out end -> letters of the robots known to have selected it. It stands for
    the column order of the out block: Algorithm 4's circular shift moves a just-selected
    column to the front of the out block, so the rightmost out column, the next one
    chosen, is the one selected least. Sets of selectors keep that round-robin through
    merges (a union), where a plain count would lose selections made concurrently.

    ``blocked``: the blocked ends (see the module docstring), ends of ``rows``.

    ``numbering`` (see :class:`Numbering`) is the one to write the matrix's entries in;
    None: a new one.
    """

    # Bit sets (positions of ``numbering``): ``_tags`` the known rows, ``_ends`` the ends
    # of those rows, ``_completed`` and ``_out`` the completed and out ends, ``_selections``
    # for each selection slot of the numbering, the out ends that robot selected (never a
    # completed one). ``_moved``: end position -> other end, where it is not the one the
    # numbering recorded first. ``_first``: the first key of ``completed`` as a dict would
    # order it, the end of a one-edge matrix that a merge looks at (see :func:`merge`).
    # ``_tree``: the source and the parents of the latest breadth-first search over ``Gc``
    # (see :meth:`layers`), reused by :meth:`route`.
    # ``_blocked``: the blocked ends (module docstring), 0 without closed vertices.
    __slots__ = ("_blocked", "_completed", "_ends", "_first", "_moved", "_out", "_selections",
                 "_tags", "_tree", "numbering")

    def __init__(
        self,
        rows: dict[str, tuple[float, ...]],
        completed: dict[End, End],
        out: dict[End, frozenset[str]],
        numbering: Numbering | None = None,
        blocked: Iterable[End] = (),
    ):
        n = _writable(numbering)
        tags = ends = 0
        for tag, angles in rows.items():
            row = n.row(tag, tuple(angles))
            tags |= row.bit
            ends |= row.mask
        done, moved = 0, {}
        for e, f in completed.items():
            i = n.end(e)
            done |= 1 << i
            if not n.link(i, f):
                moved[i] = f
        marked, selections = 0, list(n.nobody)
        for e, who in out.items():
            i = n.end(e)
            if not done >> i & 1:
                marked |= 1 << i
                for robot in who:
                    selections[n.slot(robot)] |= 1 << i
        self.numbering, self._tags, self._ends, self._completed = n, tags, ends, done
        self._out, self._selections = marked, tuple(selections)
        self._moved, self._first = moved or _UNMOVED, next(iter(completed), None)
        self._blocked = 0
        for e in blocked:
            self._blocked |= 1 << n.end(e)
        self._tree = None

    @classmethod
    def _of(cls, numbering: Numbering, tags: int, ends: int, completed: int, out: int,
                selections: tuple[int, ...], moved: Mapping[int, End], first: End | None,
            blocked: int = 0) -> IncidenceMatrix:
        """A matrix from its bit sets (see the comment on ``__slots__``)."""
        m = object.__new__(cls)
        m.numbering, m._tags, m._ends, m._completed = numbering, tags, ends, completed
        m._out, m._selections, m._moved, m._first = out, selections, moved, first
        m._blocked, m._tree = blocked, None
        return m

    @classmethod
    def initial(
        cls, tag: str, angles: tuple[float, ...], numbering: Numbering | None = None
    ) -> IncidenceMatrix:
        """``I0(vj)`` of eq. (14): one row, every edge of the vertex unexplored."""
        n = _writable(numbering)
        row = n.row(tag, tuple(angles))
        return cls._of(n, row.bit, row.mask, 0, 0, n.nobody, _UNMOVED, None)

    @classmethod
    def edge(
        cls, end_i: End, angles_i: tuple[float, ...], end_j: End, angles_j: tuple[float, ...],
        numbering: Numbering | None = None,
    ) -> IncidenceMatrix:
        """``I'`` of Algorithm 3: the column of the completed edge ``e_ij`` (with the rows of
        its two vertices, whose other edges are unexplored unless known otherwise)."""
        n = _writable(numbering)
        row_i, row_j = n.row(end_i[0], tuple(angles_i)), n.row(end_j[0], tuple(angles_j))
        i, j = n.end(end_i), n.end(end_j)
        moved = {}
        if not n.link(i, end_j):
            moved[i] = end_j
        if not n.link(j, end_i):
            moved[j] = end_i
        return cls._of(n, row_i.bit | row_j.bit, row_i.mask | row_j.mask,
                       (1 << i) | (1 << j), 0, n.nobody, moved or _UNMOVED, end_i)

    # -- the matrix as dictionaries -----------------------------------------------------

    @property
    def rows(self) -> dict[str, tuple[float, ...]]:
        """Tag -> incidence angles, for every known vertex (``Vc``)."""
        n, known = self.numbering, self._tags
        return {t: row.angles for t, row in n.rows.items() if known & row.bit}

    @property
    def completed(self) -> dict[End, End]:
        """End -> other end, for both ends of every completed edge (``Ec``)."""
        ends, other = self.numbering.end_at, self._others()
        return {ends[i]: other[i] for i in _positions(self._completed)}

    @property
    def out(self) -> dict[End, frozenset[str]]:
        """Out end -> letters of the robots known to have selected it (``Eo``)."""
        return {self.numbering.end_at[i]: self._selectors(i) for i in _positions(self._out)}

    @property
    def any_blocked(self) -> bool:
        """Whether some end is blocked (never, in a run without closed vertices)."""
        return self._blocked != 0

    @property
    def blocked(self) -> list[End]:
        """The blocked ends (module docstring), in numbering order."""
        return [self.numbering.end_at[i] for i in _positions(self._blocked)]

    # -- queries --------------------------------------------------------------------

    def is_blocked(self, end: End) -> bool:
        """Whether ``end`` leads to a closed vertex (module docstring)."""
        i = self.numbering.end_index.get(end)
        return i is not None and bool(self._blocked >> i & 1)

    def status(self, end: End) -> int:
        """``COMPLETED``, ``OUT``, ``UNEXPLORED`` or ``UNKNOWN`` (vertex not a row)."""
        n = self.numbering
        i = n.end_index.get(end)
        if i is not None:
            if self._completed >> i & 1:
                return COMPLETED
            if self._out >> i & 1:
                return OUT
        row = n.rows.get(end[0])
        return UNEXPLORED if row is not None and self._tags & row.bit else UNKNOWN

    def angles(self, tag: str) -> tuple[float, ...]:
        """The row of a known vertex: its incidence angles (``KeyError`` if unknown)."""
        row = self.numbering.rows.get(tag)
        if row is None or not self._tags & row.bit:
            raise KeyError(tag)
        return row.angles

    def selectors(self, end: End) -> frozenset[str]:
        """Letters of the robots known to have selected ``end`` if it is out, else none."""
        i = self.numbering.end_index.get(end)
        if i is None or not self._out >> i & 1:
            return _NOBODY
        return self._selectors(i)

    def _selectors(self, i: int) -> frozenset[str]:
        """Letters of the robots known to have selected the out end at position ``i``."""
        letters = self.numbering.letters
        return frozenset([letters[r] for r, ends in enumerate(self._selections) if ends >> i & 1])

    def is_complete(self, source: str | None = None, root: str | None = None) -> bool:
        """Theorem 1: exploration is complete iff ``Eu`` and ``Eo`` are empty, i.e. every
        end of every known vertex belongs to a completed edge (Remark 5: the rightmost
        column of the ordered matrix is a completed one).

        With blocked ends, the rule of the module docstring for a robot at ``source``
        (the tag it stands on) whose exploration started at ``root``: its reach holds
        ``root`` and every end of its reach is completed or blocked (both needed then)."""
        if not self._blocked:
            return self._completed.bit_count() == self._ends.bit_count()
        reach = self.reach(source)
        return root in reach and self._finished(reach)

    def reach_finished(self, source: str) -> bool:
        """Whether every end of the reach of ``source`` is completed or blocked (the reach
        is then ``source``'s whole component without the closed vertices; module
        docstring)."""
        return self._finished(self.reach(source))

    def _finished(self, reach: set[str]) -> bool:
        rows, ends = self.numbering.rows, 0
        for t in reach:
            ends |= rows[t].mask
        return not ends & ~(self._completed | self._blocked)

    def reach(self, source: str) -> set[str]:
        """The tags reachable from ``source`` over ``Gc`` without leaving by a blocked end
        (every known tag when none is blocked, Lemma 1)."""
        return {t for layer in self.layers(source) for t in layer}

    def unexplored(self) -> list[End]:
        """``Eu``: unexplored ends (blocked ones left out), in row order then angle order."""
        rows, known, taken = self.numbering.rows, self._tags, self._completed | self._out
        if self._blocked:
            taken |= self._blocked
        return [(tag, a) for tag, row in rows.items() if known & row.bit
                for a, _, bit in row.ends if not taken & bit]

    def unexplored_at(self, tag: str) -> list[float]:
        """Angles of the unexplored edges at vertex ``tag`` (``Em(vj)`` for a beacon;
        blocked ones left out)."""
        row = self.numbering.rows.get(tag)
        if row is None or not self._tags & row.bit:
            return []
        taken = self._completed | self._out
        if self._blocked:
            taken |= self._blocked
        return [a for a, _, bit in row.ends if not taken & bit]

    def completed_edges(self) -> list[tuple[End, End]]:
        """``Ec``: each completed edge once, as its two ends."""
        ends, other = self.numbering.end_at, self._others()
        return [(ends[i], other[i]) for i in _positions(self._completed) if ends[i] < other[i]]

    def order(self) -> list[tuple[End, ...]]:
        """Algorithm 2: the columns, completed | out | unexplored, each column a tuple of
        its ends. Completed and unexplored columns keep the order in which the team first
        wrote them, as Algorithm 2's concatenation does; out columns go from most to least
        selected, so that the rightmost is the next to help (Algorithm 4's shift)."""
        selectors = self.out
        out = sorted(selectors, key=lambda e: (-len(selectors[e]), e))
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

    def _others(self) -> Mapping[int, End]:
        """End position -> the other end of its edge, as this matrix knows it (read it
        for completed ends only)."""
        other = self.numbering.other
        return {**other, **self._moved} if self._moved else other

    def layers(self, source: str, parents: dict[str, End | None] | None = None):
        """Breadth-first layers of ``Gc`` from ``source``: lists of tags by hop distance,
        each vertex's completed edges taken by angle, never leaving by a blocked end.
        ``parents``, if given, receives for each tag reached the end it was reached by
        (None for ``source``)."""
        rows, done, other = self.numbering.rows, self._completed, self._others()
        if self._blocked:
            done &= ~self._blocked
        seen = {} if parents is None else parents
        seen[source] = None
        self._tree = (source, seen)  # the layers yielded so far are complete in it
        layer = [source]
        while layer:
            yield layer
            following = []
            for t in layer:
                for a, i, bit in rows[t].ends:
                    if done & bit:
                        u = other[i][0]
                        if u not in seen:
                            seen[u] = (t, a)
                            following.append(u)
            layer = following

    def distances(self, source: str) -> dict[str, int]:
        """Hop distances from ``source`` over the completed graph ``Gc`` (breadth first)."""
        return {t: d for d, layer in enumerate(self.layers(source)) for t in layer}

    def nearest(self, source: str, targets: set[str]) -> set[str]:
        """The tags of ``targets`` fewest hops from ``source`` over ``Gc``."""
        for layer in self.layers(source):
            found = targets.intersection(layer)
            if found:
                return found
        raise ValueError(f"none of {sorted(targets)} is reachable from {source}")

    def nearest_open(self, source: str) -> list[End]:
        """The unexplored ends fewest hops from ``source`` over ``Gc``; if no end is
        unexplored, the nearest out ends (empty when the exploration is complete, or when
        no open end is in the reach of ``source``). Blocked ends are never open."""
        n, done, out = self.numbering, self._completed, self._out
        if self._blocked:
            done |= self._blocked
        rows, nearest_out = n.rows, 0
        for layer in self.layers(source):
            ends = 0
            for t in layer:
                ends |= rows[t].mask
            open_ends = ends & ~done
            if open_ends & ~out:
                chosen = open_ends & ~out
                break
            if open_ends and not nearest_out:
                nearest_out, at = open_ends, layer
        else:
            if not nearest_out:
                return []
            chosen, layer = nearest_out, at
        return [(t, a) for t in layer for a, _, bit in rows[t].ends if chosen & bit]

    def route(self, source: str, target: str) -> list[End]:
        """A shortest path from ``source`` to ``target`` over ``Gc`` (Lemma 1 / Remark 4:
        it exists), as the end to leave by at each vertex on the way. Among equal-length
        paths, the one whose departures have the smallest angles, vertex by vertex."""
        if source == target:
            return []
        if self._tree is not None and self._tree[0] == source and target in self._tree[1]:
            parent = self._tree[1]
        else:
            parent = {}
            for _ in self.layers(source, parent):
                if target in parent:
                    break
            else:
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
        n = _writable(self.numbering)
        if n is not self.numbering:  # EMPTY's numbering is never written
            return IncidenceMatrix({}, {}, {end: frozenset([robot])}, n)
        i = n.end(end)
        if self._completed >> i & 1:
            return self
        r, bit, selections = n.slot(robot), 1 << i, self._selections
        if selections[r] & bit:
            return self
        selections = (*selections[:r], selections[r] | bit, *selections[r + 1:])
        m = self._of(n, self._tags, self._ends, self._completed, self._out | bit,
                     selections, self._moved, self._first, self._blocked)
        m._tree = self._tree  # the same Gc
        return m

    def block(self, end: End) -> IncidenceMatrix:
        """Mark ``end``, an end of a known row, blocked: the vertex at its far end is
        closed (module docstring). Its status stays as it is."""
        i = self.numbering.end_index.get(end)
        if i is None or not self._ends >> i & 1:
            raise KeyError(f"{end} is no end of a known vertex")
        if self._blocked >> i & 1:
            return self
        return self._of(self.numbering, self._tags, self._ends, self._completed, self._out,
                        self._selections, self._moved, self._first, self._blocked | 1 << i)

    def _renumbered(self, numbering: Numbering) -> IncidenceMatrix:
        """The same matrix written in ``numbering``."""
        m = IncidenceMatrix(self.rows, self.completed, self.out, numbering, self.blocked)
        m._first = self._first
        return m


#: The numbering of ``EMPTY``, never written.
_NONE = Numbering()

#: ``I0(Rk)`` of eq. (14): a robot at the start knows nothing.
EMPTY = IncidenceMatrix._of(_NONE, 0, 0, 0, 0, _NONE.nobody, _UNMOVED, None)


def _writable(numbering: Numbering | None) -> Numbering:
    """``numbering``, or a new one if None or ``EMPTY``'s (which stays empty)."""
    return Numbering() if numbering is None or numbering is _NONE else numbering


def merge(a: IncidenceMatrix, b: IncidenceMatrix) -> IncidenceMatrix:
    """Algorithm 1 followed by Algorithm 2's block order: the union of rows and columns
    with copies of common vertices and edges removed.

    A common edge (same vertex tag, same ``|theta|``) takes the more advanced status:
    completed over out over unexplored (Algorithm 1: differing signs become negative; a
    completed column replaces the other copy); a common out edge keeps the selectors of
    both copies. The result is equations (2) and (3) for ``Gc``, ``Eo`` and ``Eu``.
    Merging is commutative in content, and an operand that already contains the other is
    returned as it is. Two details matter only where operands disagree on the other end
    of a completed end (after a beacon was wiped and dropped again): the operand with
    fewer completed ends wins, and a one-edge matrix (Algorithm 3's ``I'``) counts as
    contained when the other operand knows its rows and its first end as completed.
    """
    if a is b or b is EMPTY:
        return a
    if a is EMPTY:
        return b
    if b.numbering is not a.numbering:
        if a.numbering.owner is None or b.numbering.owner is None:
            b = b._renumbered(a.numbering)
        else:
            b = a.numbering.learn(b)
    count_a, count_b = a._completed.bit_count(), b._completed.bit_count()
    if count_a < count_b:
        a, b, count_b = b, a, count_a
    if count_b == 2 and b._tags.bit_count() == 2 and not b._out and not b._blocked:
        if a._completed >> a.numbering.end_index[b._first] & 1 and not b._tags & ~a._tags:
            return a
        return _union(a, b)
    if _contains(a, b):
        return a
    if count_a == count_b and _contains(b, a):
        return b
    return _union(a, b)


def _union(a: IncidenceMatrix, b: IncidenceMatrix) -> IncidenceMatrix:
    """Algorithm 1's union of two matrices of one numbering (``b``'s other ends win)."""
    done = a._completed | b._completed
    out = (a._out | b._out) & ~done  # out on one side, completed on the other: not out
    selections = a._selections
    if selections is not b._selections:
        selections = tuple([(x | y) & out for x, y in zip(selections, b._selections)])
    moved = _UNMOVED
    if a._moved or b._moved:
        moved = {i: e for i, e in a._moved.items() if not b._completed >> i & 1}
        moved.update(b._moved)
    return IncidenceMatrix._of(
        a.numbering, a._tags | b._tags, a._ends | b._ends, done, out,
        selections, moved, a._first if a._completed else b._first, a._blocked | b._blocked)


def _contains(a: IncidenceMatrix, b: IncidenceMatrix) -> bool:
    """True if every entry of ``b`` is in ``a`` with at least ``b``'s status (both of one
    numbering)."""
    if b._tags & ~a._tags or b._completed & ~a._completed or (
            b._blocked and b._blocked & ~a._blocked):
        return False
    if b._selections is a._selections:
        return True
    done = a._completed  # selections of ends a knows as completed do not count
    for x, y in zip(b._selections, a._selections):
        if x & ~(y | done):
            return False
    return True
