"""Least recently visited (LRV), the baseline of Batalin and Sukhatme (IEEE T-RO 2007) as
Nagavarapu et al. compares it on the 10 x 10 lattice (Fig. 17).

LRV is a local rule: the node (here the beacon) keeps, for each of its edges, how many
times robots have traversed it, and a robot leaves along the least traversed one. Rules
inferred where the papers are silent:

* A traversal is counted at both of the edge's ends, whichever direction it went (the
  departing robot counts it at the vertex it leaves, the arriving robot at the vertex it
  reaches), so "least recently visited" is seen the same from both sides.
* Ties go to the first edge counter-clockwise from the one the robot arrived by (+x at the
  start); the arrival edge itself comes last, so a robot does not turn back on a tie.
  With an ``rng``, ties are broken at random.
* LRV has no completion test of its own. The robots build and merge the incidence matrix
  (:mod:`~algorithms.exploration.mapping`) only to declare completion by Theorem 1; the map
  never influences the choice of edge.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from algorithms.exploration.base import DONE, Beacon, Decision, ccw_from
from algorithms.exploration.mapping import MapStrategy, VertexRecord


@dataclass(slots=True)
class LRVRecord(VertexRecord):
    """Beacon record: the incidence matrix and the traversal count of each edge (by angle)."""

    visits: dict[float, int] = field(default_factory=dict)


class LRV(MapStrategy):
    """Leave along the least traversed edge of the current vertex."""

    name = "lrv"
    record_type = LRVRecord

    def on_vertex(
        self, beacon: Beacon, angles: Sequence[float], arrived_by: float | None
    ) -> Decision:
        record, _ = self.first_step(beacon, angles, arrived_by)
        visits = record.visits
        if arrived_by is not None:
            visits[self.arrival] = visits.get(self.arrival, 0) + 1
        if self.matrix.is_complete():
            return DONE
        order = ccw_from(self.arrival, self.matrix.angles(self.here))
        if self.rng is not None:
            order = [order[i] for i in self.rng.permutation(len(order))]
        choice = min(order, key=lambda a: visits.get(a, 0))
        visits[choice] = visits.get(choice, 0) + 1
        return self.leave(record, (self.here, choice))
