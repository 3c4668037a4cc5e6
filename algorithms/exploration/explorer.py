"""The embodied explorer: one robot of Nagavarapu et al. as a :class:`~algorithms.robot.Controller`.

It composes, fed only by its own observation:

* a :class:`~algorithms.navigation.Navigator` (lane following, vertex detection by IR,
  edge discovery by scanning the spokes, odometry) on its line sensors, IR and encoders;
* an exploration :class:`~algorithms.exploration.Strategy` (the graph world's code),
  called at every vertex arrival with the beacon it stands on and the angles it measured;
* a :class:`~algorithms.collision.CollisionRule` (Nagavarapu et al. Sec. 4) setting its speed
  from its bearings while it follows a lane;
* vertex entry (:mod:`algorithms.exploration.entry`) with the stations;
* optionally a :class:`~algorithms.connectivity.ConnectivityTable` (Le et al.) kept over
  its radio: its belief whether a single robot's loss would cut it off the reference;
* optionally a :class:`~algorithms.exploration.tether.Tether` (connected
  exploration), in the graph world's :class:`~algorithms.exploration.relay.ConnectedExplorer`
  (rules 1-6, the same object around the same strategy): it reads its radio neighbours'
  ranges and bearings (``Observation.detections``), and it does not drive a control
  period's distance (``v dt`` ahead) that the leash forbids: it stands (no turn either, so
  that it keeps its lane), asks for adoption, calls relays, serves as one, retreats, and
  declares the exploration infeasible on a stall (rule 5), after which it stands for good.
  Its progress along a leg is the odometry's distance since it left the vertex; a walk
  back is the navigator's :meth:`~algorithms.navigation.Navigator.turn_back`, announced to
  the stations (:class:`~algorithms.exploration.entry.TurnedBack`), and a relay's last leg
  asks only for the lane (``EntryRequest.part_way``). It is held (rule 6's "held on the
  way") when it wants to move and the speed rule or vertex entry stops it. The leash knows
  ranges, not walls: when a wall comes between it and a parent (the link is gone from its
  radio neighbours), it drives its moves since the link was last there backwards (never
  back into a vertex area it has given up, nor off a vertex centre it reached or the
  start of the lane it found, nor out of a U-turn: moves from before are forgotten; its
  navigator counts the moves backwards on its odometry, so that its motion resumes from
  where the body is),
  and then stands as if the leash had stopped it (so it calls a relay, rule 6) until it
  has a new parent or sets out on a new leg; it may still walk back along its leg (rule
  6), unless a wall cut a link on the way back too (ours). A step of a walk back may use
  the tether's reserve (rule 3: a U-turn sidesteps across its edge, and a robot at the
  end of its leash must still be able to turn), and one that turns back in the area of
  the vertex it arrived at backs out of it at once (that area is its own).

Its modes and the moves between them are in :mod:`algorithms.exploration.modes`.

Choices beyond the paper (the loop functions in :mod:`mjswarm.experiments.exploration` say the rest):

* **The speed rule applies on edges** (following a lane, Nagavarapu et al. Sec. 4 "traversing an
  edge"); in the vertex area robots move at S and are kept apart by vertex entry. A robot
  slowed by the rule while leaving a vertex would keep that vertex's area occupied,
  and at the vertex centre the rule's "beta = 0: stop" would stop a robot
  facing one that waits on the next vertex for this one: a deadlock.
* **Heading re-anchoring**: at a vertex whose beacon already stores angles
  (``Strategy.stored_angles``), the robot rotates its heading frame onto them
  (:func:`~algorithms.navigation.navigator.frame_offset`), so odometry drift does not
  accumulate over revisits and every robot keeps the beacons' frame. Frame fusion
  (ours): the robot that drops a beacon writes its frame's variance there
  (``Beacon.frame``: its heading variance plus a scan's), and a robot that has found slip
  turns only part of the way onto a stored frame, by the two variances, and moves the
  beacon's believed offset part of the way towards its own frame
  (:func:`~algorithms.navigation.navigator.fuse_frames`). The stored angles themselves
  never move: they name the vertex's edges in every robot's incidence matrix, matched
  within ``ANGLE_TOLERANCE``, and copies of them live in every matrix merged since.
* **Stopping for good**: lost its line, no beacon where it arrived, angles that match no
  beacon, a strategy that cannot reconcile a beacon, an entry denied, a vertex it was
  granted that closed while it was on its way, a strategy that cannot route round a
  closed vertex. It stands still, says why (``halted``) and tells the stations.
* **Closed vertices**: an entry blocked on its centre (:class:`~algorithms.exploration.
  entry.EntryBlocked`) is told to the strategy (``Strategy.block``) and decided anew.
* **Idle**: a strategy that answers IDLE is asked again after ``idle_wait_s``.
* **Queues**: a request on a centre ungranted for ``GIVE_UP_S`` is given up (:class:`~
  algorithms.exploration.entry.GiveUp`); once the station has dropped it
  (:class:`~algorithms.exploration.entry.EntryBusy`) the strategy plans round that edge
  (``Strategy.give_up``) and the robot asks for the new way.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

from algorithms.collision import CollisionRule
from algorithms.exploration.base import AngleMismatch, Decision, Strategy
from algorithms.exploration.events import (
    Declared,
    Infeasible,
    RelayTrip,
    SpeedChanged,
    SpeedRuleFired,
    Stopped,
    vertex_called,
)
from algorithms.exploration.relay import RELAY, ConnectedExplorer
from algorithms.exploration.leash import Leash
from algorithms.exploration.modes import (
    HOLDS_BEHIND,
    ON_LEG,
    RETURNING,
    TERMINAL,
    TRANSITIONS,
    WAITING,
    Mode,
)
from algorithms.exploration.passing import BodyWatch, PassGranted
from algorithms.exploration.tether import BASE, Tether
from algorithms.exploration.entry import (
    STATION,
    GIVE_UP_S,
    EntryBlocked,
    EntryBusy,
    EntryDenied,
    EntryGranted,
    EntryRequest,
    GiveUp,
    Halted,
    LeftVertex,
    TurnedBack,
    VertexClear,
    Withdraw,
)
from algorithms.navigation import (
    ArenaConventions,
    NavEvent,
    Navigator,
    NavigatorState,
    RobotCalibration,
)
from algorithms.navigation.navigator import SCAN_FRAME_VAR
from algorithms.navigation.percept import percept
from algorithms.robot import Command, Controller, Message, Observation


#: A relay stops this far short of where its requester stood on their lane (m): two body
#: diameters, so that a requester backing out of a wall's shadow does not reach it.
RELAY_SPACING_M = 0.3
#: The creep (ours, for dense teams): a robot on its lane that the speed rule has
#: held still this long (s) creeps on at ``CREEP_M_S`` (m/s) while its front IR sees
#: nothing nearer than ``CREEP_GUARD_M`` (m, from the chassis rim; the IR's cutoff is
#: 0.10 m, and at 5 cm/s the motors' 0.05 s ramp stops it within 3 mm).
CREEP_AFTER_S = 5.0
CREEP_M_S = 0.05
CREEP_GUARD_M = 0.06
#: A robot that waits at its wall's end for the vertex ahead to clear (vertex entry) backs
#: this far (m) along its lane, at ``CREEP_M_S``, from where it stopped (ours, for
#: dense teams). The arena places the wall's end so that a robot waiting there stands
#: 0.26 m from the vertex centre, clear of a robot leaving along a neighbouring edge
#: (:data:`mjswarm.arena.geometry.VERTEX_CLEAR_RADIUS_M`); but the wall's end is seen
#: after the IR's debounce and the stop takes the motors' ramp, and at 0.2 m/s robots
#: stop 0.236-0.239 m from the centre, where one can touch a robot leaving 90 degrees
#: away (``lattice:6x6``, 12 robots, 0.2 m/s, seed 2). The lane leads to the vertex the
#: robot holds, so nobody is behind it on it.
WAIT_BACKOFF_M = 0.04
#: A tethered robot stops short of a robot its ranging shows in its way, this far (m)
#: beyond touching (two body radii apart): its retrace and its U-turns run blind of the
#: speed rule (:meth:`Explorer._in_the_way`).
CLEARANCE_MARGIN_M = 0.03
#: A tethered robot that calls a relay while it still holds the vertex it is leaving gives
#: that vertex up once it has driven this far (m) from its centre (ours, for bodies): its
#: relay may need the very centre (where an edge turns a corner, a wall fades its links
#: as it reaches the corridor's mouth, about 0.3 m out, before it sees the corridor's
#: walls). Edges meet at 45 degrees or more, so a robot 0.25 m out along one is at least
#: 0.25 sin 45 = 0.18 m from any point of its neighbours' centre lines: more than two
#: body radii (0.15 m) from a robot on the centre or on its way to it.
CLEAR_BEHIND_M = 0.25
#: Where a tethered robot never backs its moves out (the leash's retrace forgets its trail):
#: on a vertex centre (it would scan off it) and on its way in to one. The arrival's
#: sidestep, seek and spoke are dead-reckoned moves of a plan the navigator resumes by
#: odometry; driven backwards and resumed, they end off the centre, where the robot finds
#: no spoke and is lost. A robot whose parent's link fades there stands, pinned. Nor off
#: the start of its lane: the trail is forgotten where it finds its lane. The leaving's
#: turns in place are no moves of the trail, so backed out past them it drives straight
#: back along the lane's line, and resumed off every strip it loses its lane (``lattice:
#: 3x3``, 3 robots at 1.2 m, connected, seed 1: backed 23 cm, past the centre's line).
#: Nor in a U-turn on its lane (:data:`U_TURNING`): its turn and shift are dead-reckoned
#: too, and a U-turn backed out part-way and resumed ended 25 cm off its lanes, lost
#: (``tri:2x3``, 4 robots at 2 m, connected, seed 2, 0.15 m/s).
NO_BACKING = frozenset({NavigatorState.ARRIVING, NavigatorState.SCANNING,
                        NavigatorState.AT_VERTEX})
#: The explorer's mode while its navigator U-turns onto the opposite lane.
U_TURNING = Mode.WALKING_BACK_UNTOLD


class VertexCall(NamedTuple):
    """One call of the strategy at a vertex: when, the beacon's id (never the beacon: a
    handle works only in the tick it was handed out), whether the robot had just arrived
    by an edge (else: a launch or an idle wake-up), and the decision."""

    time_s: float
    beacon_id: Any
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
        self.control_dt_s = control_dt_s
        #: its connected exploration (rules 1-6) around ``strategy``; None without a tether
        self.connected = None if tether is None else ConnectedExplorer(
            tether.me, strategy, tether, spacing=RELAY_SPACING_M, clear=CLEAR_BEHIND_M)
        #: its leash against walls (None without a tether)
        self.leash = None if tether is None else Leash(tether)
        #: passing bodies on its lane (None where it does not pass: tethered, or no radius)
        self.body_watch = (BodyWatch(calibration.body_radius_m)
                           if tether is None and calibration.body_radius_m is not None
                           else None)
        self.nav = Navigator(calibration, conventions, 0.0, speed_m_s, turn_rate_rad_s)
        #: what it is doing (:class:`Mode`)
        self.mode = Mode.SCANNING
        #: every vertex call so far (for the loop functions' metrics and recordings)
        self.calls: list[VertexCall] = []
        #: why it stopped for good, or None
        self.halted: str | None = None
        #: its speed in the last tick (m/s): the rule's on a lane, else S
        self.speed_m_s = speed_m_s
        self._left_at_m = 0.0  # odometry distance where it left its vertex
        #: whether the vertex it goes to is clear of its previous holder (the stations'
        #: last word: EntryGranted, VertexClear)
        self._ahead_clear = True
        #: this tick's report to rule 6: it wanted to move, and the speed rule or vertex
        #: entry held it (or it waits for its grant)
        self._held = False
        self._handled = 0
        self._idle_since = -math.inf  # when its strategy answered idle (s)
        self._departure: float | None = None  # angle of the edge it waits to take
        self._asked: EntryRequest | None = None  # its request, until it departs
        self._asked_at_s = 0.0  # when it sent that request (s)
        self._trips = 0  # relay missions it has set out on (rule 6)
        self._nav_then = self.nav.state  # its navigator's state in its last tick on the leash
        self._events: list = []  # what it reports this tick (``Command.events``)
        self._said_speed = speed_m_s  # its speed as last reported
        self._held_still_s = 0.0  # how long the speed rule has held it still on its lane
        self._wait_from_m: float | None = None  # odometry distance where it began to wait
        self._said_way_on_closed = False  # asking to turn, it told the stations so

    @property
    def finished(self) -> bool:
        """Whether its strategy finished: declared the exploration complete, or finished
        the part it can reach, cut off from the root (``CUT_OFF``)."""
        return self.mode is Mode.FINISHED

    @property
    def infeasible(self) -> bool:
        """Whether its tether declared the exploration infeasible (rule 5)."""
        return self.mode is Mode.INFEASIBLE

    def _enter(self, mode: Mode) -> None:
        """Move to ``mode``: only along :data:`TRANSITIONS` (or to HALTED / INFEASIBLE
        from any mode not terminal)."""
        old = self.mode
        if mode not in TRANSITIONS.get(old, {}) and not (
                mode in (Mode.HALTED, Mode.INFEASIBLE) and old not in TERMINAL):
            raise RuntimeError(f"an explorer cannot go from {old.value} to {mode.value}")
        self.mode = mode

    def reset(self) -> None:
        """Put on a vertex centre (a launch): scan, then call the strategy."""
        self.nav.begin_at_vertex()

    def step(self, observation: Observation) -> Command:
        """This tick's command, with what it reports (:mod:`algorithms.exploration.events`)."""
        command = self._step(observation)
        if self.speed_m_s != self._said_speed and self.nav.on_lane:
            self._events.append(SpeedChanged(self._said_speed, self.speed_m_s))
        self._said_speed = self.speed_m_s
        if self._events:
            command = command._replace(events=tuple(self._events))
            self._events = []
        return command

    def _step(self, observation: Observation) -> Command:
        out: list[Message] = []
        now = round(observation.time_s / self.control_dt_s)
        if self.table is not None:
            robots = [m for m in observation.inbox if m.sender != STATION]
            out += self.table.tick(now, robots, observation.neighbors)
        if self.mode not in TERMINAL:
            for m in observation.inbox:
                if m.sender == STATION:
                    self._from_station(m.payload, out, observation)
        around = {}
        if self.tether is not None:
            around = {j: (d.range_m * math.cos(d.bearing_rad), d.range_m * math.sin(d.bearing_rad))
                      for j, d in observation.detections.items()}
            self._hear(now, observation, around, out)
        if self.mode in TERMINAL:
            if self.connected is not None:
                self.connected.retire()  # it serves as nobody's relay
            return self._stand(now, out, around)
        if self.leash is not None and self.leash.cut_off(around):
            command = self._retrace(now, out, around, observation)
        else:
            command = self._drive(observation, out)
            if self.tether is None:
                return command
            command = self._on_leash(now, command, around)
        if self.tether.stalled(now):  # rule 5 (a robot whose parent failed judges it too)
            self._events.append(Infeasible())
            if self.mode not in TERMINAL:
                self._enter(Mode.INFEASIBLE)
        return command

    # -- connected exploration on bodies (rules 1-6) ----------------------------------------
    def _hear(self, now: int, observation: Observation, around, out: list[Message]) -> None:
        """Its connected exploration reads the radio; what rule 6 asks of vertex entry."""
        tied = [m for m in observation.inbox if m.sender != STATION]
        # leaving a vertex (granted the next one) it adopts nobody, it would hold both;
        # unless it relays there (a relay's last leg may end on the centre it leaves)
        willing = self.mode not in HOLDS_BEHIND or self.connected.mode == RELAY
        out += self.connected.hear(now, tied, around, willing=willing)
        if self.mode is Mode.WITHDRAWN and not self.tether.holds():
            self._enter(Mode.ASKING)  # free to go: ask again
            out.append(Message(self._asked, STATION))
        if self.connected.relay_trips != self._trips:
            self._trips = self.connected.relay_trips
            self._events.append(RelayTrip())
            self._set_out(observation, out)
        elif self.mode in WAITING and self.connected.mode == RELAY:
            self._set_out(observation, out)  # held on its way on a centre: it relays here

    def _on_leash(self, now: int, command: Command, around) -> Command:
        """Rules 3-6 on this tick's command: it stands where the leash (or a wall it met
        on this leg) forbids its drive, or a robot its ranging shows stands in its way
        (the speed rule governs lanes only, and U-turns and walks back leave them), then
        asks and beats."""
        moving = command.v_m_s != 0.0
        if moving and self._in_the_way(around, command.v_m_s):
            command, moving = Command(messages=command.messages), False
        if self.nav.state is NavigatorState.ON_EDGE and self._nav_then is not self.nav.state:
            self.leash.forget()  # on its lane: never backed off the lane's start
        self._nav_then = self.nav.state
        wanted = self.leash.check(
            (command.v_m_s, command.omega_rad_s) if moving else None,
            (command.v_m_s * self.control_dt_s, 0.0), around, back=self.mode in RETURNING,
            no_backing=self.nav.state in NO_BACKING or self.mode is U_TURNING)
        if wanted is not None:
            command = Command(messages=command.messages)
        out = list(command.messages)
        out += self.connected.after(now, wanted, command.v_m_s != 0.0, around, self._held,
                                    self.leash.cut_on_this_way(self.mode in RETURNING))
        self._give_up_behind(out)
        self._say_way_on_closed(out)
        return command._replace(messages=tuple(out))

    def _give_up_behind(self, out: list[Message]) -> None:
        """Leaving a vertex, it calls a relay (rule 6), or relays from its lane: once
        ``CLEAR_BEHIND_M`` out, it gives that vertex up (LeftVertex), so that a relay may
        take its centre and others pass through it; it never backs into it again (its
        trail is forgotten)."""
        if (self.mode is Mode.LEAVING
                and (self.connected.calls_relay or self.connected.mode == RELAY)
                and self.nav.odometry.distance_m - self._left_at_m >= CLEAR_BEHIND_M):
            self._leave_behind(out)

    def _say_way_on_closed(self, out: list[Message]) -> None:
        """Asking to turn back into the area it is leaving, with its way on closed by a
        wall (its leash): it tells the stations once (:class:`~algorithms.exploration.
        entry.TurnedBack` ``way_on_closed``). In a swap it would otherwise wait for an
        answer that never comes while it cannot go on, and the robot given its vertex
        would wait for it to leave: the stations undo the swap (entry step 5)."""
        if (self.mode is Mode.TURN_ASKED_LEAVING and not self._said_way_on_closed
                and self.leash.cut_on_this_way(back=False)):
            self._said_way_on_closed = True
            out.append(Message(TurnedBack(from_lane=False, way_on_closed=True), STATION))

    def _set_out(self, observation: Observation, out: list[Message]) -> None:
        """Rule 6: it accepted a relay mission. On an edge its plan starts with the walk
        back; on a centre where it waits for a grant it withdraws its request (the leg
        it had decided on is walked back at once: it never left) and decides anew."""
        if self.mode not in WAITING:
            if self.mode is Mode.IDLE:
                self._idle_since = -math.inf  # idle: it sets out at once
            return
        if self.rule is not None:
            out.append(Message(Withdraw(), STATION))
        self._departure, self._asked = None, None
        self.connected.arrived_back()
        self._enter(Mode.DECIDING)
        # it stands where it made its last call, and reads that beacon now (the station
        # serves it to the robot it granted the vertex, or is letting leave it)
        self._vertex_call(observation.beacon, observation.time_s, False, out, back=True)

    def _retrace(self, now: int, out: list[Message], around,
                 observation: Observation) -> Command:
        """A parent's link is gone (a wall came between them: the leash knows ranges, not
        walls): drive its last moves backwards until the link is back, then wait for a new
        parent as if the leash had stopped it (so also on its leg with no move left to
        undo, the link still gone; on a vertex centre it waits at once: a robot backed
        out of the centre it scans on would scan off it, find no beacon and stop). Its
        navigator counts these ticks on its odometry (:meth:`~algorithms.navigation.
        Navigator.carried`), so that its motion resumes from where the body is."""
        self.nav.carried(self._percept(observation))
        back = self.mode in RETURNING
        move = self.leash.undo(around, back, lambda vw: (-vw[0], -vw[1]),
                               may=lambda vw: not self._in_the_way(around, -vw[0]))
        if move is None and self.mode in ON_LEG:  # nothing left to undo: the wall stops it
            step = ((-1.0 if back else 1.0) * self.cruise_m_s * self.control_dt_s, 0.0)
            out += self.connected.after(now, step, False, around, False,
                                        self.leash.cut_on_this_way(back), pinned=True)
            self._give_up_behind(out)
            self._say_way_on_closed(out)
            return Command(messages=tuple(out))
        if move is None:
            return self._stand(now, out, around)
        out.append(self.tether.beat(now, True, False, len(self.strategy.map_edges())))
        return Command(*move, messages=tuple(out))

    def _in_the_way(self, around, v_m_s: float) -> bool:
        """Whether a robot its ranging shows (``around``: position in its own frame, m;
        the base's mast is no body)
        stands in the way of a drive at ``v_m_s`` (forwards or backwards): on that side,
        across less than two body radii, nearer than two radii and ``CLEARANCE_MARGIN_M``.
        A tethered robot checks this before each drive (:meth:`_on_leash`) and each move
        of its retrace, which runs blind of the speed rule, often backwards, where its
        bearing sensor and IR do not look."""
        reach = 2.0 * (self.nav.cal.body_radius_m or 0.0)
        return any(j != BASE and x * v_m_s > 0.0 and abs(y) < reach
                   and math.hypot(x, y) < reach + CLEARANCE_MARGIN_M
                   for j, (x, y) in around.items())

    def _stand(self, now: int, out: list[Message], around) -> Command:
        """Stand still (stopped, done, infeasible, or cut off with no move to undo); a
        tethered robot keeps beating, so that its children and the stall gossip go on."""
        if self.tether is not None:
            out += self.tether.ask(now, None, around)
            out.append(self.tether.beat(now, False, False, len(self.strategy.map_edges())))
        return Command(messages=tuple(out))

    # -- driving ----------------------------------------------------------------------------
    def _drive(self, observation: Observation, out: list[Message]) -> Command:
        """Navigator, vertex calls, the speed rule and vertex entry: this tick's command."""
        nav, sense = self.nav, self._sense(out)
        v, w = nav.update(self._percept(observation))
        self._on_events(observation, out)
        if self.mode in TERMINAL:
            return Command(messages=tuple(out))
        if sense == 0:  # rule 6: a relay, or waiting to: it stands on its edge
            v = w = 0.0
        speed = self.cruise_m_s
        if self.rule is not None:
            speed = self._speed_rule(observation)
            if self._queued_too_long(observation.time_s):
                self._enter(Mode.GIVING_UP)
                out.append(Message(GiveUp(), STATION))
            self._tell_stations(out)
            back = self._wait_ahead(speed)
            if back is not None:
                speed = 0.0
                if back:
                    self.speed_m_s, self._held = 0.0, True
                    return Command(back, 0.0, messages=tuple(out))
            self._watch_for_body(observation, speed, out)
        self.speed_m_s = speed
        # held: the speed rule or vertex entry stops it, or it waits for its grant
        self._held = (v != 0.0 and speed == 0.0) or self.mode in WAITING
        if v != 0.0:  # translations run at the rule's speed; turns in place do not
            factor = speed / self.cruise_m_s
            v, w = v * factor, w * factor
        return Command(v, w, messages=tuple(out))

    def _percept(self, observation: Observation):
        """This tick's readings as its navigator reads them (its line filter)."""
        return percept(observation.line_m, observation.ir_m, observation.encoder_rad,
                       self.nav.line_filter)

    def _speed_rule(self, observation: Observation) -> float:
        """Its speed (m/s) by the rule on a lane (with the creep), S elsewhere."""
        if not self.nav.on_lane:  # the rule governs edge traversals
            self.rule.forget_bearings()
            self._held_still_s = 0.0
            return self.cruise_m_s
        fired = self.rule.activations
        speed = self._creep(self.rule.update(self.nav.lane_bearings(observation.bearings)),
                            observation.ir_m)
        if self.rule.activations != fired:
            self._events.append(SpeedRuleFired(self.rule.activations - fired))
        return speed

    def _tell_stations(self, out: list[Message]) -> None:
        """What vertex entry owes the stations as the robot moves: LeftVertex once in its
        corridor, TurnedBack once on its new lane after a U-turn (a vertex area it gives
        up is one it never backs into: :meth:`_retrace`)."""
        nav = self.nav
        if self.mode in HOLDS_BEHIND and nav.in_corridor:  # clear of the vertex it left
            self._leave_behind(out)
        if self.mode is Mode.WALKING_BACK_UNTOLD and nav.on_lane:  # out of the area ahead
            out.append(Message(TurnedBack(from_lane=True), STATION))
            self._enter(Mode.WALKING_BACK)
            self._forget_trail()

    def _leave_behind(self, out: list[Message]) -> None:
        """It gives up the vertex it left (LeftVertex), and never backs into it again."""
        out.append(Message(LeftVertex(), STATION))
        self._enter(Mode.ON_LANE if self.mode is Mode.LEAVING else Mode.TURN_ASKED)
        self._forget_trail()

    def _forget_trail(self) -> None:
        if self.leash is not None:
            self.leash.forget()

    def _wait_ahead(self, speed: float) -> float | None:
        """Waiting for the vertex ahead (its previous holder is still leaving it), at
        the wall's end: None when it need not wait, else its speed (m/s: 0, or backwards
        while it backs off). One that turned back waits as soon as it follows its new
        lane, which may carry a robot arriving at that vertex ahead of it (one that turns
        back in the area it arrived at backs out of it: that area is its own)."""
        nav, returning = self.nav, self.mode in RETURNING
        if self._ahead_clear or not (nav.on_lane if returning else nav.at_vertex_area):
            self._wait_from_m = None
            return None
        if nav.on_lane and not returning:
            return self._back_off()
        return 0.0

    def _queued_too_long(self, now_s: float) -> bool:
        """Whether it gives up its place in a queue now (:mod:`~algorithms.exploration.
        entry`, step 8): on a centre, its request ungranted for ``GIVE_UP_S``, its
        strategy able to plan round the edge. A tethered robot does not: its waits belong
        to its tether's rules."""
        return (self.mode is Mode.ASKING and self.connected is None and self.strategy.replans
                and now_s - self._asked_at_s >= GIVE_UP_S)

    def _back_off(self) -> float:
        """Its speed (m/s, negative: backwards) while it waits at its wall's end for the
        vertex ahead: back along its lane until ``WAIT_BACKOFF_M`` from where it stopped."""
        travelled = self.nav.odometry.distance_m
        if self._wait_from_m is None:
            self._wait_from_m = travelled
        if travelled > self._wait_from_m - WAIT_BACKOFF_M:
            return -min(CREEP_M_S, self.cruise_m_s)
        return 0.0

    def _watch_for_body(self, observation: Observation, speed: float,
                        out: list[Message]) -> None:
        """A body that stands on its lane for good, seen with its own senses: it asks to
        pass it (:mod:`algorithms.exploration.passing`)."""
        if self.body_watch is None:
            return
        front = observation.ir_m[1] if observation.ir_m is not None else math.nan
        asked = self.body_watch.watch(observation.time_s, front,
                                      self.nav.on_lane and speed == 0.0, observation.detections)
        if asked is not None:
            out.append(Message(asked, STATION))

    def _sense(self, out: list[Message]) -> int:
        """Rule 6 on an edge: +1 on, 0 stand, -1 back. A walk back starts at once on its
        lane (a U-turn; the stations hear of it once it follows its new lane) or without
        vertex entry; nearer the vertex behind (a U-turn there would reach into its area),
        once the station gives it that vertex (if it gave it to another robot in a swap,
        it goes on, and turns farther along)."""
        cx = self.connected
        if cx is None or self.mode not in ON_LEG:
            return 1
        sense = cx.direction(self.nav.odometry.distance_m - self._left_at_m)
        if sense < 0 and self.mode not in RETURNING:
            self._walk_back(out)
            if self.mode not in RETURNING:
                return 1
        return sense

    def _walk_back(self, out: list[Message]) -> None:
        """Turn back along its edge: at once on its lane (a U-turn) or without vertex
        entry; nearer the vertex behind, once the station gives it that vertex back."""
        nav = self.nav
        if self.rule is None or nav.room_to_turn or nav.state is NavigatorState.ARRIVING:
            self._turn_back(granted=self.rule is None)
        elif self.mode in (Mode.LEAVING, Mode.ON_LANE):
            self._enter(Mode.TURN_ASKED_LEAVING if self.mode is Mode.LEAVING
                        else Mode.TURN_ASKED)
            self._said_way_on_closed = False
            out.append(Message(TurnedBack(from_lane=False), STATION))

    def _turn_back(self, granted: bool) -> None:
        """Start the walk back (``granted``: the vertex behind is its own already)."""
        self.nav.turn_back()
        self._enter(Mode.WALKING_BACK if granted else Mode.WALKING_BACK_UNTOLD)
        self._ahead_clear = granted
        if self.rule is not None:
            self.rule.crossed_vertex()  # a new traversal begins: eq. (34)

    def telemetry(self) -> dict[str, float]:
        """Its speed (m/s), vertex calls so far, whether it is stopped for good, its
        odometry's heading (rad, its own frame: the beacons'), whether it follows a lane
        between two vertices (1.0) and, with a connectivity table, whether the table
        believes it biconnected to the reference (1.0)."""
        out = {"speed_m_s": self.speed_m_s, "vertex_calls": len(self.calls),
               "halted": float(self.halted is not None),
               "heading_rad": self.nav.odometry.theta,
               "on_edge": float(self.nav.state is NavigatorState.ON_EDGE)}
        if self.table is not None:
            out["biconnected"] = float(self.table.is_doubly_connected())
        return out

    def _creep(self, speed: float, ir_m) -> float:
        """The rule's ``speed`` (m/s), or ``CREEP_M_S`` once the rule has held the robot
        still on its lane for ``CREEP_AFTER_S`` and its front IR sees nothing within
        ``CREEP_GUARD_M``.

        Nagavarapu et al.'s rule stops a robot for one whose bearing stays in its same-lane cone
        and does not change, and resumes when it changes. Bearings carry no range: a robot
        standing on the centre of the vertex beyond the next, waiting for the vertex this
        robot holds, can fall within the cone of a robot whose nose (and so its estimate of
        its lane's direction, early on the lane) is a few degrees off, and then neither
        ever moves (``lattice:6x6``, 8 robots, 0.15 m/s, seed 1: the cone was 2.6 degrees,
        the robot seen at 2.5). A robot on its lane is the only one on that lane (vertex
        entry, :mod:`mjswarm.experiments.stations`), so a long stop is such a phantom, and
        creeping on, guarded by the front IR, breaks the wait: its own motion changes the
        bearing, and the rule lets it go on or stops it anew. A body truly ahead is seen
        by the IR first."""
        if speed > 0.0:
            self._held_still_s = 0.0
            return speed
        self._held_still_s += self.control_dt_s
        front = ir_m[1] if ir_m is not None else math.nan
        clear = math.isnan(front) or front > CREEP_GUARD_M
        return min(CREEP_M_S, self.cruise_m_s) if (
            self._held_still_s >= CREEP_AFTER_S and clear) else 0.0

    # -- events and vertex calls -----------------------------------------------------------
    def _on_events(self, observation: Observation, out: list[Message]) -> None:
        nav = self.nav
        new = nav.events[self._handled:]
        self._handled = len(nav.events)
        for event in new:
            if event.kind is NavEvent.ARRIVED:
                if self.rule is not None:
                    self.rule.crossed_vertex()  # eq. (34)
                back = self.mode in RETURNING
                self._enter(Mode.DECIDING)
                if back and self.connected is not None:
                    self.connected.arrived_back()
                # the scan right after a launch is no arrival: the robot came by no edge;
                # nor is a walk back (it traversed none)
                self._vertex_call(observation.beacon, observation.time_s,
                                  nav.arrived_angle is not None, out, back)
            elif event.kind is NavEvent.LOST:
                self._halt(str(event), out)
            elif event.kind is NavEvent.PASSED:
                out.append(Message(self.body_watch.passed(), STATION))
        if (self.mode is Mode.IDLE
                and observation.time_s - self._idle_since >= self.idle_wait_s):
            self._enter(Mode.DECIDING)
            self._vertex_call(observation.beacon, observation.time_s, False, out)

    def _vertex_call(self, beacon, now_s: float, arrived: bool, out: list[Message],
                     back: bool = False) -> None:
        """The strategy's vertex call (through its connected exploration, if any): beacon
        in, decision out. ``back``: it walked back to this vertex (rule 6)."""
        nav, cx = self.nav, self.connected
        if beacon is None:
            self._halt("no beacon where it arrived (off the vertex centre, or not the "
                       "vertex it was granted)", out)
            return
        # a walk back traversed no edge: only a tether's rules need to know it came back
        arrived_by = nav.arrived_angle if arrived and (cx is not None or not back) else None
        try:
            if cx is None:
                decision = self.strategy.on_vertex(beacon, nav.edge_angles, arrived_by)
            else:
                cx.arrive(beacon, nav.edge_angles, arrived_by)
                decision = cx.on_vertex(beacon, nav.edge_angles, arrived_by)
        except AngleMismatch as exc:  # its heading reference is broken (e.g. after a crash)
            self._halt(f"its angles match no edge of the beacon: {exc}", out)
            return
        except ValueError as exc:  # a beacon it cannot reconcile (e.g. a wiped one)
            self._halt(f"its strategy failed: {exc}", out)
            return
        self._reanchor(beacon, cx is None or cx.consulted)
        self.calls.append(VertexCall(now_s, beacon.id, arrived and not back, decision))
        mapped = tuple(self.strategy.map_edges())
        self._events.append(vertex_called(arrived and not back, decision, beacon, mapped))
        self._decided(decision, now_s, mapped, out)

    def _reanchor(self, beacon, consulted: bool) -> None:
        """Heading re-anchoring on a beacon that stores angles; a new beacon gets its
        dropper's frame (module docstring)."""
        nav = self.nav
        if consulted and self.strategy.stored_angles is not None:
            nav.reanchor(self.strategy.stored_angles, beacon.frame)
            if nav.beacon_frame is not None:
                beacon.frame = nav.beacon_frame
        elif self.strategy.stored_angles is None and beacon.frame is None:
            # it dropped the beacon: its angles are in its own frame, as sure as its heading
            beacon.frame = (0.0, nav.heading_variance + SCAN_FRAME_VAR)

    def _decided(self, decision: Decision, now_s: float, mapped: tuple,
                 out: list[Message]) -> None:
        """The mode a decision leads to, and what it tells the stations."""
        if decision.action == "go":
            self._departure = min(self.nav.edge_angles, key=lambda a: abs(
                math.remainder(a - decision.angle, 2 * math.pi)))
            if self.rule is None:
                self._depart(Mode.ON_LANE)
            else:
                cx = self.connected
                self._asked = EntryRequest(decision.angle, cx is not None and cx.stops_part_way)
                self._asked_at_s = now_s
                self._enter(Mode.ASKING)
                out.append(Message(self._asked, STATION))
        elif decision.action == "idle":
            self._idle_since = now_s
            self._enter(Mode.IDLE)
        elif decision.action == "done":
            self._enter(Mode.FINISHED)
            self._events.append(Declared(mapped))
        elif decision.action == "cut off":  # it stands for good; VertexCalled tells
            self._enter(Mode.FINISHED)
            if self.rule is not None:  # a body for good on a centre: that vertex closes
                out.append(Message(Halted("cut off from the root, its part finished"),
                                   STATION))
        else:
            raise ValueError(f"the strategy answered an unknown decision {decision!r}")

    # -- the stations' answers (vertex entry, passing) --------------------------------------
    def _from_station(self, payload: Any, out: list[Message], observation: Observation) -> None:
        if isinstance(payload, EntryGranted):
            self._granted(payload, out)
        elif isinstance(payload, VertexClear):
            self._ahead_clear = True
        elif isinstance(payload, PassGranted):
            done = self.body_watch.granted(self.nav.on_lane, self.nav.pass_body)
            if done is not None:  # no longer where it asked: the lane is free
                out.append(Message(done, STATION))
        elif isinstance(payload, EntryDenied):
            self._halt(payload.reason, out)
        elif isinstance(payload, EntryBlocked):
            self._blocked(payload, out, observation)
        elif isinstance(payload, EntryBusy):
            if self.mode is Mode.GIVING_UP and payload.angle_rad == self._asked.angle_rad:
                # it gave up its place: it plans anew where it stands, round that edge
                self.strategy.give_up(payload.angle_rad)
                self._departure, self._asked = None, None
                self._enter(Mode.DECIDING)
                self._vertex_call(observation.beacon, observation.time_s, False, out, back=True)

    def _granted(self, payload: EntryGranted, out: list[Message]) -> None:
        """EntryGranted: the lane it asked for (it departs, or gives a clear grant back
        while it has children: rule 2), or the vertex behind it asked to return to."""
        if payload.angle_rad is not None and (
                self._asked is None or payload.angle_rad != self._asked.angle_rad):
            return  # a grant its withdrawal overtook
        self._ahead_clear = payload.clear
        if self.mode in (Mode.TURN_ASKED, Mode.TURN_ASKED_LEAVING):
            self._turn_back(granted=True)  # it may return to the vertex it is leaving
        elif self.mode is Mode.WALKING_BACK_UNTOLD:  # it turned meanwhile: no lane request
            self._enter(Mode.WALKING_BACK)
        elif self.mode in WAITING:
            if payload.clear and self.tether is not None and self.tether.holds():
                if self.mode is not Mode.WITHDRAWN:
                    self._enter(Mode.WITHDRAWN)
                out.append(Message(Withdraw(), STATION))  # it must hold: give it back
            else:
                self._depart(Mode.LEAVING)

    def _blocked(self, payload: EntryBlocked, out: list[Message],
                 observation: Observation) -> None:
        """The vertex it asked for is closed (:mod:`algorithms.exploration.entry`, step 7).
        Waiting on its centre, it tells its strategy the edge is blocked and decides anew
        there (the vertex call is re-run with the beacon it stands on, as a relay setting
        out does). On its way (granted before the vertex closed; the station tells it once
        it is out of every vertex area) it tells its strategy too, and walks back to the
        vertex it left as rule 6's relays do (:meth:`_walk_back`; its arrival there is no
        traversal, and it decides anew); a tethered robot, whose walks back belong to its
        tether, stops for good there instead, on a lane that leads only into the closed
        vertex. One whose way back closed (the vertex it walks back to, or asked for) stops
        for good. An answer its withdrawal overtook is ignored."""
        if self.mode in ON_LEG:
            if self.connected is not None:
                self._halt("the vertex it was granted closed (a body stopped in its area)", out)
            elif self.mode in RETURNING or payload.angle_rad is None:
                self._halt("the vertex it walks back to closed (a body stopped in its "
                           "area)", out)
            elif self._block(payload.angle_rad, out):
                self._walk_back(out)
            return
        if self.mode not in WAITING or payload.angle_rad != self._asked.angle_rad:
            return
        if not self._block(payload.angle_rad, out):
            return
        self._departure, self._asked = None, None
        if self.connected is not None:
            self.connected.arrived_back()  # it never left: its leg is undone
        self._enter(Mode.DECIDING)
        self._vertex_call(observation.beacon, observation.time_s, False, out, back=True)

    def _block(self, angle_rad: float, out: list[Message]) -> bool:
        """Tell its strategy the edge at ``angle_rad`` is blocked; False if it cannot (it
        stops for good)."""
        try:
            self.strategy.block(angle_rad)
        except NotImplementedError as exc:
            self._halt(str(exc), out)
            return False
        return True

    def _depart(self, mode: Mode) -> None:
        """Leave along ``_departure``: LEAVING (granted: it holds the vertex it leaves
        until in its corridor) or ON_LANE (without vertex entry)."""
        self.nav.depart(self._departure)
        self._departure, self._asked = None, None
        self._left_at_m = self.nav.odometry.distance_m
        self._enter(mode)
        if self.leash is not None:
            self.leash.new_leg()  # a new leg: new walls

    def _halt(self, reason: str, out: list[Message]) -> None:
        if self.mode not in TERMINAL:
            self.halted = reason
            self._enter(Mode.HALTED)
            self._events.append(Stopped(reason))
            if self.rule is not None:
                out.append(Message(Halted(reason), STATION))
