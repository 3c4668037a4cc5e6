"""MR-DFS, the multi-robot depth-first search of Brass, Cabrera-Mora, Gasparri and Xiao
(IEEE T-RO 27(4), 2011), the main baseline of Nagavarapu et al. (section 6, Figs. 8, 16, 17).

Bookkeeping devices at the vertices record, for each edge, how many robots went down it
and whether it is *finished* (everything behind it explored). A robot at a vertex:

1. takes an unexplored edge (no robot went down it) if there is one;
2. otherwise an explored but unfinished edge, the one with the fewest robots sent down
   it (robots help where help is scarcest);
3. otherwise (every edge but the one towards the root is finished) goes back up its
   parent edge and marks it finished at the parent on arrival; at the root this is the
   end: completion is declared there, which is why MR-DFS needs to return to the root.

Rules inferred where the paper's text was not available to us:

* The parent edge of a vertex is the edge by which the first robot entered it; it is
  stored on the beacon. Every other edge is a child edge.
* Graphs with cycles: a robot going down an edge into an already visited vertex by an
  edge other than that vertex's parent edge has closed a cycle; it marks the edge
  finished there, returns along it and marks it finished at the other end too.
* Among unexplored edges: the first counter-clockwise from the edge the robot arrived by
  (+x at the root), as for the proposed method; among explored ones, fewest robots first,
  then the same order. With an ``rng``, these ties are broken at random.
* Robots that arrive at the same time (the graph world) first all record their arrival
  on the beacons (:meth:`MRDFS.arrive`: parent edge, finished edges), then decide one
  after another, each seeing the counts the previous one left (so they take distinct
  unexplored edges): Brass et al.'s bookkeeping devices record every arrival before any
  robot leaves. Decided in arrival order instead, a robot would not yet know that
  another had just come in along a cycle edge and would traverse that edge again
  (fig9 with 2 robots: makespan 14, against 12).
* The map (for metrics) is built with the incidence matrix like every strategy
  (:mod:`~algorithms.exploration.mapping`); it plays no part in the decisions.

Checks (tests): with one robot this is single-robot DFS, exactly 2E steps on a tree; with
two robots it takes at most E + r (Nagavarapu et al. section 6) on random trees.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from algorithms.exploration.base import DONE, Beacon, Decision, ccw_from
from algorithms.exploration.incidence_matrix import merge
from algorithms.exploration.mapping import MapStrategy, VertexRecord

#: What the edge a robot is on means for it when it arrives: going down (exploring or
#: helping), or going back with everything behind it finished.
DESCENDING, FINISHING = "descending", "finishing"


@dataclass(slots=True)
class DFSRecord(VertexRecord):
    """Beacon record: incidence matrix plus MR-DFS's bookkeeping, edges keyed by angle."""

    parent: float | None = None
    robots: dict[float, int] = field(default_factory=dict)
    finished: set[float] = field(default_factory=set)


class MRDFS(MapStrategy):
    """Multi-robot DFS with finished-edge marking and helping (see module docstring)."""

    name = "mr-dfs"
    record_type = DFSRecord

    def __init__(self, index, n_robots, rng=None):
        super().__init__(index, n_robots, rng)
        self.mode = DESCENDING
        self._arrived: DFSRecord | None = None  # recorded by arrive(), not yet decided
        self._closed_cycle = False

    def arrive(self, beacon: Beacon, angles: Sequence[float], arrived_by: float | None) -> None:
        """Record the arrival on the beacon: the parent edge of a new vertex, a finished
        edge; an arrival along a new edge into a known vertex closes a cycle."""
        new = beacon.data is None
        record, _ = self.first_step(beacon, angles, arrived_by)
        self._closed_cycle = False
        if arrived_by is not None:
            if new:
                record.parent = self.arrival
            elif self.mode == FINISHING:
                record.finished.add(self.arrival)
            elif self.arrival != record.parent:
                record.finished.add(self.arrival)
                self._closed_cycle = True
        self._arrived = record

    def on_vertex(
        self, beacon: Beacon, angles: Sequence[float], arrived_by: float | None
    ) -> Decision:
        if self._arrived is None:
            self.arrive(beacon, angles, arrived_by)
        record, self._arrived = self._arrived, None
        # arrivals recorded since this robot's own: take their knowledge along
        self.matrix = record.matrix = merge(self.matrix, record.matrix)
        if self._closed_cycle:
            return self._move(record, self.arrival, FINISHING)
        children = [
            a
            for a in ccw_from(self.arrival, self.matrix.angles(self.here))
            if a != record.parent and a not in record.finished
        ]
        if self.rng is not None:
            children = [children[i] for i in self.rng.permutation(len(children))]
        counts = record.robots
        unexplored = [a for a in children if not counts.get(a)]
        if unexplored:
            return self._descend(record, unexplored[0])
        if children:
            return self._descend(record, min(children, key=lambda a: counts[a]))
        if record.parent is None:
            return DONE
        return self._move(record, record.parent, FINISHING)

    def _descend(self, record: DFSRecord, angle: float) -> Decision:
        record.robots[angle] = record.robots.get(angle, 0) + 1
        return self._move(record, angle, DESCENDING)

    def _move(self, record: DFSRecord, angle: float, mode: str) -> Decision:
        self.mode = mode
        return self.leave(record, (self.here, angle))
