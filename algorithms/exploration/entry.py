"""Vertex entry: the messages between a robot and the vertex stations.

Nagavarapu et al. emulated beacons with a central station over XBee that kept "separate
information for each vertex"; ours also decides who may enter which vertex area (one
robot per area; below, why no circular wait forms). Robots
reach the stations from anywhere (the station's XBee link), one control tick each way,
and every message is counted with the radio's. The protocol, from the robot's side:

1. On a vertex centre, having decided to leave along the edge at incidence angle ``a``
   (the common frame of the beacons), the robot sends :class:`EntryRequest` ``(a)`` to
   :data:`STATION`. It names the edge by what it knows; the station knows which vertex
   the robot holds (it granted it, or launched the robot there) and its own edges, so it
   finds the vertex ``w`` at the far end.
2. The station answers :class:`EntryGranted` once ``w`` is free (``clear`` False when
   ``w`` was granted with a closed chain of waits and its previous holder has not yet
   left its area; a :class:`VertexClear` follows when it has), or :class:`EntryDenied`
   when no edge lies within tolerance of ``a`` (the robot's frame is broken).
3. The robot leaves; once in its corridor (its left wall seen) it sends
   :class:`LeftVertex`: the station frees the vertex it left. Until ``w`` is clear it
   waits where its lane's wall ends, out of ``w``'s area.
4. A robot that stops for good sends :class:`Halted`: the station drops its request and
   holds (a body left in a vertex area keeps that vertex closed: the station sees it).
   So does a robot cut off from the root that finished its part (``CUT_OFF``): it
   stands on its vertex's centre for good, and a robot of its component that still
   wants that vertex is answered as for any closed vertex (step 7), instead of waiting
   for ever.
5. Relays (rule 6 of :mod:`algorithms.exploration.relay`, ours). A relay's last leg ends
   part-way, where its requester is: its :class:`EntryRequest` says so (``part_way``),
   and the station lets it onto the lane at once without giving it the vertex ahead
   (:class:`EntryGranted` with ``clear`` False: it never enters that area). A robot that
   must walk back sends :class:`TurnedBack`, and the station frees the vertex ahead. Near
   the vertex behind (``from_lane`` False: short of its corridor, or too near for a
   U-turn clear of that area) it asks to return there and turns once it has the grant:
   at once if it never left that area, and no answer if the station gave it to another
   robot meanwhile (a swap: it goes on, and turns farther along; a robot whose way on a
   wall closed says so in a second :class:`TurnedBack`, ``way_on_closed``, and if the
   other robot still waits on its lane for the vertex to clear, the swap is undone: its
   grant becomes a request from its lane again, and the vertex goes back to the robot
   that stands in its area, which could otherwise neither go on nor back); else when
   the vertex is free. Turned on its lane (``from_lane`` True, sent once it follows its
   new lane, out of the area ahead), it waits for the vertex behind where its new lane's
   wall ends; both wait as a request from a centre does. A robot granted a clear vertex
   while it must hold (rule 2 of the tether: it was adopted while it waited) sends
   :class:`Withdraw`: the station takes the grant back, and the robot asks again once it
   may move (rule 2), so that it does not keep two vertex areas while it stands in one
   (a robot granted a vertex not yet clear keeps it: a swap needs it to leave as soon as
   it may). A robot that sets out as a relay from a centre where it waits for a grant
   withdraws too, then asks for the way its mission takes. A grant names the request's angle, so that one
   overtaken by a withdrawal is known as such. A withdrawn swap leaves the other robot
   waiting, as before, until this one has left the vertex area it was given.
6. Passing a body that stands on a lane for good has its own protocol
   (:mod:`algorithms.exploration.passing`); a lane held for a pass is granted to nobody.
7. Closed vertices (ours: a body that cannot be passed). A vertex whose area holds
   a robot that stopped for good is *closed*: its station answers every request for it
   with :class:`EntryBlocked` instead of a grant, at once for requests waiting in its
   queue and for new ones when they come, naming the request's angle and never the
   vertex (robots know no true ids). A robot granted the vertex before it closed, on its
   way to it (waiting where its lane's wall ends for :class:`VertexClear`, since the
   body's holder never cleared it), gets :class:`EntryBlocked` too, with the angle it
   had asked for; it marks the edge blocked and walks back to the vertex it left, as in
   step 5 (a tethered robot stops for good there instead, out of the vertex area, on a
   lane that leads only into the closed vertex). A robot on a centre that gets it marks
   the edge blocked
   (:meth:`~algorithms.exploration.base.Strategy.block`) and decides anew.

8. Giving up a place in a queue (ours: not in the paper). Robots heading for one frontier queue
   vertex by vertex for grants (each waits on a centre for the vertex whose holder
   waits for the next), and a queue that reaches back to the root stops the launches. A
   robot on a centre whose request has not been granted for ``GIVE_UP_S`` sends
   :class:`GiveUp`. The station drops the request if it is still waiting and answers
   :class:`EntryBusy` with the request's angle; a request already granted stands (the
   grant is on its way and the robot obeys it), so no grant is ever taken back half-way.
   On ``EntryBusy`` the robot asks its strategy to plan again without leaving by that
   edge (:meth:`~algorithms.exploration.base.Strategy.give_up`) and asks for the way the
   new plan takes; only strategies that can plan round an edge give up (the others wait).

**The robot's side** is its explorer's modes (:mod:`algorithms.exploration.modes`):
ASKING and GIVING_UP on a centre (steps 1, 2 and 8), WITHDRAWN (step 5), LEAVING until
it tells the stations it left (step 3), TURN_ASKED and WALKING_BACK_UNTOLD on the way
back (step 5), and the answers that move it between them (EntryGranted, EntryBusy,
EntryBlocked; EntryDenied and a stop for good end in HALTED, step 4).

**The stations' side** is :class:`EntryStations` over :class:`VertexStations`, run by a
loop function that shows them the bodies (:class:`StationSight`;
:mod:`mjswarm.experiments.stations`).

**No circular wait.** A robot waits only on a vertex centre, never on a lane, so the only
waits are "robot at ``u`` wants ``w``, whose holder stands on ``w``'s centre and wants
``x``, ...". Such a chain that closes (robots on the centres of a cycle of vertices, each
wanting the next: at least two, e.g. two robots swapping the ends of an edge) is granted
as a whole: every robot in it gets its next vertex and leaves at once; each usually
arrives after the previous holder has left (leaving takes a turn and a sidestep;
arriving, a whole edge), and otherwise waits where its lane's wall ends, clear of the
vertex area, until that robot is in its corridor. Robots never wait behind one another
on a lane either: a lane leads to one vertex, held by the one robot on it. Asking for
the vertex ahead from the lane would deadlock: a robot stopped by the speed rule just
after leaving (still holding its vertex) behind a robot waiting on the lane for a vertex
whose holder was stopped the same way closes a cycle (four robots on one edge of
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
rule's 2.6 degree cone. The stations cannot see that wait; the robot breaks it
(:meth:`~algorithms.exploration.explorer.Explorer._creep`: a robot held still on its
lane for 5 s creeps on, guarded by its front IR, since vertex entry leaves nobody else
on its lane).

**Closed vertices** (ours: a body that cannot be passed). A robot that stops for good (a
fault switches it off, it halts, or it is cut off from the root with its part finished)
with its body in a vertex area, or in the stretch of its corridor still shared with the
vertex's other edges (:func:`~mjswarm.arena.geometry.junction_depths`: edges less than
about 84 degrees apart), keeps that vertex held for ever: the vertex is *closed*
(:meth:`EntryStations.release`; the station learns it from the switch-off here, a real
one would from a body in its area that has gone silent). Its station then answers every
request for it with :class:`EntryBlocked` instead of a grant: the requests in its queue
at once, new ones when they come; the robot marks the edge blocked and decides anew. A
robot granted the vertex before it closed (in a closed chain of waits, while the body
was still leaving it) is on its way and waits, out of the area, for a
:class:`VertexClear` that will never come; the station answers it with ``EntryBlocked``
once it sees it clear of every vertex area, and it walks back to the vertex it left,
asking for it as rule 6's relays do (:class:`TurnedBack`); a tethered robot stops for
good where it stands, on a lane that leads only into the closed vertex (so it blocks
nobody). :attr:`EntryStations.closed` says which vertices closed, by whose body, and
when (ground truth, for the result's unreachable edges).

Grants go in the order of the requests (then robot index), so a waiting robot is served
before later ones. A robot may give up its place (:class:`GiveUp`, step 8 of the
protocol): a request still waiting is dropped and answered with :class:`EntryBusy`; one
already granted stands. What the stations know, as the paper's station did: the edges at
each vertex (``fans``), and what they see of the bodies (:class:`StationSight`).

A station serves the beacon of its vertex only to the robot it granted (or launched
there): a robot that arrives anywhere else finds no beacon and stops.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple, Protocol

from algorithms.exploration.passing import PassDone, PassGranted, PassLanes, PassRequest

#: The address of the vertex stations.
STATION = "station"
#: How long (s of simulated time) a robot waits on a centre for a grant before it gives
#: up its place (step 8): twice the longest wait measured in a run without a long queue.
#: Waits from a centre to its grant (``python benchmarks/grant_waits.py EXPLORE-ARGS``):
#: the main job (arena2, 4 robots) 0-26 s; a dense team (lattice:6x6, 8 robots, 0.15 m/s,
#: seed 1) median 0, 99th percentile 44 s, longest 58 s; in a long queue (lattice:12x12,
#: 120 robots, 0.15 m/s, kinematic) robots that never gave up would wait for minutes.
#: Queues form in small teams too, behind a hub: some of the stress grid's runs give up
#: places (``python -m mjswarm.experiments.stress``; wheel:8 most), and every run passes
#: (``docs/exploration.md``).
GIVE_UP_S = 120.0
#: The stations map a robot's departure angle to an edge only within this (rad): half
#: the 45 degree minimum angle between edges at a vertex.
DEPARTURE_TOLERANCE_RAD = math.radians(22.5)


class EntryRequest(NamedTuple):
    """Robot → station: let me leave my vertex along the edge at ``angle_rad``
    (``part_way``: only onto its lane, not into the vertex at the far end)."""

    angle_rad: float
    part_way: bool = False


class Withdraw(NamedTuple):
    """Robot → station: drop my request, or take back the vertex you granted me; I have
    not left my vertex."""


class TurnedBack(NamedTuple):
    """Robot → station: I walk back along my edge; free the vertex ahead, give me the one
    I left (``from_lane``: I turned on my lane; else I am still in its area).
    ``way_on_closed``: sent after one without it, nor can I go on (a wall cut my
    parent's link on this way): step 5's swap is undone."""

    from_lane: bool
    way_on_closed: bool = False


class EntryGranted(NamedTuple):
    """Station → robot: go; ``clear`` says whether the vertex ahead is already clear;
    ``angle_rad`` is the request's (None: the vertex it walks back to)."""

    clear: bool
    angle_rad: float | None = None


class EntryDenied(NamedTuple):
    """Station → robot: no edge of the vertex lies along the angle asked for."""

    reason: str


class VertexClear(NamedTuple):
    """Station → robot: the previous holder of the vertex ahead has left its area."""


class LeftVertex(NamedTuple):
    """Robot → station: I am in my corridor; the vertex I left is free."""


class Halted(NamedTuple):
    """Robot → station: I stopped for good (``reason``); release what I hold."""

    reason: str


class GiveUp(NamedTuple):
    """Robot → station: I have waited ``GIVE_UP_S`` for my request; drop it unless it is
    granted (step 8)."""


class EntryBusy(NamedTuple):
    """Station → robot: your request for the edge at ``angle_rad`` was still waiting and
    is dropped (an answer to :class:`GiveUp`, step 8); you have not left."""

    angle_rad: float


class EntryBlocked(NamedTuple):
    """Station → robot: the vertex along the edge at ``angle_rad`` (the request's angle)
    is closed: a body that stopped for good stands in its area (step 7). The station
    learns it from the switch-off in our runs; a real station would from the body's
    silence in its area. The vertex is not named: robots know no true ids."""

    angle_rad: float


# -- the stations' side --------------------------------------------------------------------
class Request(NamedTuple):
    """Robot waiting on the centre of ``at`` (None: on a lane, turned back) to go to ``to``
    (requested at ``since_s``)."""

    at: str | None
    to: str
    since_s: float


class VertexStations:
    """The stations of every vertex: holds, requests, grants, and the lanes held for a
    pass. ``fans``: each vertex's edges as ``(angle rad, neighbour)`` pairs in the
    common frame (what the paper's station knew of its own vertices)."""

    def __init__(self, fans: Mapping[str, Sequence[tuple[float, str]]]) -> None:
        self._fans = fans
        self.holder: dict[str, int] = {}
        self.requests: dict[int, Request] = {}
        #: lanes held for a pass (:mod:`algorithms.exploration.passing`)
        self.lanes = PassLanes()

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
        self.lanes.done(robot)
        held = [v for v, r in self.holder.items() if r == robot]
        for v in held:
            del self.holder[v]
        return held

    def _on_held_lane(self, robot: int) -> bool:
        """Whether ``robot``'s request would take it along a lane held for a pass."""
        request = self.requests[robot]
        return self.lanes.holds(request.at, request.to)

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


class StationSight(Protocol):
    """What the stations see of the robots' bodies (ground truth, as the paper's station
    saw who stood on its vertex): given by the loop function that runs them."""

    def clear_of_areas(self, robot: int) -> bool:
        """Whether ``robot`` is out of every vertex area."""

    def in_area(self, robot: int, vertex: str) -> bool:
        """Whether ``robot`` is in ``vertex``'s area."""

    def body_closes(self, robot: int) -> str | None:
        """The vertex a body stopped for good where ``robot`` stands would close: the one
        whose area it is in, or whose corridor stretch shared with the vertex's other
        edges; None elsewhere."""

    def present(self, robot: int) -> bool:
        """Whether ``robot`` is on the floor (not in the depot)."""


class EntryStations:
    """The stations' side of the protocol (module docstring) for a team of ``n``: their
    mail, grants and answers. ``avoid``: vertex entry is on (else the stations only serve
    beacons). What they send goes to :attr:`outbox`, ``(robot, payload)`` in order, and
    what a log should show to :attr:`notes`, ``(robot, text)``; ``sight`` is what they
    see of the bodies."""

    def __init__(self, fans: Mapping[str, Sequence[tuple[float, str]]], n: int,
                 avoid: bool, sight: StationSight) -> None:
        self.grants = VertexStations(fans)
        self.avoid, self.sight = avoid, sight
        #: each robot's vertex: the one it stands on or was granted; the one it is leaving
        self.target: list[str | None] = [None] * n
        self.leaving: list[str | None] = [None] * n
        #: the vertex each robot last asked to leave (where a walk back takes it), and
        #: the angle it asked for
        self.came_from: list[str | None] = [None] * n
        self.asked: list[float | None] = [None] * n
        #: robots granted a vertex whose previous holder has not yet left it
        self.awaiting_clear: set[int] = set()
        #: closed vertices (step 7): vertex -> (robot whose body closed it, time s)
        self.closed: dict[str, tuple[int, float]] = {}
        #: robots on their way to a vertex that closed, to be told once out of every area
        self.blocked_on_way: set[int] = set()
        #: requests dropped because their robot gave up its place in a queue
        self.gave_up = 0
        self.outbox: list[tuple[int, Any]] = []
        self.notes: list[tuple[int, str]] = []

    def launched(self, i: int, vertex: str) -> None:
        """Robot ``i`` was put on ``vertex``'s centre: it holds it."""
        if self.avoid:
            self.grants.occupy(i, vertex)
        self.target[i] = vertex

    def decided(self, i: int, here: str, angle_rad: float) -> None:
        """Without vertex entry: robot ``i`` on ``here`` decided to leave along
        ``angle_rad``; its vertex is the one that edge leads to."""
        self.target[i] = self.grants.edge_towards(here, angle_rad)[0]

    def serve(self, now_s: float) -> None:
        """After the mail: the blocked told once out of every area, then grants, then
        passes."""
        if not self.avoid:
            return
        for j in sorted(self.blocked_on_way):  # out of every vertex area: told now
            if self.sight.clear_of_areas(j):
                self.blocked_on_way.discard(j)
                self.outbox.append((j, EntryBlocked(self.asked[j])))
        granted = self.grants.grant()
        for i, vertex in granted:  # a cycle's grants all take effect at once ...
            self.leaving[i], self.target[i] = self.target[i], vertex
        for i, vertex in granted:  # ... before anyone is told whether its vertex is clear
            clear = not any(v == vertex for j, v in enumerate(self.leaving) if j != i)
            if not clear:
                self.awaiting_clear.add(i)
            self.outbox.append((i, EntryGranted(clear, self.asked[i])))
            self.notes.append((i, f"R{i + 1} granted {vertex}"))
        for i in self.grants.lanes.ready(self._on_the_way):
            self.outbox.append((i, PassGranted()))
            self.notes.append((i, f"R{i + 1} passes a body"))

    def receive(self, i: int, payload: Any, now_s: float) -> None:
        """One message from robot ``i``."""
        if isinstance(payload, EntryRequest):
            self._request(i, payload, now_s)
        elif isinstance(payload, TurnedBack):
            self._turned_back(i, payload.from_lane, payload.way_on_closed, now_s)
        elif isinstance(payload, Withdraw):
            self._withdraw(i)
        elif isinstance(payload, GiveUp):
            # still waiting: dropped and told; granted: the grant on its way stands
            if i in self.grants.requests:
                self.grants.withdraw(i)
                self.outbox.append((i, EntryBusy(self.asked[i])))
                self.gave_up += 1
        elif isinstance(payload, LeftVertex):
            left, self.leaving[i] = self.leaving[i], None
            self.grants.release(i, left)
            self._tell_clear()
        elif isinstance(payload, Halted):
            self.release(i, now_s)
        elif isinstance(payload, PassRequest):
            # the opposite lane leads from the vertex ahead back to the one it left
            self.grants.lanes.request(i, self.target[i], self.came_from[i])
        elif isinstance(payload, PassDone):
            self.grants.lanes.done(i)

    def _on_the_way(self, start: str, end: str) -> bool:
        """Whether some robot is on the lane from ``start`` to ``end``: it was granted
        ``end`` leaving ``start`` and is not yet in ``end``'s area, as that station sees
        (one switched off on the lane stays there: a pass beside it waits for good)."""
        return any(self.came_from[j] == start and self.target[j] == end
                   and not self.sight.in_area(j, end) for j in range(len(self.target)))

    def _request(self, i: int, payload: EntryRequest, now_s: float) -> None:
        vertex = self.target[i]
        ahead, off = self.grants.edge_towards(vertex, payload.angle_rad)
        if off > DEPARTURE_TOLERANCE_RAD:  # the denial names no vertex: robots know none
            self.outbox.append((i, EntryDenied(
                f"its departure angle is {math.degrees(off):.0f} deg from every edge at "
                "its vertex")))
            return
        self.came_from[i], self.asked[i] = vertex, payload.angle_rad
        if payload.part_way:  # a relay's last leg: onto the lane, not into ``ahead``
            self.leaving[i], self.target[i] = vertex, None
            self.outbox.append((i, EntryGranted(False, payload.angle_rad)))
            return
        if ahead in self.closed:  # it stays on its centre and decides anew
            self.outbox.append((i, EntryBlocked(payload.angle_rad)))
            return
        self.grants.request(i, vertex, ahead, now_s)

    def _withdraw(self, i: int) -> None:
        """Robot ``i``, still on its vertex centre, drops its request or gives its grant
        back (step 5). If its vertex went to another robot in a swap, that robot still
        waits until this one has left the area."""
        self.grants.withdraw(i)
        here = self.leaving[i]
        if here is None:
            return  # not granted yet
        self.grants.release(i, self.target[i])
        self.awaiting_clear.discard(i)
        self.target[i] = here
        if self.grants.holder.get(here) == i:
            self.leaving[i] = None
        self._tell_clear()

    def _turned_back(self, i: int, from_lane: bool, way_on_closed: bool,
                     now_s: float) -> None:
        """Robot ``i`` walks back along its edge (step 5): short of its corridor it gets
        the vertex behind back at once, unless the station gave it to another robot (a
        swap: no answer, and it goes on; if that robot has stopped for good since, the
        vertex is free and its own again; if ``i`` cannot go on either, the swap is undone
        while that robot still waits on its lane, :meth:`_undo_swap`); else it asks for it
        as from a centre, and the grant tells it when it may turn, or enter."""
        back = self.came_from[i]
        holder = self.grants.holder.get(back)
        swapped = not from_lane and self.leaving[i] == back and holder not in (None, i)
        if way_on_closed and not swapped:
            return  # it says so after its TurnedBack: only a swap has anything to undo
        if swapped and not (way_on_closed and self._undo_swap(holder, back, now_s)):
            return
        self.awaiting_clear.discard(i)
        self.grants.release(i, self.target[i])
        if self.leaving[i] == back:  # it had not left that area: it is its own again
            self.grants.occupy(i, back)
            self.leaving[i], self.target[i] = None, back
            self.outbox.append((i, EntryGranted(clear=True)))
        else:  # from its lane, or its corridor: as a request from a centre
            self.target[i], self.asked[i] = None, None  # the grant answers no EntryRequest
            self.grants.request(i, None, back, now_s)
        self._tell_clear()

    def _undo_swap(self, j: int, vertex: str, now_s: float) -> bool:
        """Take ``vertex`` back from robot ``j``, granted it in a swap, if ``j`` waits for it
        on its lane (clear of the vertex it left, told ``vertex`` is not clear yet): its
        grant becomes a request from its lane again, answered as any (it keeps waiting
        where its lane's wall ends meanwhile). False (nothing changed) if ``j`` is not
        waiting so."""
        if j not in self.awaiting_clear or self.leaving[j] is not None:
            return False
        self.awaiting_clear.discard(j)
        self.grants.release(j, vertex)
        self.target[j] = None
        self.grants.request(j, None, vertex, now_s)
        return True

    def release(self, i: int, now_s: float) -> None:
        """Robot ``i`` stopped for good (or was switched off): its holds go; a station
        whose vertex area the body still occupies keeps the vertex closed (it sees the
        body, as it sees who stands on its centre) and blocks the robots that want it."""
        self.grants.release_all(i)
        self.blocked_on_way.discard(i)
        vertex = self.sight.body_closes(i)
        self.leaving[i] = None
        self.awaiting_clear.discard(i)
        if vertex is not None:
            self.grants.occupy(i, vertex)
            self._close(vertex, i, now_s)
        self._tell_clear()

    def _close(self, vertex: str, body: int, now_s: float) -> None:
        """``vertex`` is closed by robot ``body``'s body (step 7): the requests for it
        waiting on centres are answered with ``EntryBlocked`` now; robots on their way to
        it (granted, or walking back to it from a lane) once out of every area."""
        self.closed.setdefault(vertex, (body, now_s))
        for j, request in sorted(self.grants.requests.items()):
            if request.to == vertex:
                self.grants.withdraw(j)
                if request.at is not None:
                    self.outbox.append((j, EntryBlocked(self.asked[j])))
                else:
                    self.blocked_on_way.add(j)
        for j in range(len(self.target)):
            if j != body and self.target[j] == vertex and self.sight.present(j):
                self.awaiting_clear.discard(j)
                self.blocked_on_way.add(j)

    def _tell_clear(self) -> None:
        """Tell the robots waiting for a vertex whose previous holder has now left it."""
        for j in sorted(self.awaiting_clear):
            if self.target[j] not in self.leaving:
                self.awaiting_clear.discard(j)
                self.outbox.append((j, VertexClear()))
