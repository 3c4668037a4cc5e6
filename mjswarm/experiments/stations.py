"""Vertex stations: who may enter which vertex area (embodied exploration's vertex entry).

Nagavarapu et al.'s robots kept apart on edges with the bearing-rate rule and spent only a moment
at a vertex; ours scan there for about ten seconds, and a robot's sidesteps between the
vertex centre and its lane cross the lanes of the other edges at that vertex. So a vertex
area holds one robot at a time, and each vertex has a *station* (the paper's central
station, which knew its own vertices, emulated the beacons; ours also grants entry) that
decides who that is. The protocol, per robot:

1. A robot that has decided, on a vertex centre ``u``, to leave along the edge at angle
   ``a`` tells ``u``'s station so (it names the edge by its angle, in the common frame of
   the beacons); the station knows its own edges and asks the station of the far end
   ``w`` for entry on the robot's behalf (:meth:`VertexStations.request`).
2. The robot waits on ``u``'s centre until ``w`` is granted, then leaves. It holds ``w``
   from the grant and ``u`` until it is in the corridor of its edge (has seen its left
   wall): then it is clear of ``u``'s area (:meth:`VertexStations.release`).
3. A robot that stops for good (lost, failed) releases everything it holds.

**No circular wait.** A robot waits only on a vertex centre, never on a lane, so the
only waits are "robot at ``u`` wants ``w``, whose holder stands on ``w``'s centre and
wants ``x``, ...". Such a chain that closes (robots on the centres of a cycle of
vertices, each wanting the next: at least two, e.g. two robots swapping the ends of an
edge) is granted as a whole: every robot in it gets its next vertex and leaves at once; each
usually arrives after the previous holder has left (leaving takes a turn and a
sidestep; arriving, a whole edge), and otherwise waits where its lane's wall ends, clear
of the vertex area, until that robot is in its corridor (:mod:`mjswarm.experiments.exploration`). Robots never wait behind one another on a lane
either: a lane leads to one vertex, held by the one robot on it. Asking for the vertex
ahead from the lane would deadlock: a robot stopped by the speed rule just after
leaving (still holding its vertex) behind a robot waiting on the lane for a vertex whose
holder was stopped the same way closes a cycle (four robots on one edge of
``lattice:10x10``).

**Robots that turn back** (rule 6's relays, ours) ask for the vertex behind them from a
lane (``at`` None) and wait where that lane's wall ends. Such a robot holds nothing (it
gave up the vertex ahead when it turned, and the one behind when it reached its
corridor), so no chain of station waits closes through it; the chains above are
unchanged. One wait is not the stations': a robot that asked from its corridor, not yet
turned (too near the vertex behind for a U-turn), still stands on the lane that leads
away from that vertex, and a robot leaving that vertex along the same edge is stopped
behind it by the speed rule while it holds the vertex the first one waits for. That
deadlock is not broken here; the team's stall verdict ends such a run.

A wait that closes through the speed rule (the dense-team grid, ``python -m
mjswarm.experiments.stress --dense``; ``lattice:6x6``, 8 robots, 0.15 m/s, seed 1 stalls
without the creep): R4, on its lane from ``v4_2`` to ``v4_3`` (holding ``v4_3``, still
leaving ``v4_2``), is held still by the speed rule for R5, which stands on the centre of
``v4_4``, the vertex beyond, and waits for ``v4_3``; R3 waits where its lane's wall ends
for ``v4_2`` to be clear, and five more robots wait on centres for vertices those hold.
Bearings carry no range: R5 stands 2.5 degrees off R4's estimate of its lane, inside the
rule's 2.6 degree cone. The stations cannot see that
wait; the robot breaks it (:meth:`~algorithms.exploration.explorer.Explorer._creep`: a
robot held still on its lane for 5 s creeps on, guarded by its front IR, since vertex
entry leaves nobody else on its lane).

**Closed vertices** (ours: a body that cannot be passed). A robot that stops
for good (a fault switches it off, it halts, or it is cut off from the root with its part
finished) with its body in a vertex area, or in the stretch of its corridor still shared
with the vertex's other edges (:func:`~mjswarm.arena.geometry.junction_depths`: edges
less than about 84 degrees apart), keeps that vertex held for ever: the vertex is *closed* (:meth:`StationService._release`; the station
learns it from the switch-off here, a real one would from a body in its area that has
gone silent). Its station then answers every request for it with
:class:`~algorithms.exploration.entry.EntryBlocked` instead of a grant: the requests in
its queue at once, new ones when they come; the robot marks the edge blocked and decides
anew. A robot granted the vertex before it closed (in a closed chain of waits, while the
body was still leaving it) is on its way and waits, out of the area, for a
:class:`~algorithms.exploration.entry.VertexClear` that will never come; the station
answers it with ``EntryBlocked`` once it sees it clear of every vertex area, and it walks
back to the vertex it left, asking for it as rule 6's relays do (:class:`~algorithms.
exploration.entry.TurnedBack`); a tethered robot stops for good where it stands, on a
lane that leads only into the closed vertex (so it blocks nobody). :attr:`StationService.closed` says which vertices closed, by whose body, and
when (ground truth, for the result's unreachable edges).

Grants go in the order of the requests (then robot index), so a waiting robot is served
before later ones. A robot may give up its place (:class:`~algorithms.exploration.entry.
GiveUp`, step 8 of the protocol): a request still waiting is dropped and answered with
:class:`~algorithms.exploration.entry.EntryBusy`; one already granted stands. Ground truth used here, as the paper's station had it: the arena's
edges at each vertex (:func:`mjswarm.arena.geometry.vertex_fans`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from algorithms.exploration.entry import (
    EntryBlocked,
    EntryBusy,
    EntryDenied,
    EntryGranted,
    EntryRequest,
    GiveUp,
    Halted,
    LeftVertex,
    PassDone,
    PassGranted,
    PassRequest,
    TurnedBack,
    VertexClear,
    Withdraw,
)
from algorithms.exploration.events import VertexCalled
from mjswarm.arena import ArenaSpec
from mjswarm.arena.geometry import VERTEX_CLEAR_RADIUS_M, junction_depths, vertex_fans
from mjswarm.worlds.loop import Loop, LoopFunctions

#: A robot is on a vertex when within this distance of its centre (m).
ON_VERTEX_M = 0.05
#: The stations map a robot's departure angle to an edge only within this (rad): half
#: the 45 degree minimum angle between edges at a vertex.
DEPARTURE_TOLERANCE_RAD = math.radians(22.5)


@dataclass(frozen=True)
class Request:
    """Robot waiting on the centre of ``at`` (None: on a lane, turned back) to go to ``to``
    (requested at ``since_s``)."""

    at: str | None
    to: str
    since_s: float


class VertexStations:
    """The stations of every vertex of ``spec``: holds, requests, grants."""

    def __init__(self, spec: ArenaSpec) -> None:
        self._fans = vertex_fans(spec)
        self.holder: dict[str, int] = {}
        self.requests: dict[int, Request] = {}
        #: lanes held for a pass (:mod:`algorithms.exploration.entry`, step 6): robot ->
        #: (from, to), the lane's ends in its direction of travel; nobody is granted ``to``
        #: from ``from`` meanwhile
        self.passes: dict[int, tuple[str, str]] = {}

    def edge_towards(self, vertex: str, angle: float) -> tuple[str, float]:
        """The neighbour of ``vertex`` along the edge nearest to ``angle`` (rad, common
        frame) and how far (rad) that edge's true angle is from it."""
        true, neighbour = min(
            self._fans[vertex], key=lambda an: abs(math.remainder(an[0] - angle, 2 * math.pi)))
        return neighbour, abs(math.remainder(true - angle, 2 * math.pi))

    def occupy(self, robot: int, vertex: str) -> None:
        """``robot`` was put on ``vertex`` (a launch): it holds it."""
        self.holder[vertex] = robot

    def request(self, robot: int, at: str | None, to: str, now_s: float) -> None:
        """``robot``, on the centre of ``at`` (None: on a lane), wants to go to ``to``."""
        self.requests[robot] = Request(at, to, now_s)

    def withdraw(self, robot: int) -> None:
        """``robot`` no longer asks (no effect once granted)."""
        self.requests.pop(robot, None)

    def grant(self) -> list[tuple[int, str]]:
        """Grant what can be granted now; returns ``(robot, vertex)`` pairs, in order."""
        granted = []
        for robot in self._queue():
            to = self.requests[robot].to
            if to not in self.holder and not self._on_held_lane(robot):
                granted.append((robot, to))
                self._give(robot)
        for robot in self._queue():
            if robot in self.requests:  # not granted as part of an earlier cycle
                cycle = self._cycle_from(robot)
                granted += [(r, self.requests[r].to) for r in cycle]
                for r in cycle:
                    self._give(r)
        return granted

    def release(self, robot: int, vertex: str | None) -> None:
        """``robot`` is clear of ``vertex`` (no effect if someone else holds it now)."""
        if vertex is not None and self.holder.get(vertex) == robot:
            del self.holder[vertex]

    def release_all(self, robot: int) -> list[str]:
        """``robot`` stopped for good: drop its request and every hold; returns the vertices."""
        self.requests.pop(robot, None)
        self.passes.pop(robot, None)
        held = [v for v, r in self.holder.items() if r == robot]
        for v in held:
            del self.holder[v]
        return held

    def _on_held_lane(self, robot: int) -> bool:
        """Whether ``robot``'s request would take it along a lane held for a pass."""
        request = self.requests[robot]
        return (request.at, request.to) in self.passes.values()

    def _queue(self) -> list[int]:
        return sorted(self.requests, key=lambda r: (self.requests[r].since_s, r))

    def _give(self, robot: int) -> None:
        self.holder[self.requests.pop(robot).to] = robot

    def _cycle_from(self, robot: int) -> list[int]:
        """The robots of a closed chain of waits through ``robot`` (empty if none):
        each stands on the centre of the vertex the previous one wants."""
        chain = [robot]
        while True:
            wanted = self.requests[chain[-1]].to
            holder = self.holder.get(wanted)
            request = self.requests.get(holder) if holder is not None else None
            if request is None or request.at != wanted:
                return []  # the holder is not waiting on that centre: it will move on
            if self._on_held_lane(chain[-1]):
                return []  # it waits for a pass (which waits for no grant)
            if holder == robot:
                return chain
            if holder in chain:
                return []  # a cycle that does not pass through ``robot``
            chain.append(holder)


#: Robot-by-vertex distances from which :class:`NearestVertex` asks a k-d tree: below, the
#: whole matrix costs less than the tree's query (the main job's 4 robots by 10 vertices:
#: about 4 us against 14 us a state).
NEAREST_TREE_FROM = 4096


class NearestVertex:
    """Which vertex each robot of ``sim`` is nearest to, and how far (m): what the
    stations see. Worked out once per world state, for every robot on the floor at once
    (``present``, the world's live mask; robots waiting in the depot are asked about
    one by one, if ever), by a k-d tree over the vertices (a robot-by-vertex distance
    matrix took 5.3 of 9.4 s of a 1000-robot ``lattice:30x30`` run's first 20 s;
    ``tree.query`` is ``O(N log V)``), or by the whole matrix below ``NEAREST_TREE_FROM``
    robot-vertex pairs (the same vertices: a robot exactly halfway between two is the
    only case the two could answer apart)."""

    def __init__(self, sim, spec: ArenaSpec, present: np.ndarray | None = None) -> None:
        self.sim = sim
        self._xy = np.array(list(spec.vertices.values()))
        self._tree = (cKDTree(self._xy) if sim.n * len(self._xy) >= NEAREST_TREE_FROM
                      else None)
        self._ids = list(spec.vertices)
        self._present = np.ones(sim.n, bool) if present is None else present
        self._version = -1
        self._nearest: list = []
        self._distance: list = []

    def __call__(self, i: int) -> tuple[str, float]:
        sim = self.sim
        if self._version != sim.state_version:
            rows = np.flatnonzero(self._present)
            nearest, distance = np.zeros(sim.n, np.intp), np.full(sim.n, np.nan)
            nearest[rows], distance[rows] = self._find(sim.poses()[rows, :2])
            self._nearest, self._distance = nearest.tolist(), distance.tolist()
            self._version = sim.state_version
        if not self._present[i]:  # in the depot: asked alone
            (v,), (d,) = self._find(sim.poses()[i:i + 1, :2])
            return self._ids[v], float(d)
        return self._ids[self._nearest[i]], self._distance[i]

    def _find(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The nearest vertex of each point ``xy`` (m), by index, and its distance (m)."""
        if self._tree is not None:
            nearest = self._tree.query(xy)[1]
        else:
            gap = xy[:, None, :] - self._xy[None, :, :]
            nearest = np.einsum("nvk,nvk->nv", gap, gap).argmin(axis=1)
        v = self._xy[nearest]
        return nearest, np.hypot(xy[:, 0] - v[:, 0], xy[:, 1] - v[:, 1])


class StationService(LoopFunctions):
    """The vertex stations as a loop function: the beacon service (which vertex's beacon a
    robot may read now) and the entry protocol (:mod:`algorithms.exploration.entry`)
    over ``uplink``. ``avoid``: vertex entry is on (else a robot's vertex is the one its
    decision leads to, and any robot on a centre reads its beacon)."""

    def __init__(self, spec: ArenaSpec, world, uplink, nearest: NearestVertex,
                 avoid: bool) -> None:
        self.spec, self.world, self.uplink = spec, world, uplink
        self.fans, self.junctions = vertex_fans(spec), junction_depths(spec)
        self.nearest, self.avoid = nearest, avoid
        self.stations = VertexStations(spec)
        k = world.n
        #: each robot's vertex: the one it stands on or was granted; the one it is leaving
        self.target: list[str | None] = [None] * k
        self.leaving: list[str | None] = [None] * k
        #: the vertex each robot last asked to leave (where a walk back takes it), and
        #: the angle it asked for
        self.came_from: list[str | None] = [None] * k
        self.asked: list[float | None] = [None] * k
        #: robots granted a vertex whose previous holder has not yet left it
        self.awaiting_clear: set[int] = set()
        #: robots that asked to pass a body and have not yet been told to
        self.pass_waiting: set[int] = set()
        #: closed vertices (module docstring): vertex -> (robot whose body closed it, time s)
        self.closed: dict[str, tuple[int, float]] = {}
        #: robots on their way to a vertex that closed, to be told once out of every area
        self.blocked_on_way: set[int] = set()
        #: requests dropped because their robot gave up its place in a queue
        self.gave_up = 0
        self.loop: Loop | None = None

    def initialize(self, loop: Loop) -> None:
        self.loop = loop

    def _switched_off(self, i: int, reason: str) -> None:
        if self.world.present[i]:  # one still in the depot holds nothing
            self._release(i)

    # ------------------------------------------------------------------ beacons
    def beacon_at(self, i: int) -> str | None:
        """The vertex whose beacon robot ``i`` may read now: the one whose centre it
        stands on, if the station there granted it that vertex (or launched it there), or
        has granted it the next one and not yet seen it leave."""
        vertex, distance = self.nearest(i)
        if distance >= ON_VERTEX_M:
            return None
        if self.avoid and vertex != self.target[i] and vertex != self.leaving[i]:
            return None
        return vertex

    # ------------------------------------------------------------------ hooks
    def launched(self, i: int, vertex: str) -> None:
        """Robot ``i`` was put on ``vertex``'s centre: it holds it."""
        if self.avoid:
            self.stations.occupy(i, vertex)
        self.target[i] = vertex

    def before_step(self, loop: Loop) -> None:
        """The stations' mail, then their grants."""
        for message in self.uplink.receive():
            self._receive(message.sender, message.payload)
        if not self.avoid:
            return
        for j in sorted(self.blocked_on_way):  # out of every vertex area: told now
            if self.nearest(j)[1] >= VERTEX_CLEAR_RADIUS_M:
                self.blocked_on_way.discard(j)
                self.uplink.reply(j, EntryBlocked(self.asked[j]))
        granted = self.stations.grant()
        for i, vertex in granted:  # a cycle's grants all take effect at once ...
            self.leaving[i], self.target[i] = self.target[i], vertex
        for i, vertex in granted:  # ... before anyone is told whether its vertex is clear
            clear = not any(v == vertex for j, v in enumerate(self.leaving) if j != i)
            if not clear:
                self.awaiting_clear.add(i)
            self.uplink.reply(i, EntryGranted(clear, self.asked[i]))
            loop.event(f"R{i + 1} granted {vertex}", i)
        for i in sorted(self.pass_waiting):
            if not self._on_the_way(*self.stations.passes[i]):
                self.pass_waiting.discard(i)
                self.uplink.reply(i, PassGranted())
                loop.event(f"R{i + 1} passes a body", i)

    def after_step(self, loop: Loop) -> None:
        """Without vertex entry, a robot's vertex is the one its decision leads to."""
        if self.avoid:
            return
        for i, event in loop.reports:
            if type(event) is VertexCalled and event.action == "go":
                vertex = self.nearest(i)[0]
                self.target[i] = self.stations.edge_towards(vertex, event.angle_rad)[0]

    # ------------------------------------------------------------------ protocol
    def _receive(self, i: int, payload) -> None:
        if isinstance(payload, EntryRequest):
            self._request(i, payload)
        elif isinstance(payload, TurnedBack):
            self._turned_back(i, payload.from_lane)
        elif isinstance(payload, Withdraw):
            self._withdraw(i)
        elif isinstance(payload, GiveUp):
            # still waiting: dropped and told; granted: the grant on its way stands
            if i in self.stations.requests:
                self.stations.withdraw(i)
                self.uplink.reply(i, EntryBusy(self.asked[i]))
                self.gave_up += 1
        elif isinstance(payload, LeftVertex):
            left, self.leaving[i] = self.leaving[i], None
            self.stations.release(i, left)
            self._tell_clear()
        elif isinstance(payload, Halted):
            self._release(i)
        elif isinstance(payload, PassRequest):
            # the opposite lane leads from the vertex ahead back to the one it left
            self.stations.passes[i] = (self.target[i], self.came_from[i])
            self.pass_waiting.add(i)
        elif isinstance(payload, PassDone):
            self.stations.passes.pop(i, None)
            self.pass_waiting.discard(i)

    def _on_the_way(self, start: str, end: str) -> bool:
        """Whether some robot is on the lane from ``start`` to ``end``: it was granted
        ``end`` leaving ``start`` and is not yet in ``end``'s area, as that station sees
        (one switched off on the lane stays there: a pass beside it waits for good)."""
        for j in range(self.world.n):
            if self.came_from[j] == start and self.target[j] == end:
                vertex, distance = self.nearest(j)
                if vertex != end or distance >= VERTEX_CLEAR_RADIUS_M:
                    return True
        return False

    def _request(self, i: int, payload: EntryRequest) -> None:
        vertex = self.target[i]
        ahead, off = self.stations.edge_towards(vertex, payload.angle_rad)
        if off > DEPARTURE_TOLERANCE_RAD:  # the denial names no vertex: robots know none
            self.uplink.reply(i, EntryDenied(
                f"its departure angle is {math.degrees(off):.0f} deg from every edge at "
                "its vertex"))
            return
        self.came_from[i], self.asked[i] = vertex, payload.angle_rad
        if payload.part_way:  # a relay's last leg: onto the lane, not into ``ahead``
            self.leaving[i], self.target[i] = vertex, None
            self.uplink.reply(i, EntryGranted(False, payload.angle_rad))
            return
        if ahead in self.closed:  # it stays on its centre and decides anew
            self.uplink.reply(i, EntryBlocked(payload.angle_rad))
            return
        self.stations.request(i, vertex, ahead, self.world.time_s)

    def _withdraw(self, i: int) -> None:
        """Robot ``i``, still on its vertex centre, drops its request or gives its grant
        back (:mod:`algorithms.exploration.entry`, step 5). If its vertex went to another
        robot in a swap, that robot still waits until this one has left the area."""
        self.stations.withdraw(i)
        here = self.leaving[i]
        if here is None:
            return  # not granted yet
        self.stations.release(i, self.target[i])
        self.awaiting_clear.discard(i)
        self.target[i] = here
        if self.stations.holder.get(here) == i:
            self.leaving[i] = None
        self._tell_clear()

    def _turned_back(self, i: int, from_lane: bool) -> None:
        """Robot ``i`` walks back along its edge (:mod:`algorithms.exploration.entry`, step
        5): short of its corridor it gets the vertex behind back at once, unless the
        station gave it to another robot (a swap: no answer, and it goes on; if that robot
        has stopped for good since, the vertex is free and its own again); else it asks
        for it as from a centre, and the grant tells it when it may turn, or enter."""
        back = self.came_from[i]
        holder = self.stations.holder.get(back)
        if not from_lane and self.leaving[i] == back and holder not in (None, i):
            return
        self.awaiting_clear.discard(i)
        self.stations.release(i, self.target[i])
        if self.leaving[i] == back:  # it had not left that area: it is its own again
            self.stations.occupy(i, back)
            self.leaving[i], self.target[i] = None, back
            self.uplink.reply(i, EntryGranted(clear=True))
        else:  # from its lane, or its corridor: as a request from a centre
            self.target[i], self.asked[i] = None, None  # the grant answers no EntryRequest
            self.stations.request(i, None, back, self.world.time_s)
        self._tell_clear()

    def _release(self, i: int) -> None:
        """Robot ``i`` stopped for good (or was switched off): its holds go; a station
        whose vertex area the body still occupies keeps the vertex closed (it sees the
        body, as it sees who stands on its centre) and blocks the robots that want it
        (:meth:`_close`)."""
        self.stations.release_all(i)
        self.blocked_on_way.discard(i)
        vertex, distance = self.nearest(i)
        self.leaving[i] = None
        self.awaiting_clear.discard(i)
        self.pass_waiting.discard(i)
        if distance < VERTEX_CLEAR_RADIUS_M or distance < self._junction_depth(i, vertex):
            self.stations.occupy(i, vertex)
            self._close(vertex, i)
        self._tell_clear()

    def _junction_depth(self, i: int, vertex: str) -> float:
        """How far from ``vertex``'s centre the corridor robot ``i`` stands in is still
        shared with the vertex's other edges (m; :func:`~mjswarm.arena.geometry.
        junction_depths`): beyond the vertex area where edges meet at less than about
        84 degrees. A body there blocks robots turning in and out of those edges too, and
        cannot be passed, so it closes the vertex as one in its area does."""
        x, y = self.world.true_poses()[i, :2] - self.spec.vertices[vertex]
        heading = math.atan2(y, x)
        _, towards = min(self.fans[vertex], key=lambda fan: abs(
            math.remainder(fan[0] - heading, 2 * math.pi)))
        return self.junctions[(vertex, towards)]

    def _close(self, vertex: str, body: int) -> None:
        """``vertex`` is closed by robot ``body``'s body (module docstring): the requests
        for it waiting on centres are answered with ``EntryBlocked`` now; robots on their
        way to it (granted, or walking back to it from a lane) once out of every area."""
        self.closed.setdefault(vertex, (body, self.world.time_s))
        for j, request in sorted(self.stations.requests.items()):
            if request.to == vertex:
                self.stations.withdraw(j)
                if request.at is not None:
                    self.uplink.reply(j, EntryBlocked(self.asked[j]))
                else:
                    self.blocked_on_way.add(j)
        for j in range(len(self.target)):
            if j != body and self.target[j] == vertex and self.world.present[j]:
                self.awaiting_clear.discard(j)
                self.blocked_on_way.add(j)

    def _tell_clear(self) -> None:
        """Tell the robots waiting for a vertex whose previous holder has now left it."""
        for j in sorted(self.awaiting_clear):
            if self.target[j] not in self.leaving:
                self.awaiting_clear.discard(j)
                self.uplink.reply(j, VertexClear())
