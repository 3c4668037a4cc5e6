"""Nagavarapu et al.'s decentralised multi-robot exploration: the modified MR-DFS with the
incidence matrix (section 3, Algorithms 3 and 4, priority (4), Theorem 1 / Remark 5).

One call of :meth:`FrontierExplorer.on_vertex` is one update instance ``n`` for the
visiting robot: the first step (Algorithm 3, :class:`~algorithms.exploration.mapping.MapStrategy`)
merges robot, beacon and the column of the edge just completed; the completion test
(Theorem 1) stops the robot; otherwise the second step (Algorithm 4) keeps or makes a
selection, queues the shortest path over the robot's completed graph ``Gc(Rk)`` to the
known end of the selected edge, marks the selected edge out (eq. (5)) and leaves along the
first queued edge.

Choices where the paper is silent or ambiguous (each checked by tests):

* **Set equations, not column placement.** The selection follows the set equations
  (3)-(5) with priority (4): ``Em(Rk)``, then ``Eu(Rk)``, then ``Eo(Rk)``. Algorithm 3's
  literal column placement puts the beacon's unexplored edges to the right of the robot's
  own, which contradicts (4) at revisited vertices (DESIGN notes); the matrix still holds
  the same entries (I10(v6) test).
* **Em(Rk) is a stack.** The ordered sum ``Em(vj) + Em(Rk)`` of (3) puts the current
  vertex's unexplored edges first (depth first), in counter-clockwise order starting from
  the edge the robot arrived by (+x at the root); this reproduces Fig. 9, where sorting by
  absolute angle does not. Edges that became out or completed are dropped when they reach
  the top.
* **Column order of I0(vj).** A beacon's row keeps its edges by increasing angle in
  (0, 2*pi]; which of them a robot prefers is the stack order above (equivalently, the
  rightmost column of ``I0(vj)`` is the first edge counter-clockwise from the arrival).
* **Within Eu and Eo** (the paper: "the rightmost column"), the edge whose known end is
  nearest in hops over ``Gc(Rk)``; among equally near out edges the one selected least
  often (the round-robin that Algorithm 4's circular shift of the out block produces:
  helpers spread over unfinished branches); then by beacon id and angle. With an ``rng``,
  ties among a vertex's own new edges and among the remaining candidates are random.
  Without it, helpers pile into one branch and the method falls behind MR-DFS on
  branching trees (``tree3`` with 4 robots: 9 steps against 8).
* **Re-selection while travelling.** Algorithm 4 keeps the decision "until the selected
  edge is a completed edge". Under that literal reading Proposition 2 fails (a star
  explored from its centre by K >= 2 robots takes 17 steps for E = 12). Default
  (``reselect="taken"``): at every vertex on the way the robot compares what the
  beacon knew about its selected edge *before* the merge with what the robot knew right
  after selecting it (out, with itself among the selectors). If the beacon knows more -
  the edge is completed, or out with a selector the robot did not know of - another
  robot has taken it (or is also heading there), and the robot selects again at once,
  with what it has just learned. A reservation of its own that another robot merely
  carried to this beacon does not count. ``reselect="completed"`` is the literal
  reading, kept to show the difference.
* **Negation and circular shift.** The selected column is negated (made out) only when a
  selection is made (the pseudo-code's indentation was lost; negating at every visit
  would mark edges the robot never takes). "Circularly shift-right" keeps the completed
  block fixed and moves the selected column to the front of the out block; the sparse
  matrix records it as one more selection of that out edge (``IncidenceMatrix.out``).
* Completion is tested at every vertex visit, including vertices passed while travelling.
* **Closed vertices** (ours: a robot stopped for good in a vertex area that no
  robot can pass). The station of a closed vertex answers a request for it with
  ``EntryBlocked``; the robot has not left, and :meth:`IncidenceDFS.block` marks the end it
  asked for blocked (:mod:`~algorithms.exploration.incidence_matrix`: a blocked end is
  neither unexplored nor out, never a candidate, never left by on a route, and counts as
  finished), drops its queue (the next call, at the same vertex, writes the mark into the
  beacon and decides anew). An end of ``Em(Rk)`` outside the robot's reach (known vertices
  reachable over ``Gc`` without leaving by a blocked end) is dropped as a taken one is, and
  so is a decision whose queue holds a blocked end. Completion is Theorem 1's test on the
  reach (the rule in :mod:`~algorithms.exploration.incidence_matrix`): the team declares
  completion of the part it can reach; a robot cut off from the root answers IDLE while
  its reach holds an end out (another robot on it), and ``CUT_OFF`` once its whole reach
  is finished. Without blocked ends every step takes the paper's
  path unchanged. Only ``incidence-dfs`` handles closed vertices; the other strategies
  refuse (:meth:`~algorithms.exploration.base.Strategy.block`).
"""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Sequence

from algorithms.exploration.base import (
    CUT_OFF,
    DONE,
    IDLE,
    Beacon,
    Decision,
    ccw_from,
    match_angle,
    normalize_angle,
)
from algorithms.exploration.incidence_matrix import (
    COMPLETED,
    OUT,
    UNEXPLORED,
    End,
    IncidenceMatrix,
)
from algorithms.exploration.mapping import MapStrategy

RESELECT_RULES = ("taken", "completed")


class FrontierExplorer(MapStrategy):
    """Algorithm 4's machinery: queue ``Q`` of edges to the selected edge, re-selection,
    completion. Subclasses choose the edge (:meth:`select`)."""

    def __init__(self, index, n_robots, rng=None, reselect: str = "taken"):
        super().__init__(index, n_robots, rng)
        if reselect not in RESELECT_RULES:
            raise ValueError(f"reselect must be one of {RESELECT_RULES}, got {reselect!r}")
        self.reselect = reselect
        self.queue: list[End] = []
        #: Robots known to have selected the selected edge, this one included.
        self._selectors: frozenset[str] = frozenset()
        #: ends of the vertex it stands on that it gave up waiting for (only strategies
        #: that plan round them fill it: ``IncidenceDFS.give_up``)
        self._given_up: set[End] = set()

    def on_vertex(
        self, beacon: Beacon, angles: Sequence[float], arrived_by: float | None
    ) -> Decision:
        if self._given_up and (arrived_by is not None or beacon.id != self.here):
            self._given_up.clear()  # ends of a vertex it has left
        record, before = self.first_step(beacon, angles, arrived_by)
        self.observe()
        if self.matrix.is_complete(self.here, self.root):
            self.queue.clear()
            return DONE
        if self.queue and not self._keep(before):
            self.queue.clear()
        if not self.queue:
            plan = self.plan()
            if plan is None:  # cut off from the root, nothing open within reach
                return CUT_OFF if self.matrix.reach_finished(self.here) else IDLE
            selected, route = plan
            self.matrix = self.matrix.select(selected, self.letters)
            self._selectors = self.matrix.selectors(selected)
            self.queue = [*route, selected]
        end = self.queue.pop(0)
        return self.leave(record, end, self.queue[-1] if self.queue else end)

    def _keep(self, before: IncidenceMatrix | None) -> bool:
        """Whether the decision in ``Q`` stands at this vertex (see module docstring)."""
        selected, m = self.queue[-1], self.matrix
        if self.queue[0][0] != self.here or m.status(selected) == COMPLETED:
            return False
        # the matrix's blocked bit set, read directly: 0 but with closed vertices, and this
        # runs at every vertex on the way (the graph world's hot path)
        if m._blocked and any(map(m.is_blocked, self.queue)):
            return False
        if self.reselect == "completed" or before is None:
            return True
        status = before.status(selected)
        if status == COMPLETED:
            return False
        return status != OUT or before.selectors(selected) <= self._selectors

    def observe(self) -> None:
        """Hook run after the first step, before any decision."""

    def plan(self) -> tuple[End, list[End]] | None:
        """Algorithm 4's new decision: the selected edge and the shortest route over
        ``Gc(Rk)`` to its known end (None: nothing open within reach)."""
        selected = self.select()
        return None if selected is None else (selected, self.matrix.route(self.here, selected[0]))

    @abstractmethod
    def select(self) -> End | None:
        """The edge to explore next; called only when the exploration is not complete.
        None: no open edge within the robot's reach (only with blocked ends)."""

    def pick(self, ends: list[End]) -> End:
        """One of equally near ends: the one fewest *other* robots are known to have
        selected (out edges; see ``IncidenceMatrix.out``; a robot re-selecting must not be
        held back by its own earlier choice), then the smallest (beacon id, angle), or at
        random among those with an ``rng``."""
        selectors, me = self.matrix.selectors, self.letters
        others = [len(who) - (me in who) for who in map(selectors, ends)]
        fewest = min(others)
        ties = sorted(e for e, n in zip(ends, others) if n == fewest)
        return ties[0] if self.rng is None else ties[self.rng.integers(len(ties))]


class IncidenceDFS(FrontierExplorer):
    """The proposed strategy: priority (4) ``{Em(Rk), Eu(Rk), Eo(Rk)}``."""

    name = "incidence-dfs"
    replans = True

    def __init__(self, index, n_robots, rng=None, reselect: str = "taken"):
        super().__init__(index, n_robots, rng, reselect)
        #: ``Em(Rk)``: my-unexplored ends, most preferred last.
        self.my_unexplored: list[End] = []

    def plan(self) -> tuple[End, list[End]] | None:
        """Algorithm 4's decision; after :meth:`give_up`, made on a copy of the matrix in
        which the ends given up are blocked (so that it neither selects them nor routes
        through them), with ``Em(Rk)`` as it was (the copy's pops are undone: the ends are
        busy, not closed). If that leaves nothing open within reach, it forgets what it
        gave up and decides as before: it queues again."""
        if not self._given_up:
            return super().plan()
        real, stack = self.matrix, list(self.my_unexplored)
        for end in self._given_up:
            self.matrix = self.matrix.block(end)
        try:
            plan = super().plan()
        finally:
            self.matrix, self.my_unexplored = real, stack
        if plan is None:
            self._given_up.clear()
            return super().plan()
        return plan

    def give_up(self, angle: float) -> None:
        """The robot waited too long for the vertex across the edge at ``angle`` (rad, the
        beacons' frame) from the vertex of the latest call, and did not leave
        (:mod:`~algorithms.exploration.entry`, step 8; ours): it drops its queue
        and, at the next call here, plans without leaving by that edge (nor by any other
        it gave up here). Nothing is written into the matrix: the edge keeps its status
        (out, if it selected it: the marks of an abandoned selection stay, as after a
        "taken" re-selection), so Theorem 1's completion test is unchanged, and an edge
        given up is still explored by whoever selects it later (this robot too, once it
        has left this vertex). What it costs is liveness only: a robot may give up and
        come back more than once."""
        here = self.here
        self._given_up.add((here, match_angle(normalize_angle(angle), self.matrix.angles(here))))
        self.queue.clear()
        self.forget_departure()

    def observe(self) -> None:
        """Eq. (3): ``Em(Rk) = Em(vj) + Em(Rk)``: push this vertex's unexplored edges."""
        fresh = self.matrix.unexplored_at(self.here)
        if fresh:
            order = ccw_from(self.arrival, fresh)
            if self.rng is not None:
                order = [order[i] for i in self.rng.permutation(len(order))]
            self.my_unexplored.extend((self.here, a) for a in reversed(order))

    def select(self) -> End | None:
        """Priority (4): the top of ``Em(Rk)`` that is still unexplored (and, with blocked
        ends, not blocked and within reach); else the nearest unexplored edge
        (``Eu(Rk)``); else the nearest out edge (``Eo(Rk)``); None if none is in reach."""
        stack, m = self.my_unexplored, self.matrix
        status = m.status
        if m._blocked:  # as in ``_keep``
            reach = m.reach(self.here)
            while stack and (status(stack[-1]) != UNEXPLORED or m.is_blocked(stack[-1])
                             or stack[-1][0] not in reach):
                stack.pop()
        while stack and status(stack[-1]) != UNEXPLORED:
            stack.pop()
        if stack:
            return stack[-1]
        nearest = m.nearest_open(self.here)
        return self.pick(nearest) if nearest else None

    def block(self, angle: float) -> None:
        """The edge at ``angle`` (rad, the beacons' frame) from the vertex of the latest
        call leads to a closed vertex; the robot did not leave (module docstring)."""
        here = self.here
        self.matrix = self.matrix.block((here, match_angle(normalize_angle(angle),
                                                           self.matrix.angles(here))))
        self.queue.clear()
        self.forget_departure()
