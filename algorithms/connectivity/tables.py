"""Le et al.: connectivity tables of access paths to a reference robot.

An *access path* of robot R (Definition 1) is a path from one of R's neighbours, its
*access robot*, to the reference robot that avoids R. It is stored as the tuple
``(access robot, ..., reference)``; the reference itself announces the empty path ``()``.
R's *connectivity table* holds the access paths it has learnt (section 2, Table 2).

Building (Algorithm 1, New-Access-Path): the reference broadcasts ``()``; a robot receiving
path p from sender s drops it if its own id is in p (loops), else stores ``(s,) + p`` and,
if the forwarding rule accepts it, broadcasts it on. Updating (section 4): a robot that
loses a neighbour deletes the paths through that link and broadcasts Link-Broken; a robot
deleting a path because of a Link-Broken forwards it, else drops it. Robots that meet a new neighbour
send it their table; the receiver runs Algorithm 1 on each path.

Choices, where the paper is silent or contradicts itself:

* **Stored vs forwarded.** Algorithm 1 stores every received path (line 6, before the test
  of line 7), and Table 2 lists non-disjoint paths (R4: (R2, R1), (R7, R3, R2, R1)), though
  section 3 says robots "store and propagate only access paths that are internally
  disjoint". We store every path (the literal algorithm) and keep the forwarding rule below.
* **Forwarding rule.** Line 7 forwards a path only if it is internally disjoint with every
  stored path. Taken literally that misses doubly connected robots (a robot whose second
  route overlaps a stored-but-unforwarded path never passes it on): measured on 500
  connected random geometric teams of 5-30 robots at mean degree 4, 329 of 8554 robots
  wrong and 7 of 500 team verdicts. We forward a path iff it *shrinks the set of robots shared
  by all paths forwarded so far* (the robots whose loss would cut this robot off, as far as
  its neighbours can tell); the first path is always forwarded, and forwarding stops once
  that set is empty (typically: two internally disjoint paths have gone out). With that rule the table's shared set equals
  the true set of single points of failure between R and the reference (proof sketch in
  :meth:`ConnectivityTable.critical_robots`), so the check below is exact. Every robot
  forwards at most n - 1 paths: O(n^2) messages in all, the paper's bound.
* **Forward-two variant** (``max_forwards=2``, Le et al. section 5, [LBSM09]): store all,
  forward at most two: the first path and then the first one internally disjoint with it
  (in general, with a budget of k the last forward must empty the shared set). At most 2n
  messages. Its verdicts are sound but can miss: a robot with two disjoint paths may not
  learn them (same 500 teams: 141 of 8554 robots, 2 of 500 team verdicts).
* **Links.** Paths arriving from a robot that is no longer a neighbour are ignored (the link
  broke while the message was in flight). After deleting paths a robot re-offers its
  remaining stored paths to the forwarding rule; without this, tables after a removal
  keep fewer paths than a recomputation finds. The table sent to a new neighbour is the
  list of paths this robot has forwarded: what a neighbour present from the start got.
* **Hop times.** With moving robots a link can break and come back while its Link-Broken
  is still travelling; the paper's message would then delete good paths learnt over the
  new link, for good. So messages carry, for each link of the path, the tick at which
  they crossed it (a shared clock: ticks in the harness, simulation time in the world),
  Link-Broken carries the tick of the break, and a robot deletes only paths that crossed
  the link no later than that. A path heard again keeps its newest hop times and, if it
  was forwarded, is announced again.
* **Neighbours at the first tick** are the initial network (Le et al. assumes the robots
  start together); only later changes trigger exchange or Link-Broken.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable
from itertools import pairwise
from typing import NamedTuple

from algorithms.robot import Message

#: ``(access robot, ..., reference)``; ``()`` is the reference's own announcement.
AccessPath = tuple


class NewAccessPath(NamedTuple):
    """Algorithm 1's message: the sender's access path (the sender is the envelope's).

    Hop times: ``times[0]`` is the tick at which the announcement crossed the link
    sender-``path[0]``, ``times[j]`` the link ``path[j-1]``-``path[j]`` (see Link-Broken).
    """

    path: AccessPath
    times: tuple[int, ...] = ()


class LinkBroken(NamedTuple):
    """Section 4: the link between robots u and v was found broken at tick ``at``."""

    u: Hashable
    v: Hashable
    at: int


class TableExchange(NamedTuple):
    """Section 4: the sender's table, ``(path, times)`` pairs, for a robot it has met."""

    entries: tuple[tuple[AccessPath, tuple[int, ...]], ...]


def interior(path: AccessPath) -> frozenset:
    """The robots a stored path passes through before the reference (access robot included)."""
    return frozenset(path[:-1])


def crossed_before(
    robot_id: Hashable, path: AccessPath, times: tuple[int, ...], link: LinkBroken
) -> bool:
    """True if the route ``robot_id, *path`` crossed ``link`` no later than its break.

    A path that crossed the link after the break was learnt over the link as it is now
    (it broke and came back while the news travelled) and stays.
    """
    route = (robot_id, *path)
    return any(
        {a, b} == {link.u, link.v} and t <= link.at
        for (a, b), t in zip(pairwise(route), times)
    )


def _canonical(ids: Iterable[Hashable]) -> list[Hashable]:
    """A deterministic order for id sets (independent of hash seeds)."""
    return sorted(ids, key=repr)


class ConnectivityTable:
    """One robot's connectivity table and its upkeep (Le et al., Algorithm 1 and section 4).

    Args:
        robot_id: this robot's id.
        reference: the reference robot's id (chosen beforehand, Le et al. section 3).
        max_forwards: None for the base algorithm, 2 for the forward-two variant.
    """

    def __init__(
        self, robot_id: Hashable, reference: Hashable, *, max_forwards: int | None = None
    ) -> None:
        if max_forwards is not None and max_forwards < 1:
            raise ValueError("max_forwards must be at least 1")
        self.robot_id = robot_id
        self.reference = reference
        self.max_forwards = max_forwards
        self._paths: dict[AccessPath, tuple[int, ...]] = {}  # path -> hop times
        self._forwarded: dict[AccessPath, None] = {}
        self._shared: frozenset = frozenset()
        self._neighbors: frozenset | None = None

    @property
    def is_reference(self) -> bool:
        """This robot is the reference robot."""
        return self.robot_id == self.reference

    @property
    def paths(self) -> list[AccessPath]:
        """Stored access paths, oldest first."""
        return list(self._paths)

    @property
    def forwarded(self) -> list[AccessPath]:
        """The paths this robot has announced to its neighbours (the reference: ``()``)."""
        return list(self._forwarded)

    # -- what the table tells the robot -------------------------------------------------
    def critical_robots(self) -> frozenset | None:
        """Robots on every stored path: each one's loss cuts this robot off the reference.

        None without a path. For the base algorithm this is exactly the set of robots
        separating this robot from the reference. Proof sketch: a stored path is a real
        path, so every separator is on it. Conversely let x be on every stored path of u
        but u have a route u = w0, ..., wk = reference avoiding x. w(k-1) stores ``(ref)``,
        so its set is empty; take the last wj whose set contains x. w(j+1) forwarded some
        path q avoiding x (forwarding keeps the shared set of forwarded paths equal to that
        of all stored paths). If wj is not on q, wj stored ``(w(j+1),) + q``, which avoids x;
        if it is, the tail of q after wj is a path wj itself forwarded, and it avoids x.
        Either way x is not in wj's set: contradiction. It holds for any delivery order.
        """
        if not self._paths:
            return frozenset() if self.is_reference else None
        return frozenset.intersection(*(interior(p) for p in self._paths))

    def is_doubly_connected(self) -> bool:
        """Two internally disjoint paths to the reference (Ahmadi & Stone Definition 3).

        True iff at least two paths are stored and no robot is on all of them.
        """
        return not self.is_reference and len(self._paths) >= 2 and not self.critical_robots()

    def last_hops(self) -> frozenset:
        """The reference's neighbours through which stored paths enter the reference.

        All of them are connected to this robot without the reference; the check merges
        these sets over all robots to find whether the reference is a cut robot.
        """
        return frozenset(p[-2] if len(p) > 1 else self.robot_id for p in self._paths)

    # -- one tick ---------------------------------------------------------------------
    def tick(
        self, now: int, inbox: Iterable[Message], neighbors: Iterable[Hashable]
    ) -> list[Message]:
        """Handle neighbour changes and this tick's messages; return what to transmit."""
        neighbors = frozenset(neighbors)
        out: list[Message] = []
        if self._neighbors is None:
            self._neighbors = neighbors
            if self.is_reference:
                self._forward((), out)
        else:
            lost, met = self._neighbors - neighbors, neighbors - self._neighbors
            self._neighbors = neighbors
            for a in _canonical(lost):
                broken = LinkBroken(self.robot_id, a, now)
                self._drop_link(broken)
                out.append(Message(broken))
                self._reoffer(out)
            for b in _canonical(met):
                entries = tuple((p, self._times(p)) for p in self._forwarded)
                out.append(Message(TableExchange(entries), to=b))
        for message in inbox:
            payload = message.payload
            if isinstance(payload, NewAccessPath):
                self._new_access_path(message.sender, payload, now, out)
            elif isinstance(payload, TableExchange):
                for path, times in payload.entries:
                    self._new_access_path(message.sender, NewAccessPath(path, times), now, out)
            elif isinstance(payload, LinkBroken) and self._drop_link(payload):
                out.append(Message(payload))  # deleted something: pass the news on
                self._reoffer(out)
        return out

    def _new_access_path(
        self, sender: Hashable, message: NewAccessPath, now: int, out: list[Message]
    ) -> None:
        """Algorithm 1: drop loops, store ``(sender,) + path``, forward if the rule says so.

        A path already stored keeps the newer of its hop times; if that changes a path
        this robot forwarded, it re-announces it so its neighbours' copies are fresh too.
        """
        path = message.path
        if self.is_reference or self.robot_id in path or sender not in (self._neighbors or ()):
            return
        p, times = (sender, *path), (now, *message.times)
        known = self._paths.get(p)
        if known is not None:
            fresher = tuple(map(max, known, times))
            if fresher != known:
                self._paths[p] = fresher
                if p in self._forwarded:
                    out.append(Message(NewAccessPath(p, fresher)))
            return
        self._paths[p] = times
        if self._accepts(p):
            self._forward(p, out)

    def _accepts(self, p: AccessPath) -> bool:
        """The forwarding rule: p shrinks the set shared by all forwarded paths."""
        k = len(self._forwarded)
        if self.max_forwards is not None and k >= self.max_forwards:
            return False
        if k == 0:
            return True
        remaining = self._shared & interior(p)
        if remaining == self._shared:
            return False
        return not remaining if self.max_forwards is not None and k == self.max_forwards - 1 else True

    def _forward(self, p: AccessPath, out: list[Message]) -> None:
        self._shared = interior(p) if not self._forwarded else self._shared & interior(p)
        self._forwarded[p] = None
        out.append(Message(NewAccessPath(p, self._times(p))))

    def _times(self, p: AccessPath) -> tuple[int, ...]:
        """Hop times of a stored path (the reference's ``()`` has none)."""
        return self._paths.get(p, ())

    def _drop_link(self, link: LinkBroken) -> bool:
        """Delete the stored paths that crossed ``link`` before it broke; True if any."""
        gone = [p for p, t in self._paths.items() if crossed_before(self.robot_id, p, t, link)]
        for p in gone:
            del self._paths[p]
            self._forwarded.pop(p, None)
        if gone:
            kept = [interior(p) for p in self._forwarded]
            self._shared = frozenset.intersection(*kept) if kept else frozenset()
        return bool(gone)

    def _reoffer(self, out: list[Message]) -> None:
        """After deletions, forward stored paths the rule now accepts (oldest first)."""
        for p in list(self._paths):
            if p not in self._forwarded and self._accepts(p):
                self._forward(p, out)


class Report(NamedTuple):
    """What a robot's subtree tells its parent in the check the tables give.

    Fields: ``robots`` in the subtree; ``doubly_connected``: all of them have two
    internally disjoint access paths; ``critical``: union of their critical robots;
    ``groups``: the reference's neighbours, grouped by connection avoiding the reference.
    """

    robots: int
    doubly_connected: bool
    critical: frozenset
    groups: tuple[frozenset, ...]


def merge_groups(groups: Iterable[frozenset]) -> tuple[frozenset, ...]:
    """Merge overlapping sets until the sets are disjoint (connected components)."""
    merged: list[set] = []
    for g in groups:
        hits = [m for m in merged if not m.isdisjoint(g)]
        union = set(g).union(*hits)
        merged = [m for m in merged if m.isdisjoint(g)] + [union]
    return tuple(frozenset(m) for m in merged)


def _combine(reports: Iterable[Report]) -> Report:
    reports = list(reports)
    return Report(
        robots=sum(r.robots for r in reports),
        doubly_connected=all(r.doubly_connected for r in reports),
        critical=frozenset().union(*(r.critical for r in reports)),
        groups=merge_groups(g for r in reports for g in r.groups),
    )


class TableCheck:
    """The biconnectivity check the tables give, gathered at the reference robot.

    Le et al. calls the team biconnected when every robot has two internally disjoint
    access paths; that alone misses a reference that is itself a cut robot (Ahmadi & Stone,
    Figure 1), so the check adds: the reference's neighbours are all connected without
    the reference (the merged :meth:`ConnectivityTable.last_hops`). The paper does not say
    how robots learn the team's verdict; we gather it up the tree of first access paths
    (each robot's oldest path's access robot is its parent), timed like Ahmadi & Stone: tables
    are complete after N - 1 ticks, a robot at depth h (length of its first path) reports
    at tick 2N - 1 - h, and the reference decides at tick 2N - 1 (ticks counted from each
    robot's first tick; all robots start together). That adds n - 1 messages. One object
    gathers once: the tables keep updating afterwards, the verdict does not.

    Verdicts on the reference: :attr:`connected` (all n robots reported), :attr:`biconnected`
    and :attr:`articulation_points` (of the reference's component: critical robots, plus
    the reference if its neighbours fall in two or more groups). Exact for the base table;
    for the forward-two variant "biconnected" is never wrongly true and articulation points
    are a superset.
    """

    def __init__(
        self,
        robot_id: Hashable,
        reference: Hashable,
        team_size: int,
        *,
        max_robots: int | None = None,
        max_forwards: int | None = None,
    ) -> None:
        self.table = ConnectivityTable(robot_id, reference, max_forwards=max_forwards)
        self.team_size = team_size
        self.max_robots = team_size if max_robots is None else max_robots
        if self.max_robots < team_size:
            raise ValueError(f"N = {self.max_robots} is below the team size {team_size}")
        self.connected: bool | None = None
        self.biconnected: bool | None = None
        self.articulation_points: frozenset | None = None
        self.decided_at: int | None = None
        self._gathered: list[Report] = []
        self._reported = False
        self._start: int | None = None

    @property
    def decision_tick(self) -> int:
        """2N - 1: ticks after its first tick at which the reference decides."""
        return 2 * self.max_robots - 1

    def tick(
        self, now: int, inbox: Iterable[Message], neighbors: Iterable[Hashable]
    ) -> list[Message]:
        """Keep the table up to date; report (or, at the reference, decide) on time."""
        if self._start is None:
            self._start = now
        inbox = list(inbox)
        self._gathered += [m.payload for m in inbox if isinstance(m.payload, Report)]
        out = self.table.tick(
            now, [m for m in inbox if not isinstance(m.payload, Report)], neighbors
        )
        table, elapsed = self.table, now - self._start
        if table.is_reference:
            if self.decided_at is None and elapsed >= self.decision_tick:
                self._decide(now)
        elif not self._reported and table.paths:
            first = table.paths[0]
            if elapsed >= self.decision_tick - len(first):
                out.append(Message(self._subtree_report(), to=first[0]))
                self._reported = True
        return out

    def _subtree_report(self) -> Report:
        table = self.table
        own = Report(
            robots=1,
            doubly_connected=table.is_doubly_connected(),
            critical=table.critical_robots() or frozenset(),
            groups=(table.last_hops(),),
        )
        return _combine([own, *self._gathered])

    def _decide(self, now: int) -> None:
        team = _combine(self._gathered)
        self.connected = team.robots + 1 == self.team_size
        self.biconnected = self.connected and team.doubly_connected and len(team.groups) == 1
        cut_reference = {self.table.reference} if len(team.groups) > 1 else set()
        self.articulation_points = team.critical | cut_reference
        self.decided_at = now
