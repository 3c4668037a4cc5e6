"""What every strategy does at a vertex before deciding: name and drop beacons, merge the
incidence matrix (Algorithm 3), and mark the chosen edge out when leaving (eq. (5)).

All strategies, baselines included, build their map this way, so that "the declaring
robot's map" means the same thing for each of them; the baselines do not use the map to
choose edges (see their modules).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from algorithms.exploration.base import (
    TWO_PI,
    Beacon,
    Decision,
    Strategy,
    go,
    match_angle,
    normalize_angle,
)
from algorithms.exploration.beacon_ids import beacon_id, robot_letters
from algorithms.exploration.incidence_matrix import (
    UNEXPLORED,
    End,
    IncidenceMatrix,
    Numbering,
    merge,
)


@dataclass(slots=True)
class VertexRecord:
    """What a beacon stores: the incidence matrix ``In(vj)``. Baselines extend it."""

    matrix: IncidenceMatrix


class MapStrategy(Strategy):
    """Beacon naming, Algorithm 3 (first step on a vertex visit) and eq. (5) bookkeeping.

    The angles a robot measures are used to write a new beacon's row; at a vertex that
    already has a beacon the stored angles are authoritative, and the measured arrival
    angle is matched to the nearest of them (within ``ANGLE_TOLERANCE``), so that every
    robot names an edge end with the same number.

    After :meth:`first_step`, ``self.here`` is the tag of the current vertex,
    ``self.arrival`` the angle (at this vertex) of the edge the robot came by, or 2*pi
    (the +x reference) when it did not move; ``self.matrix`` is ``In(Rk)``, empty at the
    start. The matrices a robot writes use its own team numbering
    (:class:`~algorithms.exploration.incidence_matrix.Numbering`); what it reads from a
    beacon :func:`merge` writes in it.
    """

    record_type: type[VertexRecord] = VertexRecord

    def __init__(self, index, n_robots, rng=None):
        super().__init__(index, n_robots, rng)
        self.letters = robot_letters(index)
        self.matrix = IncidenceMatrix({}, {}, {}, Numbering(self.letters, n_robots))
        self.here: str | None = None
        self.arrival: float = TWO_PI
        self.root: str | None = None
        self._dropped = 0
        self._left_by: End | None = None

    def first_step(
        self, beacon: Beacon, angles: Sequence[float], arrived_by: float | None
    ) -> tuple[VertexRecord, IncidenceMatrix | None]:
        """Algorithm 3: drop a beacon with ``I0(vj)`` on a first visit, then
        ``In(Rk) = In(vj) = Order(Merge(Merge(I', In-1(Rk)), In-1(vj)))``.

        Returns the beacon's record and its matrix as it was before the merge (``None``
        if the beacon was just dropped).
        """
        record = beacon.data
        if record is None:
            self._dropped += 1
            beacon.id = tag = beacon_id(self.index, self._dropped)
            row = tuple(sorted(map(normalize_angle, angles)))
            record = beacon.data = self.new_record(
                IncidenceMatrix.initial(tag, row, self.matrix.numbering))
            before = None
            self.stored_angles = None
        else:
            tag = beacon.id
            before = record.matrix
            row = self.stored_angles = before.angles(tag)
            if before.numbering is not self.matrix.numbering:  # a teammate's: its names
                record.matrix = self.matrix.numbering.learn(before)
        matrix = self.matrix
        if arrived_by is not None and self._left_by is not None:
            self.arrival = match_angle(normalize_angle(arrived_by), row)
            left = self._left_by
            column = IncidenceMatrix.edge(left, matrix.angles(left[0]), (tag, self.arrival), row,
                                          matrix.numbering)
            matrix = merge(column, matrix)
        else:
            self.arrival = TWO_PI
        self._left_by = None
        self.matrix = record.matrix = merge(matrix, record.matrix)
        self.here = tag
        if self.root is None:
            self.root = tag
        return record, before

    def new_record(self, matrix: IncidenceMatrix) -> VertexRecord:
        """The record a newly dropped beacon starts with."""
        return self.record_type(matrix)

    def leave(self, record: VertexRecord, end: End, selected: End | None = None) -> Decision:
        """Second-step bookkeeping: mark ``selected`` (default: ``end``) out if it was
        unexplored (eq. (5), Algorithm 4's negation), write ``In(vj) = In(Rk)`` and leave
        along ``end``, an edge of the current vertex."""
        selected = end if selected is None else selected
        if self.matrix.status(selected) == UNEXPLORED:
            self.matrix = self.matrix.select(selected, self.letters)
        record.matrix = self.matrix
        self._left_by = end
        return go(end[1])

    def forget_departure(self) -> None:
        """It did not leave along the edge of its latest :meth:`leave` (the far vertex is
        closed): its next call, at the same vertex, completes no edge."""
        self._left_by = None

    def map_edges(self) -> list[tuple[str, str]]:
        """Its completed edges; with blocked ends, those within its reach (the part it
        declares, :mod:`~algorithms.exploration.incidence_matrix`)."""
        m = self.matrix
        if m.any_blocked and self.here is not None:
            reach = m.reach(self.here)
            return [(e[0], f[0]) for e, f in m.completed_edges()
                    if e[0] in reach and f[0] in reach]
        return [(e[0], f[0]) for e, f in m.completed_edges()]
