"""The embodied explorer: one robot of seed 003 as a :class:`~algorithms.robot.Controller`.

It composes, fed only by its own observation:

* a :class:`~algorithms.navigation.Navigator` (lane following, vertex detection by IR,
  edge discovery by scanning the spokes, odometry) on its line sensors, IR and encoders;
* an exploration :class:`~algorithms.exploration.Strategy` (the graph world's code),
  called at every vertex arrival with the beacon it stands on and the angles it measured;
* a :class:`~algorithms.collision.CollisionRule` (seed 003 Sec. 4) setting its speed
  from its bearings while it follows a lane;
* vertex entry (:mod:`algorithms.exploration.entry`) with the stations;
* optionally a :class:`~algorithms.connectivity.ConnectivityTable` (seed 004) kept over
  its radio: its belief whether a single robot's loss would cut it off the reference;
* optionally a :class:`~algorithms.exploration.tether.Tether` (issue 17's connected
  exploration, rules 1-5): it reads its radio neighbours' ranges and bearings
  (``Observation.detections``), and it does not drive a control period's distance
  (``v dt`` ahead) that the leash forbids: it stands (no turn either, so that it keeps its
  lane), asks for adoption, and declares the exploration infeasible on a stall (rule 5),
  after which it stands for good. The leash knows ranges, not walls: when a wall comes
  between it and a parent (the link is gone from its radio neighbours), it drives its
  moves since the link was last there backwards, and then stands as if the leash had
  stopped it until it has a new parent (ours). Relays on demand (rule 6) are not part of
  the embodied explorer yet.

Choices beyond the paper (the loop functions in :mod:`mjswarm.experiments.exploration` say the rest):

* **The speed rule applies on edges** (following a lane, seed 003 Sec. 4 "traversing an
  edge"); in the vertex area robots move at S and are kept apart by vertex entry. A robot
  slowed by the rule while leaving a vertex would keep that vertex's area occupied
  (issue 13), and at the vertex centre the rule's "beta = 0: stop" would stop a robot
  facing one that waits on the next vertex for this one: a deadlock.
* **Heading re-anchoring**: at a vertex whose beacon already stores angles
  (``Strategy.stored_angles``), the robot rotates its heading frame onto them
  (:func:`~algorithms.navigation.navigator.frame_offset`), so odometry drift does not
  accumulate over revisits and every robot keeps the beacons' frame.
* **Stopping for good**: lost its line, no beacon where it arrived, angles that match no
  beacon, a strategy that cannot reconcile a beacon, an entry denied. It stands still,
  says why (``halted``) and tells the stations.
* **Idle**: a strategy that answers IDLE is asked again after ``idle_wait_s``.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

from algorithms.collision import CollisionRule
from algorithms.exploration.base import AngleMismatch, Decision, Strategy
from algorithms.exploration.tether import Tether
from algorithms.exploration.entry import (
    STATION,
    EntryDenied,
    EntryGranted,
    EntryRequest,
    Halted,
    LeftVertex,
    VertexClear,
)
from algorithms.navigation import ArenaConventions, NavEvent, Navigator, RobotCalibration
from algorithms.navigation.percept import percept
from algorithms.robot import Command, Controller, Message, Observation


class VertexCall(NamedTuple):
    """One call of the strategy at a vertex: when, the beacon, whether the robot had
    just arrived by an edge (else: a launch or an idle wake-up), and the decision."""

    time_s: float
    beacon: Any
    arrived: bool
    decision: Decision


class Explorer(Controller):
    """Args:
        strategy: the exploration mind (one per robot).
        calibration, conventions: the robot's body and the arena marks it reads.
        speed_m_s: cruising speed S (m/s).
        rule: its speed rule (None: no collision avoidance, and no vertex entry: it
            leaves a vertex as soon as it has decided).
        turn_rate_rad_s: in-place turn and scan rate.
        idle_wait_s: how long to wait before asking an idle strategy again.
        table: a connectivity table kept over the radio (None: none).
        control_dt_s: its control period (its clock counts ticks for the table).
        tether: its tether to the base (None: exploration without the constraint).
    """

    def __init__(self, strategy: Strategy, calibration: RobotCalibration,
                 conventions: ArenaConventions, speed_m_s: float,
                 rule: CollisionRule | None, turn_rate_rad_s: float = 1.0,
                 idle_wait_s: float = 2.0, table=None, control_dt_s: float = 0.02,
                 tether: Tether | None = None) -> None:
        self.strategy = strategy
        self.calibration, self.conventions = calibration, conventions
        self.cruise_m_s = speed_m_s
        self.rule = rule
        self.turn_rate_rad_s = turn_rate_rad_s
        self.idle_wait_s = idle_wait_s
        self.table = table
        self.tether = tether
        #: whether its tether declared the exploration infeasible (rule 5)
        self.infeasible = False
        self._progressed = False
        self._trail: list[tuple[float, float]] = []  # moves since its parents were all linked
        self._occluded = False  # lost a parent's link to a wall: waits for a new parent
        self._parents_then = None if tether is None else tether.parents
        self.control_dt_s = control_dt_s
        self.nav = Navigator(calibration, conventions, 0.0, speed_m_s, turn_rate_rad_s)
        #: every vertex call so far (for the loop functions' metrics and recordings)
        self.calls: list[VertexCall] = []
        #: why it stopped for good, or None
        self.halted: str | None = None
        #: whether its strategy declared the exploration complete
        self.declared = False
        #: its speed in the last tick (m/s): the rule's on a lane, else S
        self.speed_m_s = speed_m_s
        self._handled = 0
        self._idle_since: float | None = None
        self._departure: float | None = None  # angle of the edge it waits to take
        self._leaving = False  # holds the vertex it left until it is in its corridor
        self._clear = True  # the vertex it goes to is clear of its previous holder

    def reset(self) -> None:
        """Put on a vertex centre (a launch): scan, then call the strategy."""
        self.nav.begin_at_vertex()

    def step(self, observation: Observation) -> Command:
        out: list[Message] = []
        now = round(observation.time_s / self.control_dt_s)
        if self.table is not None:
            robots = [m for m in observation.inbox if m.sender != STATION]
            out += self.table.tick(now, robots, observation.neighbors)
        around = {}
        if self.tether is not None:
            around = {j: (d.range_m * math.cos(d.bearing_rad), d.range_m * math.sin(d.bearing_rad))
                      for j, d in observation.detections.items()}
            tied = [m for m in observation.inbox if m.sender != STATION]
            out += self.tether.hear(now, tied, around)
        for m in observation.inbox:
            if m.sender == STATION:
                self._from_station(m.payload, out)
        if self.halted is not None or self.declared or self.infeasible:
            return self._stand(now, out, around)
        if self.tether is not None and not all(q in around for q in self.tether.parents):
            return self._retrace(now, out, around)
        command = self._drive(observation, out)
        if self.tether is None:
            return command
        wanted = None
        if command.v_m_s != 0.0:
            step = (command.v_m_s * self.control_dt_s, 0.0)  # in its own frame
            if self._occluded or not self.tether.may_step(step, around):
                wanted, command = step, Command(messages=command.messages)
            else:
                self._trail.append((command.v_m_s, command.omega_rad_s))
        if self.tether.parents != self._parents_then:  # a new parent: try again
            self._occluded, self._trail = False, []
        self._parents_then = self.tether.parents
        out = list(command.messages)
        out += self.tether.ask(now, wanted, around)
        out.append(self.tether.beat(now, command.v_m_s != 0.0, self._progressed,
                                    len(self.strategy.map_edges())))
        self._progressed = False
        if self.tether.stalled(now):
            self.infeasible = True
        return command._replace(messages=tuple(out))

    def _retrace(self, now: int, out: list[Message], around) -> Command:
        """A parent's link is gone (a wall came between them: the leash knows ranges, not
        walls): drive its last moves backwards until the link is back, then wait for a new
        parent as if the leash had stopped it."""
        self._occluded = True
        if not self._trail:
            return self._stand(now, out, around)
        v, w = self._trail.pop()
        out.append(self.tether.beat(now, True, False, len(self.strategy.map_edges())))
        return Command(-v, -w, messages=tuple(out))

    def _stand(self, now: int, out: list[Message], around) -> Command:
        """Stand still (stopped, done, or infeasible); a tethered robot keeps beating, so
        that its children and the stall gossip go on."""
        if self.tether is not None:
            out += self.tether.ask(now, None, around)
            out.append(self.tether.beat(now, False, False, len(self.strategy.map_edges())))
        return Command(messages=tuple(out))

    def _drive(self, observation: Observation, out: list[Message]) -> Command:
        """Navigator, vertex calls, the speed rule and vertex entry: this tick's command."""
        v, w = self.nav.update(percept(observation.line_m, observation.ir_m,
                                       observation.encoder_rad, self.calibration.line_floor_m))
        self._on_events(observation, out)
        if self.halted is not None or self.declared:
            return Command(messages=tuple(out))
        speed = self.cruise_m_s
        nav = self.nav
        if self.rule is not None:
            if nav.on_lane:  # the rule governs edge traversals
                speed = self.rule.update(observation.bearings)
            else:
                self.rule.forget_bearings()
            if self._leaving and nav.in_corridor:  # clear of the vertex it left
                out.append(Message(LeftVertex(), STATION))
                self._leaving = False
            if nav.at_vertex_area and not self._clear:
                speed = 0.0  # the previous holder of the vertex ahead is still leaving it
        self.speed_m_s = speed
        if v != 0.0:  # translations run at the rule's speed; turns in place do not
            factor = speed / self.cruise_m_s
            v, w = v * factor, w * factor
        return Command(v, w, messages=tuple(out))

    def telemetry(self) -> dict[str, float]:
        """Its speed (m/s), vertex calls so far, and whether it is stopped for good."""
        return {"speed_m_s": self.speed_m_s, "vertex_calls": len(self.calls),
                "halted": float(self.halted is not None)}

    # -- events and vertex calls -----------------------------------------------------------
    def _on_events(self, observation: Observation, out: list[Message]) -> None:
        nav = self.nav
        new = nav.events[self._handled:]
        self._handled = len(nav.events)
        for event in new:
            if event.kind is NavEvent.ARRIVED:
                if self.rule is not None:
                    self.rule.crossed_vertex()  # eq. (34)
                # the scan right after a launch is no arrival: the robot came by no edge
                self._vertex_call(observation, nav.arrived_angle is not None, out)
            elif event.kind is NavEvent.LOST:
                self._halt(str(event), out)
        if (self._idle_since is not None
                and observation.time_s - self._idle_since >= self.idle_wait_s):
            self._idle_since = None
            self._vertex_call(observation, False, out)

    def _vertex_call(self, observation: Observation, arrived: bool, out: list[Message]) -> None:
        """The strategy's vertex call: beacon in, decision out."""
        beacon, nav = observation.beacon, self.nav
        if beacon is None:
            self._halt("no beacon where it arrived (off the vertex centre, or not the "
                       "vertex it was granted)", out)
            return
        try:
            decision = self.strategy.on_vertex(beacon, nav.edge_angles,
                                               nav.arrived_angle if arrived else None)
        except AngleMismatch as exc:  # its heading reference is broken (e.g. after a crash)
            self._halt(f"its angles match no edge of the beacon: {exc}", out)
            return
        except ValueError as exc:  # a beacon it cannot reconcile (e.g. a wiped one)
            self._halt(f"its strategy failed: {exc}", out)
            return
        if self.strategy.stored_angles is not None:  # re-anchoring
            nav.reanchor(self.strategy.stored_angles)
        self.calls.append(VertexCall(observation.time_s, beacon, arrived, decision))
        self._progressed = arrived
        if decision.action == "go":
            self._departure = min(nav.edge_angles, key=lambda a: abs(
                math.remainder(a - decision.angle, 2 * math.pi)))
            if self.rule is None:
                self._depart()
            else:
                out.append(Message(EntryRequest(decision.angle), STATION))
        elif decision.action == "idle":
            self._idle_since = observation.time_s
        elif decision.action == "done":
            self.declared = True
        else:
            raise ValueError(f"the strategy answered an unknown decision {decision!r}")

    def _from_station(self, payload: Any, out: list[Message]) -> None:
        if isinstance(payload, EntryGranted):
            self._clear = payload.clear
            self._leaving = True
            self._depart()
        elif isinstance(payload, VertexClear):
            self._clear = True
        elif isinstance(payload, EntryDenied):
            self._halt(payload.reason, out)

    def _depart(self) -> None:
        self.nav.depart(self._departure)
        self._departure = None

    def _halt(self, reason: str, out: list[Message]) -> None:
        if self.halted is None:
            self.halted = reason
            if self.rule is not None:
                out.append(Message(Halted(reason), STATION))
