"""Relays on demand: rule 6 of connected exploration (:mod:`algorithms.exploration.tether`).

The tether keeps every robot connected, but a robot that reaches the end of its leash can
only wait. Rule 6 (ours) brings it a relay, leapfrogging the chain forward:

* **Request.** An exploring robot (or one walking back to its task) that has wanted to
  step and could not for ``RECRUIT_AFTER_TICKS`` floods ``RelayWanted`` with where it is: its loop-free route
  from the root (the legs it took, each named by the beacon it started from and the
  incidence angles at both ends), the leg it is on, and how far along it is.
* **Offer.** A robot that is free (exploring, without children, and itself stuck as long,
  or idle at a vertex) floods ``RelayOffer``. A robot with a request of its own offers only
  to requesters with a smaller index, and then drops its request, so one of two stuck
  robots always serves the other.
* **Accept.** The requester takes the first offer (the lowest index among those of one
  tick) and floods ``RelayAccepted``; other offers lapse after ``OFFER_TIMEOUT_TICKS``.
* **Transit.** The relay suspends its own task (its strategy is not asked anything and no
  beacon is written until it resumes), goes back to the last vertex where its route and the
  requester's agree, then along the requester's route and leg, and stops where the
  requester is (or where its own leash stops it). There it stands still: rule 4 lets the
  requester adopt it, and the requester goes on within range of its relay.
* **Release.** A relay holds while it has children. Once it has had none for
  ``RELEASE_TICKS`` (its child went on, or came back and re-attached nearer the base), or
  was never adopted within ``RELAY_PATIENCE_TICKS``, it goes back the same way and resumes
  its own task where it left it.
* **Retreat.** An exploring robot stuck without children for ``RETREAT_AFTER_TICKS``
  (nobody came) suspends its task and walks back to the root, where it waits in
  reserve: free to serve as a relay, and back to its own task once it has heard no
  request for ``RESUME_AFTER_TICKS``. A robot walking back to its task that gets stuck is
  free to serve, and retreats again after as long.

* **Settled robots adopt.** A robot's beat says it stands still only when it stands by
  its own choice: a relay, in reserve, idle, holding, or stuck at the end of its leash.
  Rule 4 asks only robots whose beat says so, so a robot that merely paused between two
  moves (at a vertex on its way back to its task, say) is never made a permanent anchor
  wherever it happened to be (on ``lattice:1x8`` with five robots at 1 m, a robot
  adopted next to the base held there for the rest of the run).

The walk is the robot's own: it follows incidence angles from vertex to vertex as seed
003's robots do; routes name vertices by their beacons (each beacon's hardware identity).
Flooded messages are forwarded once by every robot and by the base.
"""

from __future__ import annotations

from collections.abc import Hashable, Mapping, Sequence
from typing import Any, NamedTuple

from algorithms.exploration.base import IDLE, Decision, Strategy, go
from algorithms.exploration.tether import Tether
from algorithms.robot import Message

#: Ticks a robot waits at the end of its leash before it asks for a relay.
RECRUIT_AFTER_TICKS = 10
#: Ticks an offer (or a request without offers) stays open.
OFFER_TIMEOUT_TICKS = 40
#: Ticks a relay stays without children before it goes back.
RELEASE_TICKS = 10
#: Ticks a relay waits to be adopted before it goes back.
RELAY_PATIENCE_TICKS = 40
#: Ticks an exploring robot stays stuck before it retreats to the root.
RETREAT_AFTER_TICKS = RECRUIT_AFTER_TICKS + OFFER_TIMEOUT_TICKS
#: Ticks without a request after which a robot in reserve resumes its task.
RESUME_AFTER_TICKS = 50

EXPLORE, TRANSIT, RELAY, RETURN, RETREAT, RESERVE = (
    "explore", "transit", "relay", "return", "retreat", "reserve")


class Leg(NamedTuple):
    """An edge as a robot walks it: the beacon it left, the incidence angle it left by,
    and the angle of the same edge at the far vertex (None while under way)."""

    start: Any
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


class ConnectedExplorer:
    """A seed-003 strategy on a tether, with relays on demand (module docstring).

    The world calls, each tick: :meth:`hear`; at a vertex :meth:`arrive` (all robots of a
    batch first) and :meth:`on_vertex`; on an edge :meth:`direction` and, for the step,
    ``tether.may_step``; then :meth:`after`. ``progress`` (the share of its edge behind it)
    is the robot's odometry.
    """

    def __init__(self, index: int, mind: Strategy, tether: Tether) -> None:
        self.index = index
        self.mind = mind
        self.tether = tether
        self.flood = Flooder()
        self.mode = EXPLORE
        self.route: list[Leg] = []  # loop-free, from the root to where it stands / left
        self.leg: Leg | None = None
        self.backwards = False
        self.progress = 0.0
        self.idle = False
        self.stuck = 0  # ticks it wanted to step and could not
        self.serial = 0
        self.request: tuple[int, int] | None = None  # (serial, tick) of an open request
        self.offer: tuple[Hashable, int, int] | None = None  # (requester, serial, tick)
        self.plan: list[tuple] = []
        self.stop_at: float | None = None
        self.task: tuple[tuple[Leg, ...], Leg | None, float] | None = None
        self.relay_since = 0
        self.had_child_at: int | None = None
        self.progressed = False
        self._root = None
        self._tick = 0
        self._wanted: RelayWanted | None = None
        self.last_wanted = 0  # tick of the last request heard
        #: relay missions this robot has set out on
        self.relay_trips = 0

    # ------------------------------------------------------------------ messages
    def hear(self, tick: int, inbox: Sequence[Message], around: Mapping) -> list[Message]:
        out = self.tether.hear(tick, inbox, around)
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
        if offers and self.request is not None and self.mode in (EXPLORE, RETURN):
            mine = [o for o in offers if o.serial == self.request[0]]
            if mine:
                best = min(mine, key=lambda o: o.offerer)
                self.request = None
                accepted = RelayAccepted(self.index, best.serial, best.offerer)
                self.flood.fresh(accepted)
                out.append(Message(accepted))
        return out

    def _free(self) -> bool:
        if self.tether.children or self.offer is not None or self.tether.request is not None:
            return False
        stuck = self.stuck >= RECRUIT_AFTER_TICKS
        return (self.mode == RESERVE or (self.mode == EXPLORE and (stuck or self.idle))
                or (self.mode == RETURN and stuck))

    def _consider(self, tick: int, wanted: RelayWanted, out: list[Message]) -> None:
        if not self._free():
            return
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
        self.plan = self._way(w.route, w.leg, w.progress)
        self.mode, self.stuck, self.idle, self.stop_at = TRANSIT, 0, False, None
        self.relay_trips += 1

    # ------------------------------------------------------------------ at a vertex
    def arrive(self, beacon, angles: Sequence[float], arrived_by: float | None) -> None:
        self._walked_to(beacon, arrived_by)
        if self.mode == EXPLORE:
            self.mind.arrive(beacon, angles, arrived_by)

    def on_vertex(self, beacon, angles: Sequence[float], arrived_by: float | None) -> Decision:
        self.idle = False
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
        decision = self.mind.on_vertex(beacon, angles, arrived_by)
        if decision.action == "go":
            return self._depart(beacon, decision.angle)
        self.idle = decision.action == "idle"
        return decision

    def _depart(self, beacon, angle: float) -> Decision:
        self.leg, self.backwards, self.progress = Leg(beacon, angle), False, 0.0
        return go(angle)

    def _walked_to(self, beacon, arrived_by: float | None) -> None:
        """Keep the route loop-free: arriving where a leg of it started cuts it there."""
        if self.leg is None:
            if self._root is None:
                self._root = beacon
            return
        done = Leg(self.leg.start, self.leg.depart, arrived_by)
        self.leg = None
        if self.backwards:
            return  # back at the start of the leg: the route is as it was
        starts = [leg.start for leg in self.route]
        if beacon is self._root:
            self.route = []
        elif beacon in starts:
            del self.route[starts.index(beacon):]
        else:
            self.route.append(done)

    # ------------------------------------------------------------------ on an edge
    def direction(self, progress: float) -> int:
        """+1 on along the edge, -1 back, 0 stay."""
        self.progress = progress
        if self.mode == RELAY:
            return 0
        if self.plan and self.plan[0] == ("back",):
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

    def _way(self, route: Sequence[Leg], leg: Leg | None, progress: float) -> list[tuple]:
        """The plan from here to ``progress`` along ``leg`` at the end of ``route`` (to
        the end of ``route`` if ``leg`` is None): back to the vertex it is walking from,
        back along its own route to where the two routes part, on along the other."""
        plan = [("back",)] if self.leg is not None else []
        common = _common(self.route, route)
        plan += [("go", l.arrive) for l in reversed(self.route[common:])]
        plan += [("go", l.depart) for l in route[common:]]
        if leg is not None:
            plan.append(("to", leg.depart, progress))
        return plan

    def _become_relay_here(self) -> Decision:
        self.mode, self.stop_at, self.plan = RELAY, None, []
        self.relay_since, self.had_child_at = self._tick, None
        return IDLE

    # ------------------------------------------------------------------ end of tick
    def after(self, tick: int, wanted: Sequence[float] | None, moved: bool,
              around: Mapping) -> list[Message]:
        """``wanted``: the step it wanted and did not take (None if none)."""
        self._tick = tick
        out = self.tether.ask(tick, wanted, around)
        blocked = wanted is not None and not self.tether.children
        self.stuck = self.stuck + 1 if blocked else 0
        if self.mode in (EXPLORE, RETURN) and self.stuck >= RECRUIT_AFTER_TICKS and self.leg is not None:
            if self.request is None or tick - self.request[1] > OFFER_TIMEOUT_TICKS:
                self.serial += 1
                self.request = (self.serial, tick)
                w = RelayWanted(self.index, self.serial, tuple(self.route), self.leg,
                                self.progress)
                self.flood.fresh(w)
                out.append(Message(w))
        if self.offer is not None and tick - self.offer[2] > OFFER_TIMEOUT_TICKS:
            self.offer = None
        if self.mode == TRANSIT and self.stuck >= RECRUIT_AFTER_TICKS:
            self._become_relay_here()
        if self.mode == RELAY:
            self._relay_tick(tick)
        if self.mode in (EXPLORE, RETURN) and self.stuck >= RETREAT_AFTER_TICKS:
            if self.task is None:
                self.task = (tuple(self.route), self.leg, self.progress)
            self.plan, self.mode, self.request = self._way([], None, 0.0), RETREAT, None
            self.stop_at, self.stuck = None, 0
        if self.mode == RESERVE and tick - self.last_wanted >= RESUME_AFTER_TICKS:
            self.plan, self.mode = self._way(*self.task), RETURN
        out.append(self.tether.beat(tick, moved or not self._settled(), self.progressed,
                                    len(self.mind.map_edges())))
        self.progressed = False
        return out

    def _settled(self) -> bool:
        """Whether it stands by its own choice (a relay, in reserve, idle, holding, or stuck
        at the end of its leash): only then does its beat say it is still, so that nobody
        asks a robot that merely paused between two moves to adopt them (it would hold
        there for as long as its child needs it)."""
        return (self.mode in (RELAY, RESERVE) or self.idle or self.stuck > 0
                or bool(self.tether.children))

    def _relay_tick(self, tick: int) -> None:
        if self.tether.children:
            self.had_child_at = tick
            return
        if self.had_child_at is None:
            if tick - self.relay_since < RELAY_PATIENCE_TICKS:
                return
        elif tick - self.had_child_at < RELEASE_TICKS:
            return
        self.plan, self.mode = self._way(*self.task), RETURN


def _common(a: Sequence[Leg], b: Sequence[Leg]) -> int:
    """How many legs two routes from the root share."""
    n = 0
    for x, y in zip(a, b):
        if x.start is not y.start or x.depart != y.depart:
            break
        n += 1
    return n
