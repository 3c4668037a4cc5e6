"""Relays on demand: rule 6 of connected exploration (:mod:`algorithms.exploration.tether`).

The tether keeps every robot connected, but a robot that reaches the end of its leash can
only wait. Rule 6 (ours) brings it a relay, leapfrogging the chain forward:

* **Request.** An exploring robot (or one walking back to its task, or retreating to the
  root) that has wanted to step and could not for ``RECRUIT_AFTER_UNITS`` floods
  ``RelayWanted`` with where it is:
  its loop-free route from the root (the legs it took, each named by the beacon it
  started from and the incidence angles at both ends), the leg it is on, and how far
  along it is.
* **Offer.** A robot that is free (exploring, without children, and itself stuck or held
  by the world as long, or idle at a vertex; never one that can take no step at all, see
  Retreat, nor one that awaits a relay of its own, see Accept) floods ``RelayOffer``, to
  any requester but its own parent (the requester takes its relay for a parent, which a
  robot hanging from it cannot be; on bodies its walk there leads past the requester on
  its lane). (A robot held on a vertex centre before its leg began is back where it
  started at once: the world calls :meth:`ConnectedExplorer.arrived_back` without moving
  it.) A robot with a request of its own offers only to requesters with a smaller index,
  and then drops its request, so one of two stuck robots always serves the other.
* **Accept.** The requester takes the first offer (the lowest index among those of one
  tick) and floods ``RelayAccepted``; other offers lapse after ``OFFER_TIMEOUT_UNITS``.
  It then awaits that relay: it neither asks again nor retreats for
  ``OFFER_TIMEOUT_UNITS`` plus ``JOURNEY_UNITS_PER_LEG`` per leg of its route (the
  relay's way to it, at most back to the root and out again), or until it moves on.
  (Asking again at once, as a requester still stuck would, recruits every free robot
  in as many ticks, and one that retreats, or sets out as another's relay, before its
  relay arrives leaves it waiting for nobody: on bodies, where relays queue for vertex
  areas, a livelock.)
* **Transit.** The relay suspends its own task (its strategy is not asked anything and no
  beacon is written until it resumes), goes back to the last vertex where its route and the
  requester's agree, then along the requester's route and leg, and stops where the
  requester is, less the world's ``spacing`` (or where its own leash stops it). A point
  within the world's ``clear`` of the vertex the requester left lies in that vertex's
  area, which a body standing there keeps from every other robot: the relay then stands
  where the lane into that vertex ends (vertex entry holds it there, short of the
  area), or on the root if the requester left the root (ours, for bodies; 0 for
  points). There it stands still: rule 4 lets the requester adopt it, and the requester
  goes on within range of its relay.
* **Release.** A relay holds while it has children. Once it has had none for
  ``RELEASE_UNITS`` (its child went on, or came back and re-attached nearer the base), or
  was never adopted within ``RELAY_PATIENCE_UNITS``, it goes back the same way and resumes
  its own task where it left it. It goes back too once the world has held every child
  of its for ``RELAY_PATIENCE_UNITS``: on bodies a relay on a vertex centre is in the way
  of a child that walks back through that vertex, and neither would ever move
  (``tri:2x3``, four robots at 2 m). Going back, it steps only within its held
  children's leash (rule 2) and stands again as soon as one of them moves.
* **Retreat.** An exploring robot stuck with no child to hold for (none, or each one
  held by the world: rule 2 lets it step) for ``RETREAT_AFTER_UNITS`` (nobody came)
  suspends its task and walks back to the root, where it waits in reserve: free to
  serve as a relay, and back to its own task once it has heard no request for
  ``RESUME_AFTER_UNITS``. A robot walking back to its task that gets stuck is
  free to serve, and retreats again after as long. A robot that can take no step at all
  (a wall fades its parent's link, and it has no move left to undo: the leash,
  :mod:`algorithms.exploration.leash`) never retreats: it keeps asking, since only a
  relay in its ranging can free it. A retreating robot that its leash stops asks too
  (ours): it is on its way to where the free robots wait, and none would come to it
  unasked (``tri:2x3``, 4 robots at 2 m, seed 2, 0.15 m/s: a robot pinned in its U-turn
  stood from 240 s until the team's stall at 883 s).

* **Held on the way.** A relay that the world holds on its way (a body ahead on its lane,
  a vertex area it may not enter yet, on a lane or on a vertex centre where it waits for
  it) for as long as it waits at a leash stops where it is and relays from there, as one
  the leash stops. A robot held by the world stands by
  necessity, for as long as what holds it lasts, so it counts as settled (below).

* **Settled robots adopt.** A robot's beat says it stands still only when it stands by
  its own choice or by necessity: a relay, in reserve, idle, holding, stuck at the end
  of its leash, or held by the world.
  Rule 4 asks only robots whose beat says so, so a robot that merely paused between two
  moves (at a vertex on its way back to its task, say) is never made a permanent anchor
  wherever it happened to be (on ``lattice:1x8`` with five robots at 1 m, a robot
  adopted next to the base held there for the rest of the run).

The walk is the robot's own: it follows incidence angles from vertex to vertex as
Nagavarapu et al.'s robots do; routes name vertices by their beacons (each beacon's
hardware identity).
Walking back along an edge is the world's: the graph world reverses, a MuJoCo robot turns
onto the opposite lane (:meth:`~algorithms.navigation.Navigator.turn_back`). The waits are
in time units, so they keep their meaning at any control rate.
Flooded messages are forwarded once by every robot and by the base.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Hashable, Mapping, Sequence
from typing import Any, NamedTuple

from algorithms.exploration.base import IDLE, Decision, Strategy, go
from algorithms.exploration.entry import DEPARTURE_TOLERANCE_RAD
from algorithms.exploration.tether import Tether
from algorithms.robot import Message

#: Rule 6's waits, in time units (an edge's traversal: the tether's ``ticks_per_unit``
#: control ticks). How long a robot waits at the end of its leash before it asks for a relay:
RECRUIT_AFTER_UNITS = 1.0
#: How long an offer (or a request without offers) stays open.
OFFER_TIMEOUT_UNITS = 4.0
#: How long a relay stays without children before it goes back.
RELEASE_UNITS = 1.0
#: How long a relay waits to be adopted before it goes back.
RELAY_PATIENCE_UNITS = 4.0
#: How long an exploring robot stays stuck before it retreats to the root.
RETREAT_AFTER_UNITS = RECRUIT_AFTER_UNITS + OFFER_TIMEOUT_UNITS
#: How long a robot in reserve hears no request before it resumes its task.
RESUME_AFTER_UNITS = 5.0
#: How long a requester awaits the relay it accepted, per leg of its route (an edge's
#: traversal there and back, with room for waits at vertices), after OFFER_TIMEOUT_UNITS.
JOURNEY_UNITS_PER_LEG = 2.0

EXPLORE, TRANSIT, RELAY, RETURN, RETREAT, RESERVE, RETIRED = (
    "explore", "transit", "relay", "return", "retreat", "reserve", "retired")
#: The modes in which a robot that its leash stops asks for a relay (rule 6's Request).
ASKS = (EXPLORE, RETURN, RETREAT)
#: Every mode, in a fixed order (a robot's ``mode`` telemetry is its index here).
MODES = (EXPLORE, TRANSIT, RELAY, RETURN, RETREAT, RESERVE, RETIRED)


class Leg(NamedTuple):
    """An edge as a robot walks it: the id of the beacon it left (an opaque name, never
    the beacon: messages carry it), the incidence angle it left by, and the angle of the
    same edge at the far vertex (None while under way)."""

    start: Hashable
    depart: float
    arrive: float | None = None


class RelayWanted(NamedTuple):
    requester: Hashable
    serial: int
    route: tuple[Leg, ...]
    leg: Leg
    progress: float


class RelayOffer(NamedTuple):
    requester: Hashable
    serial: int
    offerer: Hashable


class RelayAccepted(NamedTuple):
    requester: Hashable
    serial: int
    relay: Hashable


def flood_key(payload) -> tuple | None:
    """What identifies a flooded message (None: not flooded)."""
    if isinstance(payload, RelayWanted):
        return ("wanted", payload.requester, payload.serial)
    if isinstance(payload, RelayOffer):
        return ("offer", payload.requester, payload.serial, payload.offerer)
    if isinstance(payload, RelayAccepted):
        return ("accepted", payload.requester, payload.serial)
    return None


class Flooder:
    """Forwards each flooded message once."""

    def __init__(self) -> None:
        self.seen: set[tuple] = set()

    def fresh(self, payload) -> bool:
        key = flood_key(payload)
        if key is None or key in self.seen:
            return False
        self.seen.add(key)
        return True


class Waits(NamedTuple):
    """Rule 6's waits in control ticks (the ``*_UNITS`` constants at a world's rate)."""

    recruit: int
    offer: int
    release: int
    patience: int
    retreat: int
    resume: int

    @classmethod
    def at(cls, ticks_per_unit: int) -> "Waits":
        units = (RECRUIT_AFTER_UNITS, OFFER_TIMEOUT_UNITS, RELEASE_UNITS, RELAY_PATIENCE_UNITS,
                 RETREAT_AFTER_UNITS, RESUME_AFTER_UNITS)
        return cls(*(max(1, round(u * ticks_per_unit)) for u in units))


class ConnectedExplorer:
    """An exploration strategy on a tether, with relays on demand (module docstring).

    The world calls, each tick: :meth:`hear`; at a vertex :meth:`arrive` (all robots of a
    batch first) and :meth:`on_vertex`; on an edge :meth:`direction` and, for the step,
    ``tether.may_step``; then :meth:`after`. ``progress`` (how far along its leg it is) is
    the robot's odometry, in the world's measure: the share of the edge in the graph
    world, metres driven since it left the vertex on the MuJoCo robots (a robot compares
    only its own progress with a requester's, on the same leg). A relay stops ``spacing``
    short of where its requester stood, and never within ``clear`` of the vertex the
    requester left (both 0 in the graph world; bodies need room, and a vertex area holds
    one body).
    """

    def __init__(self, index: int, mind: Strategy, tether: Tether, spacing: float = 0.0,
                 clear: float = 0.0) -> None:
        self.index = index
        self.spacing = spacing
        self.clear = clear
        self.mind = mind
        self.tether = tether
        self.flood = Flooder()
        self.mode = EXPLORE
        self.route: list[Leg] = []  # loop-free, from the root to where it stands / left
        self.leg: Leg | None = None
        self.backwards = False
        self.progress = 0.0
        self.idle = False
        #: ticks it wanted to step and the leash forbade it (not holding for a child: a
        #: parent whose children the world all holds may step, rule 2, so it counts too)
        self.stuck = 0
        self.held = 0  # ticks it wanted to move and the world held it
        self.pinned = False  # it could take no step at all in its last tick (:meth:`after`)
        self.under_way = False  # on an edge (the world has asked its direction since it left)
        self.turned = False  # it has been told to walk back along the leg it is on
        self._waits = Waits.at(tether.ticks_per_unit)
        #: whether its last vertex call asked its strategy (else: it walked a plan)
        self.consulted = False
        self.serial = 0
        self.request: tuple[int, int] | None = None  # (serial, tick) of an open request
        self.awaiting_until: int | None = None  # tick until which it awaits its relay
        self.offer: tuple[Hashable, int, int] | None = None  # (requester, serial, tick)
        self.plan: list[tuple] = []
        self._goal: tuple = ((), None, 0.0)  # what ``plan`` leads to (:meth:`_head_for`)
        self.stop_at: float | None = None
        self.task: tuple[tuple[Leg, ...], Leg | None, float] | None = None
        self.relay_since = 0
        self.had_child_at: int | None = None
        self.children_held_since: int | None = None  # tick since every child is held
        self.progressed = False
        self._root: Hashable | None = None  # the root's beacon id
        self._tick = 0
        self._wanted: RelayWanted | None = None
        self.last_wanted = 0  # tick of the last request heard
        #: relay missions this robot has set out on
        self.relay_trips = 0

    # ------------------------------------------------------------------ messages
    def hear(self, tick: int, inbox: Sequence[Message], around: Mapping,
             willing: bool = True) -> list[Message]:
        out = self.tether.hear(tick, inbox, around, willing)
        offers = []
        for m in inbox:
            p = m.payload
            if not self.flood.fresh(p):
                continue
            out.append(Message(p))  # flooded on
            if isinstance(p, RelayWanted) and p.requester != self.index:
                self.last_wanted = tick
                self._consider(tick, p, out)
            elif isinstance(p, RelayOffer) and p.requester == self.index:
                offers.append(p)
            elif isinstance(p, RelayAccepted):
                self._accepted(tick, p)
        if offers and self.request is not None and self.mode in ASKS:
            mine = [o for o in offers if o.serial == self.request[0]]
            if mine:
                best = min(mine, key=lambda o: o.offerer)
                self.request = None
                self.awaiting_until = tick + self._waits.offer + round(
                    JOURNEY_UNITS_PER_LEG * (len(self.route) + 1) * self.tether.ticks_per_unit)
                accepted = RelayAccepted(self.index, best.serial, best.offerer)
                self.flood.fresh(accepted)
                out.append(Message(accepted))
        return out

    def retire(self) -> None:
        """It stopped for good (done, stopped, or the team is infeasible): it still floods
        and holds, and offers itself to nobody."""
        self.mode, self.offer, self.request = RETIRED, None, None

    @property
    def calls_relay(self) -> bool:
        """Whether it has wanted to step, and could not, long enough to call a relay."""
        return self.stuck >= self._waits.recruit

    def _free(self) -> bool:
        if (self.tether.children or self.offer is not None or self.tether.request is not None
                or self.pinned or self.awaiting_until is not None):
            return False  # one awaiting its own relay stays where that relay heads for
        stuck = max(self.stuck, self.held) >= self._waits.recruit
        return (self.mode == RESERVE or (self.mode == EXPLORE and (stuck or self.idle))
                or (self.mode == RETURN and stuck))

    def _consider(self, tick: int, wanted: RelayWanted, out: list[Message]) -> None:
        if not self._free() or wanted.requester in self.tether.parents:
            return  # never its parent's relay: its parent would take it for a parent
        if self.request is not None:
            if wanted.requester > self.index:
                return
            self.request = None
        self.offer = (wanted.requester, wanted.serial, tick)
        self._wanted = wanted
        offer = RelayOffer(wanted.requester, wanted.serial, self.index)
        self.flood.fresh(offer)
        out.append(Message(offer))

    def _accepted(self, tick: int, accepted: RelayAccepted) -> None:
        if self.offer is None or self.offer[:2] != (accepted.requester, accepted.serial):
            return
        self.offer = None
        if accepted.relay != self.index:
            return
        w = self._wanted
        if self.task is None:  # exploring: suspend the task (else it is suspended already)
            self.task = (tuple(self.route), self.leg, self.progress)
        stop = w.progress - self.spacing
        if stop >= self.clear:
            self._head_for(w.route, w.leg, stop)
        elif w.route:  # short of ``clear``: where the lane into that vertex ends
            self._head_for(w.route[:-1], w.route[-1], math.inf)
        else:  # ... or, from the root, on the root
            self._head_for((), None, 0.0)
        # its waits count from here: held as long before its trip, it is not held on its way
        self.mode, self.stuck, self.held, self.idle, self.stop_at = TRANSIT, 0, 0, False, None
        self.relay_trips += 1

    # ------------------------------------------------------------------ at a vertex
    def arrive(self, beacon, angles: Sequence[float], arrived_by: float | None) -> None:
        self._walked_to(beacon, arrived_by)
        if self.mode == EXPLORE:
            self.mind.arrive(beacon, angles, arrived_by)

    def on_vertex(self, beacon, angles: Sequence[float], arrived_by: float | None) -> Decision:
        decision = self._on_vertex(beacon, angles, arrived_by)
        if self._root is None:  # the first call, at the root: its beacon is named now
            self._root = beacon.id
        return decision

    def _on_vertex(self, beacon, angles: Sequence[float], arrived_by: float | None) -> Decision:
        self.idle = self.consulted = False
        if self.plan and self.plan[0] == ("back",):  # planned on the edge it has finished
            self.plan = self._way(*self._goal)
        if self.mode in (TRANSIT, RETURN, RETREAT) and not self.plan:
            if self.mode == TRANSIT:  # the requester stood at a vertex
                return self._become_relay_here()
            if self.mode == RETREAT:
                self.mode = RESERVE
                return IDLE
            self.mode, self.task = EXPLORE, None  # back where it was idle: ask again
            arrived_by = None
        if self.mode in (RELAY, RESERVE):
            return IDLE
        if self.mode in (TRANSIT, RETURN, RETREAT):
            step = self.plan.pop(0)
            if step[0] == "to":
                self.stop_at = step[2]
            return self._depart(beacon, step[1])
        self.progressed = arrived_by is not None
        self.consulted = True
        decision = self.mind.on_vertex(beacon, angles, arrived_by)
        if decision.action == "go":
            return self._depart(beacon, decision.angle)
        self.idle = decision.action == "idle"
        return decision

    def _depart(self, beacon, angle: float) -> Decision:
        self.leg, self.backwards, self.progress = Leg(beacon.id, angle), False, 0.0
        self.under_way = self.turned = False
        return go(angle)

    def _walked_to(self, beacon, arrived_by: float | None) -> None:
        """Keep the route loop-free: arriving where a leg of it started cuts it there."""
        if self.leg is None:
            return  # the root's id is kept after its first call (:meth:`on_vertex`)
        done = Leg(self.leg.start, self.leg.depart, arrived_by)
        self.leg, self.under_way = None, False
        if self.backwards:
            return  # back at the start of the leg: the route is as it was
        here = beacon.id  # None: a beacon nobody has named, so no vertex of the route
        starts = [leg.start for leg in self.route]
        if here is not None and here == self._root:
            self.route = []
        elif here is not None and here in starts:
            del self.route[starts.index(here):]
        else:
            self.route.append(done)

    # ------------------------------------------------------------------ on an edge
    @property
    def stops_part_way(self) -> bool:
        """Whether the leg it is setting out on ends part-way, where its requester is (a
        relay's last leg): it needs the lane, not the vertex at the far end."""
        return self.mode == TRANSIT and self.stop_at is not None

    def direction(self, progress: float) -> int:
        """+1 on along the edge, -1 back, 0 stay."""
        self.progress, self.under_way = progress, True
        if self.mode == RELAY:
            return 0
        if self.plan and self.plan[0] == ("back",):
            self.turned = True
            return -1
        if self.stop_at is not None and progress >= self.stop_at - 1e-9:
            if self.mode == TRANSIT:
                self._become_relay_here()
                return 0
            self.stop_at = None  # RETURN: at its old spot, on with its own leg
            self.mode, self.task = EXPLORE, None
        return 1

    def arrived_back(self) -> None:
        """The world: a backward walk reached the start of the leg."""
        self.backwards = True
        if self.plan and self.plan[0] == ("back",):
            self.plan.pop(0)

    def _head_for(self, route: Sequence[Leg], leg: Leg | None, progress: float) -> None:
        """Plan the way to ``progress`` along ``leg`` at the end of ``route`` (:meth:`_way`)
        and remember the goal: a plan made on an edge the robot has in fact just finished
        (the world tells it of the vertex after its messages) is made anew there."""
        self._goal = (route, leg, progress)
        self.plan = self._way(route, leg, progress)

    def _way(self, route: Sequence[Leg], leg: Leg | None, progress: float) -> list[tuple]:
        """The plan from here to ``progress`` along ``leg`` at the end of ``route`` (to
        the end of ``route`` if ``leg`` is None): back to the vertex it is walking from,
        back along its own route to where the two routes part, on along the other.
        Under way, not yet told to walk back, a plan whose first move from that vertex
        is out along the very edge it is on goes straight on instead (ours): turning
        back only to come out again takes a body across its edge twice, and the walk
        back may wait for that vertex (a robot retreating on ``arena2``, 4 robots at
        2.5 m, 0.15 m/s, seed 2, waited for good on the lane of a robot that wanted to
        come out of that vertex along it)."""
        plan = [("back",)] if self.leg is not None else []
        common = _common(self.route, route)
        plan += [("go", l.arrive) for l in reversed(self.route[common:])]
        plan += [("go", l.depart) for l in route[common:]]
        if leg is not None:
            plan.append(("to", leg.depart, progress))
        if (self.under_way and not self.turned and len(plan) > 1 and plan[1][0] == "go"
                and _same_edge(plan[1][1], self.leg.depart)):
            return plan[2:]
        return plan

    def _become_relay_here(self) -> Decision:
        self.mode, self.stop_at, self.plan = RELAY, None, []
        self.relay_since, self.had_child_at, self.children_held_since = self._tick, None, None
        return IDLE

    # ------------------------------------------------------------------ end of tick
    def after(self, tick: int, wanted: Sequence[float] | None, moved: bool,
              around: Mapping, held: bool = False, cut: Collection = (),
              pinned: bool = False) -> list[Message]:
        """``wanted``: the step the leash forbade it (None if none); ``held``: it wanted to
        move and the world held it (a body ahead on its lane, a vertex not yet entered);
        ``cut``: parents whose link that step would lose to a wall (rule 4's ``cut``);
        ``pinned``: it can take no step at all, back included (a wall fades its parent's
        link and no move is left to undo), so it never retreats: it keeps asking."""
        self._tick = tick
        waits = self._waits
        out = self.tether.ask(tick, wanted, around, cut, held)
        blocked = wanted is not None and not self.tether.holds()
        self.stuck = self.stuck + 1 if blocked else 0
        self.held = self.held + 1 if held else 0
        self.pinned = pinned
        if self.awaiting_until is not None and (not self.stuck or tick >= self.awaiting_until):
            if self.stuck:  # its relay did not come: ask again, then retreat as before
                self.stuck = waits.recruit
            self.awaiting_until = None
        awaiting = self.awaiting_until is not None
        if (self.mode in ASKS and self.stuck >= waits.recruit and not awaiting
                and self.leg is not None):
            if self.request is None or tick - self.request[1] > waits.offer:
                self.serial += 1
                self.request = (self.serial, tick)
                w = RelayWanted(self.index, self.serial, tuple(self.route), self.leg,
                                self.progress)
                self.flood.fresh(w)
                out.append(Message(w))
        if self.offer is not None and tick - self.offer[2] > waits.offer:
            self.offer = None
        if self.mode == TRANSIT and (self.under_way or held) and max(
                self.stuck, self.held) >= waits.recruit:
            self._become_relay_here()  # held on its way, on an edge or on a centre
        if self.mode == RELAY:
            self._relay_tick(tick)
        if (self.mode in (EXPLORE, RETURN) and self.stuck >= waits.retreat and not awaiting
                and not pinned):
            if self.task is None:
                self.task = (tuple(self.route), self.leg, self.progress)
            self.mode, self.request = RETREAT, None
            self._head_for([], None, 0.0)
            self.stop_at, self.stuck = None, 0
        if self.mode == RESERVE and tick - self.last_wanted >= waits.resume:
            self.mode = RETURN
            self._head_for(*self.task)
        out.append(self.tether.beat(tick, moved or not self._settled(), self.progressed,
                                    len(self.mind.map_edges()), held, blocked))
        self.progressed = False
        return out

    def _settled(self) -> bool:
        """Whether it stands by its own choice (a relay, in reserve, idle, holding, stuck
        at the end of its leash, or held by the world): only then does its beat say it is
        still, so that nobody asks a robot that merely paused between two moves to adopt
        them (it would hold there for as long as its child needs it)."""
        return (self.mode in (RELAY, RESERVE) or self.idle or self.stuck > 0
                or self.held > 0 or bool(self.tether.children))

    def _relay_tick(self, tick: int) -> None:
        if self.tether.children:
            self.had_child_at = tick
            if self.tether.holds():  # a child on the move
                self.children_held_since = None
                return
            if self.children_held_since is None:
                self.children_held_since = tick
            if tick - self.children_held_since < self._waits.patience:
                return  # every child held by the world, for a while yet: it still relays
        elif self.had_child_at is None:
            if tick - self.relay_since < self._waits.patience:
                return
        elif tick - self.had_child_at < self._waits.release:
            return
        self.mode = RETURN
        self._head_for(*self.task)


def _same_edge(a: float, b: float) -> bool:
    """Whether two incidence angles (rad) at one vertex name the same edge: an arrival
    angle is measured, a departure angle decided, so they agree within half the 45
    degrees edges are at least apart (:data:`~algorithms.exploration.entry.
    DEPARTURE_TOLERANCE_RAD`)."""
    return abs(math.remainder(a - b, 2.0 * math.pi)) <= DEPARTURE_TOLERANCE_RAD


def _common(a: Sequence[Leg], b: Sequence[Leg]) -> int:
    """How many legs two routes from the root share."""
    n = 0
    for x, y in zip(a, b):
        if x.start != y.start or x.depart != y.depart:
            break
        n += 1
    return n
