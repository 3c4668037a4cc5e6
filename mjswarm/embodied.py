"""Embodied exploration: the graph strategies on MuJoCo robots (issue 5).

Every robot runs three pieces of its own mind, fed only by its own sensors:

* a :class:`~algorithms.navigation.Navigator` (lane following, vertex detection by IR,
  edge discovery by scanning the spokes, odometry),
* an exploration :class:`~algorithms.exploration.Strategy` (the same code as the graph
  world), called at every vertex arrival with the beacon there and the angles the robot
  measured,
* a :class:`~algorithms.collision.CollisionRule` (seed 003 Sec. 4) that sets its linear
  speed from the bearings its bearing sensor reports.

This module is the "loop functions" side (ARGoS's term): it owns the beacons, launches
robots, records and measures. Choices it makes, beyond the paper:

* **Beacons** are a store keyed by the arena's vertex (seed 003 emulated beacons with a
  central station over XBee, "separate information for each vertex"; so do we). A robot
  reads and writes the beacon only during its vertex call, i.e. while it stands on the
  vertex centre; the world finds which vertex that is from ground truth, as the station
  knew which vertex was calling.
* **The speed rule applies on edges** (following a lane, seed 003 Sec. 4 "traversing an
  edge"); in the vertex area (turns, scans, the sidesteps between lane and vertex
  centre, finding the lane) robots move at S and are kept apart by vertex entry. A robot
  slowed by the rule while it leaves a vertex would keep that vertex's area occupied
  (issue 13: a robot leaving ``v7`` of ``fig9`` at 3 mm/s, slowed for the robot that was
  swapping vertices with it, was run into by it). Applied at the vertex
  centre too, the rule's "beta = 0: stop" would stop a robot facing a robot on the next
  vertex along its edge, which may be waiting to enter this vertex: a deadlock.
* **Vertex entry** (our addition, needed once robots have bodies): a vertex area holds
  one robot at a time; a robot decides on a vertex centre, asks the vertex stations for
  the vertex at the far end of its edge and leaves once granted
  (:mod:`mjswarm.stations`, which also explains why no circular wait can form).
  ``--no-collision-avoidance`` turns this off together with the speed rule.
* **Heading re-anchoring**: at a vertex whose beacon already stores angles
  (``Strategy.stored_angles``), the robot rotates its heading frame onto them
  (:func:`~algorithms.navigation.navigator.frame_offset`: the mean offset over all the
  vertex's edges). Odometry drift then no longer accumulates over revisits, and every
  robot keeps the frame of the beacons; ``heading_error_deg`` in the result is the
  largest odometry heading error of any robot over the run (ground truth, never seen by
  robots).
* **Robots that stop** (lost their line, not on a vertex centre after arriving, angles
  that match no beacon, a fault) release every vertex they hold, stay where they are as
  obstacles (a vertex whose area the body still occupies stays closed) and are listed in ``stopped_robots`` with the reason and the time. A run ends
  early, not completed, when no robot has reached a vertex for ``stall_timeout_s``
  (``ended_because``: ``"completed"``, ``"stalled"``, ``"all robots stopped"`` or
  ``"max time"``).
* **Launching from the root**: robots wait in a depot outside the arena and are put on the
  root centre one at a time (as the paper's robots were placed by hand), in ``launch_order``,
  at least ``launch_interval_s`` apart, whenever the root is free. Each starts with compass
  heading 0 along the world's +x, the common reference direction of the incidence angles.
* **Metrics**: ``makespan`` is the largest number of edges any robot had traversed when
  completion was declared (the synchronous world's step count; seed 003 counts "edge
  traversals"), ``total_traversals`` the sum; ``collisions`` are robot-robot contact events
  (ground truth, never seen by robots); ``speed_changes`` the collision rule's activations
  (eq. 27).
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from algorithms.collision import PAPER_SPEED_M_S, CollisionRule, epsilons
from algorithms.exploration import Beacon, Strategy
from algorithms.exploration.base import AngleMismatch
from algorithms.navigation import NavEvent, NavigatorState
from mjswarm.arena import ArenaSpec
from mjswarm.arena.geometry import LANE_OFFSET_M, VERTEX_CLEAR_RADIUS_M
from mjswarm.arena.builder import arena_world_spec
from mjswarm.awareness import TableAwareness
from mjswarm.bearing import BearingSensor
from mjswarm.errors import MjswarmError
from mjswarm.faults import Fault
from mjswarm.graphworld import ExplorationResult, make_minds, outcome
from mjswarm.navigation import NavigationDriver, percepts
from mjswarm.simulation import Simulation
from mjswarm.stations import VertexStations
from mjswarm.world import Pose2D

#: A robot is on a vertex when within this distance of its centre (m).
ON_VERTEX_M = 0.05
#: The root counts as free for a launch when no active robot is this close to it (m).
ROOT_CLEAR_M = 0.35
DEPOT_SPACING_M = 0.4
DEPOT_OFFSET_M = 1.5
#: The stations map a robot's departure angle to an edge only within this (rad): half
#: the 45 degree minimum angle between edges at a vertex.
DEPARTURE_TOLERANCE_RAD = math.radians(22.5)
#: Default stall timeout: at least this long (s), and at least STALL_EDGE_FACTOR times
#: the time to drive the longest edge at the run's speed.
STALL_MIN_S = 300.0
STALL_EDGE_FACTOR = 10.0
#: Wall seconds between status lines when progress goes to a log, not a terminal.
STATUS_EVERY_S = 30.0


@dataclass
class EmbodiedConfig:
    """Parameters of an embodied run (SI units).

    Attributes:
        speed_m_s: the initial speed S of every robot (seed 003's experiments: 0.05).
        collision_avoidance: the speed rule and vertex entry (see module doc).
        epsilons: per-robot eps_k (eq. 28); default :func:`algorithms.collision.epsilons`.
        launch_interval_s: least time between two launches from the root.
        launch_order: robot indices in launch order (default 0, 1, ...).
        idle_wait_s: how long a robot whose strategy answered IDLE waits before asking again.
        max_sim_time_s: give up after this much simulated time.
        stall_timeout_s: end the run early when no robot has reached a vertex for this
            long (s); None: ``max(STALL_MIN_S, STALL_EDGE_FACTOR * longest edge / speed)``.
        turn_rate_rad_s: in-place turn and scan rate.
        bearing_fov_deg, bearing_range_m, bearing_noise_deg: the bearing sensor.
        radio_range_m: with a range (m), robots carry radios and keep connectivity tables
            (:mod:`mjswarm.awareness`); None: no radio.
        faults: injected faults (:mod:`mjswarm.faults`).
        line_noise_m, ir_noise_m: standard deviation of the line and IR rangefinders'
            Gaussian noise (m).
        wheel_slip: scale of the wheel-slip model (:class:`mjswarm.simulation.Simulation`).
    """

    speed_m_s: float = PAPER_SPEED_M_S
    collision_avoidance: bool = True
    epsilons: list[float] | None = None
    launch_interval_s: float = 2.0
    launch_order: list[int] | None = None
    idle_wait_s: float = 2.0
    max_sim_time_s: float = 3600.0
    stall_timeout_s: float | None = None
    turn_rate_rad_s: float = 1.0
    bearing_fov_deg: float = 60.0
    bearing_range_m: float = 1.0
    bearing_noise_deg: float = 0.0
    radio_range_m: float | None = None
    faults: list[Fault] = field(default_factory=list)
    line_noise_m: float = 0.0
    ir_noise_m: float = 0.0
    wheel_slip: float = 0.0


@dataclass
class EmbodiedResult(ExplorationResult):
    """An embodied run's measurements: the graph world's keys plus physics ones.

    ``edge_time`` is ``"physics"``; ``makespan`` counts edges (see the module docstring).
    Robots are numbered from 1 (R1 is 1) in ``stopped_robots``.
    """

    collisions: int = 0
    speed_changes: int = 0
    sim_time_s: float = 0.0
    wall_time_s: float = 0.0
    realtime_factor: float = 0.0
    #: why the run ended: "completed", "stalled", "all robots stopped" or "max time"
    ended_because: str = ""
    #: robots that stopped for good: ``{"robot": R, "reason": ..., "at_s": t}``
    stopped_robots: list[dict] = field(default_factory=list)
    #: largest |odometry heading - true heading| of any robot over the run (deg), on lanes
    #: and at vertex calls
    heading_error_deg: float = 0.0
    #: injected faults and when they took effect: ``{"fault": text, "at_s": t}``
    faults: list[dict] = field(default_factory=list)
    #: with a radio: messages sent in all, by the busiest robot, and the share of sampled
    #: robot beliefs ("biconnected" or not) that equalled the truth
    radio_messages: int | None = None
    radio_max_messages_per_robot: int | None = None
    radio_belief_agreement: float | None = None


def same_lane_bearing(range_m: float) -> float:
    """The ``|beta|`` (rad) below which the speed rule takes a robot for one ahead on the
    same lane (eq. (27), ``beta = 0``): half the bearing, at the sensor's full range, of a
    robot on the edge's centre line, ``atan(LANE_OFFSET_M / 2 / range)`` (2.6 degrees at
    1 m). Robots on vertex centres stand on centre lines; one waiting on the centre of the
    vertex beyond the one a robot drives to (vertex entry) is no obstacle, and stopping
    for it would wait for ever (issue 13, ``arena2`` with 4 robots: a robot waiting on v9
    for v5 stopped the robot driving from v3 to v5). A robot on the opposite lane is
    twice as far off again."""
    return math.atan2(LANE_OFFSET_M / 2.0, range_m)


class EmbodiedExploration:
    """One embodied exploration run: build the world, step it, measure it."""

    def __init__(self, spec: ArenaSpec, minds: list[Strategy], config: EmbodiedConfig,
                 seed: int | None = None, recorder=None) -> None:
        k = len(minds)
        if config.speed_m_s <= 0:
            raise MjswarmError(f"speed must be positive, got {config.speed_m_s} m/s")
        order = list(range(k)) if config.launch_order is None else list(config.launch_order)
        if sorted(order) != list(range(k)):
            raise MjswarmError(f"launch order must be a permutation of 0..{k - 1}, got {order}")
        if config.stall_timeout_s is not None and not config.stall_timeout_s > 0:
            raise MjswarmError(f"stall timeout must be positive, got {config.stall_timeout_s} s")
        eps = config.epsilons or epsilons(k)
        if len(eps) != k:
            raise MjswarmError(f"need {k} epsilons, got {len(eps)}")
        self.spec, self.minds, self.config, self.seed = spec, minds, config, seed
        self.recorder = recorder
        xs = [x for x, _ in spec.vertices.values()]
        ys = [y for _, y in spec.vertices.values()]
        depot = [Pose2D(min(xs) + DEPOT_SPACING_M * i, min(ys) - DEPOT_OFFSET_M, 0.0)
                 for i in range(k)]
        self.sim = Simulation(arena_world_spec(spec, depot), seed=seed or 0,
                              line_noise_m=config.line_noise_m, ir_noise_m=config.ir_noise_m,
                              wheel_slip=config.wheel_slip)
        if self.sim.geometry.max_speed_m_s < config.speed_m_s:
            raise MjswarmError(
                f"speed {config.speed_m_s} m/s exceeds the robot's top speed "
                f"{self.sim.geometry.max_speed_m_s:.2f} m/s")
        self.driver = NavigationDriver(self.sim, [0.0] * k, config.speed_m_s,
                                       config.turn_rate_rad_s)
        self.bearing = BearingSensor(
            self.sim, math.radians(config.bearing_fov_deg), config.bearing_range_m,
            math.radians(config.bearing_noise_deg), seed=seed or 0)
        self.rules = [CollisionRule(config.speed_m_s, e, dt=self.sim.control_dt_s,
                                    same_lane=same_lane_bearing(config.bearing_range_m))
                      for e in eps]
        self.beacons = {v: Beacon() for v in spec.vertices}
        self.beacon_vertex: dict[str, str] = {}
        self.launch_queue = order
        self.active = [False] * k
        self.done = [False] * k
        self.dead = [False] * k  # failed by an injected fault: radio off too
        self.waiting_since: list[float | None] = [None] * k  # IDLE
        self.stations = VertexStations(spec)
        #: each robot's vertex: the one it stands on or was granted; the one it is leaving
        self.target: list[str | None] = [None] * k
        self.leaving: list[str | None] = [None] * k
        self._departure_angle: list[float] = [0.0] * k
        self.paths = [[spec.root] for _ in range(k)]
        self.handled_events = [0] * k
        self.last_launch = -math.inf
        self.last_progress_s = 0.0
        self.declared: tuple[float, int, str] | None = None
        self.stopped: list[dict] = []
        self._last_speed = [config.speed_m_s] * k  # for the recording's speed-change events
        self.heading_error_rad = 0.0
        self.pending_faults = sorted(config.faults, key=lambda f: f.at_s)
        self.fault_log: list[dict] = []
        self.ended_because = "max time"
        longest = max(math.dist(spec.vertices[u], spec.vertices[v]) for u, v in spec.edges)
        self.stall_timeout_s = (config.stall_timeout_s if config.stall_timeout_s is not None
                                else max(STALL_MIN_S, STALL_EDGE_FACTOR * longest / config.speed_m_s))
        self.awareness = None
        if config.radio_range_m is not None:
            if config.radio_range_m <= 0:
                raise MjswarmError(f"radio range must be positive, got {config.radio_range_m} m")
            self.awareness = TableAwareness(self.sim, config.radio_range_m)
        self._vertices = np.array(list(spec.vertices.values()))
        self._vertex_ids = list(spec.vertices)
        for fault in config.faults:
            fault.check(self)

    # ------------------------------------------------------------------ loop
    def run(self, progress: bool = False) -> EmbodiedResult:
        """Step until the run is over (:meth:`finished`) or ``max_sim_time_s``.

        ``progress``: on a terminal, a bar of simulated seconds (there is no honest total:
        a run ends when a robot declares completion) with the edge traversals so far;
        elsewhere (logs, CI) a status line on stderr every ``STATUS_EVERY_S`` of wall
        time and one at the end."""
        cfg = self.config
        start = last_status = time.perf_counter()
        ticks = int(cfg.max_sim_time_s / self.sim.control_dt_s)
        bar = tqdm(unit="sim s", desc=f"explore {self.spec.name}", leave=False,
                   disable=not (progress and sys.stderr.isatty()))
        log = progress and bar.disable
        shown = 0
        for _ in range(ticks):
            self.step()
            if self.finished():
                break
            now = int(self.sim.time_s)
            if now > shown:
                bar.update(now - shown)
                shown = now
                bar.set_postfix(edges=self._traversals(), refresh=False)
            if log and time.perf_counter() - last_status >= STATUS_EVERY_S:
                last_status = time.perf_counter()
                print(self._status(last_status - start), file=sys.stderr, flush=True)
        bar.close()
        self._event(None, f"run ended: {self.ended_because}")
        if log:
            print(self._status(time.perf_counter() - start), file=sys.stderr, flush=True)
        return self.result(time.perf_counter() - start)

    def _traversals(self) -> int:
        return sum(len(p) - 1 for p in self.paths)

    def _status(self, wall_s: float) -> str:
        """One line for logs: where the run is."""
        return (f"explore {self.spec.name}: {self.sim.time_s:.0f} s simulated in "
                f"{wall_s:.0f} s, {self._traversals()} edge traversals, "
                f"{sum(self.active)} of {len(self.active)} robots launched, "
                f"{len(self.stopped)} stopped")

    def finished(self) -> bool:
        """Whether the run is over (and why, in ``ended_because``)."""
        if self.declared is not None:
            self.ended_because = "completed"
        elif all(self.done):
            self.ended_because = "all robots stopped"
        elif self.sim.time_s - self.last_progress_s > self.stall_timeout_s:
            self.ended_because = "stalled"
        else:
            return False
        return True

    def step(self) -> None:
        """One control tick: faults, launch, grant, sense, decide, act, simulate."""
        sim, cfg = self.sim, self.config
        self._inject_faults()
        self._launch_if_free()
        if cfg.collision_avoidance:
            for i, vertex in self.stations.grant():
                self._depart(i, vertex)
        speeds = np.zeros(sim.n)
        bearings = self.bearing.read() if cfg.collision_avoidance else None
        v = np.zeros(sim.n)
        w = np.zeros(sim.n)
        poses = sim.poses()
        for i, (nav, percept) in enumerate(zip(self.driver.navigators, percepts(sim))):
            if not self.active[i] or self.done[i]:
                continue
            vi, wi = nav.update(percept)
            self._handle_events(i)
            if self.done[i]:
                continue
            if nav.state is NavigatorState.ON_EDGE:
                self._measure_heading(i, poses[i, 2])
            speed = cfg.speed_m_s
            if cfg.collision_avoidance:
                if nav.on_lane:  # the rule governs edge traversals
                    speed = self.rules[i].update(bearings[i])
                else:
                    self.rules[i].forget_bearings()
                if self.leaving[i] is not None and nav.in_corridor:  # clear of it
                    self.stations.release(i, self.leaving[i])
                    self.leaving[i] = None
                if nav.at_vertex_area and self.target[i] in self.leaving:
                    speed = 0.0  # its previous holder is still leaving (a cycle's grant)
            if speed != self._last_speed[i] and nav.on_lane:
                self._event(i, f"R{i + 1} speed {self._last_speed[i]:.3f} -> {speed:.3f} m/s")
            self._last_speed[i] = speed
            factor = speed / cfg.speed_m_s
            if vi != 0.0:  # translations run at the rule's speed; turns in place do not
                vi, wi = vi * factor, wi * factor
            v[i], w[i], speeds[i] = vi, wi, speed
        sim.set_velocity(v, w)
        sim.step()
        if self.awareness is not None:
            self._radio_tick()
        if self.recorder is not None:
            readings = sim.readings()
            self.recorder.log_tick(sim.step_count, sim.time_s, sim.poses(), readings["line"],
                                   readings["ir"], speeds,
                                   [list(b.items()) for b in bearings] if bearings else
                                   [[] for _ in range(sim.n)],
                                   readings["encoder"], readings["battery"])

    # ------------------------------------------------------------------ robots
    def _radio_tick(self) -> None:
        """Tables follow the moving radio graph; beliefs sampled 5 times a second."""
        aware = self.awareness
        aware.step(np.array(self.active) & ~np.array(self.dead))
        if self.sim.step_count % 10:
            return
        beliefs, truth = aware.sample()
        if self.recorder is not None:
            edges = [tuple(e) for e in aware.radio.graph().edges]
            self.recorder.log_radio(self.sim.step_count, self.sim.time_s, edges, beliefs, truth)

    def _launch_if_free(self) -> None:
        if not self.launch_queue:
            return
        if self.sim.time_s - self.last_launch < self.config.launch_interval_s:
            return
        root = np.array(self.spec.vertices[self.spec.root])
        poses = self.sim.poses()
        for j, on in enumerate(self.active):
            if on and not self.done[j] and np.hypot(*(poses[j, :2] - root)) < ROOT_CLEAR_M:
                return
        if self.config.collision_avoidance and self.spec.root in self.stations.holder:
            return
        i = self.launch_queue.pop(0)
        self.sim.place_robot(i, Pose2D(root[0], root[1], 0.0))
        self.active[i] = True
        self.last_launch = self.last_progress_s = self.sim.time_s
        if self.config.collision_avoidance:
            self.stations.occupy(i, self.spec.root)
        self.target[i] = self.spec.root
        self.driver.navigators[i].begin_at_vertex()
        self._event(i, f"R{i + 1} launched at {self.spec.root}")

    def _handle_events(self, i: int) -> None:
        nav = self.driver.navigators[i]
        new = nav.events[self.handled_events[i]:]
        self.handled_events[i] = len(nav.events)
        for event in new:
            if event.kind is NavEvent.ARRIVED:
                self.rules[i].crossed_vertex()  # eq. (34)
                # the scan right after a launch is no arrival: the robot came by no edge
                self._at_vertex(i, arrived=nav.arrived_angle is not None)
            elif event.kind is NavEvent.LOST:
                self._stop(i, str(event))
        waiting = self.waiting_since[i]
        if waiting is not None and self.sim.time_s - waiting >= self.config.idle_wait_s:
            self.waiting_since[i] = None
            self._at_vertex(i, arrived=False)

    def _at_vertex(self, i: int, arrived: bool) -> None:
        """The strategy's vertex call: beacon in, decision out."""
        nav = self.driver.navigators[i]
        vertex = self._vertex_under(i)
        if vertex is None:
            self._stop(i, "not on a vertex centre after arriving")
            return
        if vertex != self.target[i]:
            self._stop(i, f"arrived at {vertex}, not at {self.target[i]} where it was heading")
            return
        if arrived:
            self.paths[i].append(vertex)
            self.last_progress_s = self.sim.time_s
            self._event(i, f"R{i + 1} at {vertex}")
        beacon = self.beacons[vertex]
        mind = self.minds[i]
        try:
            decision = mind.on_vertex(beacon, nav.edge_angles,
                                      nav.arrived_angle if arrived else None)
        except AngleMismatch as exc:  # its heading reference is broken (e.g. after a crash)
            self._stop(i, f"its angles match no edge of the beacon at {vertex}: {exc}")
            return
        except ValueError as exc:  # a beacon it cannot reconcile (e.g. a wiped one)
            self._stop(i, f"its strategy failed at {vertex}: {exc}")
            return
        if mind.stored_angles is not None:  # re-anchoring (see the module docstring)
            nav.reanchor(mind.stored_angles)
        self._measure_heading(i, self.sim.poses()[i, 2])
        if beacon.id is not None:
            self.beacon_vertex.setdefault(beacon.id, vertex)
        if self.recorder is not None:
            self._record_vertex_call(i, vertex, beacon)
        if decision.action == "go":
            self._ask_to_leave(i, vertex, decision.angle)
        elif decision.action == "idle":
            self.waiting_since[i] = self.sim.time_s
        elif decision.action == "done":
            self.declared = (self.sim.time_s, i, vertex)
            self.done[i] = True
            self._event(i, f"R{i + 1} declares completion at {vertex}")
            self._event(None, f"R{i + 1} declared completion at {vertex}")
        else:
            raise ValueError(f"robot {i + 1} answered an unknown decision {decision!r}")

    def _measure_heading(self, i: int, true_yaw: float) -> None:
        """Track ``heading_error_deg``: sampled where the heading is in use, on a lane and
        at vertex calls (mid-scan the odometry over-reads rotation until the scan's own
        calibration corrects it)."""
        error = abs(math.remainder(self.driver.navigators[i].odometry.theta - true_yaw,
                                   2 * math.pi))
        self.heading_error_rad = max(self.heading_error_rad, error)

    def _ask_to_leave(self, i: int, vertex: str, angle: float) -> None:
        """Vertex entry, step 1: the robot names its edge by its angle; the stations find
        the vertex at its far end and queue the request (:mod:`mjswarm.stations`)."""
        nav = self.driver.navigators[i]
        self._departure_angle[i] = min(
            nav.edge_angles, key=lambda a: abs(math.remainder(a - angle, 2 * math.pi)))
        ahead, off = self.stations.edge_towards(vertex, angle)
        if off > DEPARTURE_TOLERANCE_RAD:
            self._stop(i, f"its departure angle at {vertex} is {math.degrees(off):.0f} deg "
                          "from every edge there")
            return
        if not self.config.collision_avoidance:
            self._depart(i, ahead)
            return
        self.stations.request(i, vertex, ahead, self.sim.time_s)

    def _depart(self, i: int, ahead: str) -> None:
        """Entry granted: leave along the chosen spoke towards ``ahead``."""
        self.leaving[i], self.target[i] = self.target[i], ahead
        self.driver.navigators[i].depart(self._departure_angle[i])

    def _stop(self, i: int, reason: str) -> None:
        """Robot ``i`` stops for good: it releases its holds and stays as an obstacle. A
        station whose vertex area the body still occupies keeps the vertex closed (it
        sees the body, as it sees who stands on its centre)."""
        self.done[i] = True
        self.stations.release_all(i)
        xy = self.sim.poses()[i, :2]
        d = np.hypot(*(self._vertices - xy).T)
        j = int(np.argmin(d))
        if d[j] < VERTEX_CLEAR_RADIUS_M:
            self.stations.occupy(i, self._vertex_ids[j])
        self.leaving[i] = None
        self.stopped.append({"robot": i + 1, "reason": reason, "at_s": round(self.sim.time_s, 2)})
        self._event(i, f"R{i + 1} stopped: {reason}")

    def _inject_faults(self) -> None:
        """Apply the faults whose time has come (:mod:`mjswarm.faults`), at the control
        tick nearest to it."""
        now = self.sim.time_s + self.sim.control_dt_s / 2.0
        while self.pending_faults and self.pending_faults[0].at_s <= now:
            fault = self.pending_faults.pop(0)
            fault.apply(self)
            self.fault_log.append({"fault": str(fault), "at_s": round(self.sim.time_s, 2)})
            self._event(None, f"fault: {fault}")

    def _record_vertex_call(self, i: int, vertex: str, beacon: Beacon) -> None:
        """Beacon contents and the robot's map (beacon ids shown as arena vertices)."""
        step, now = self.sim.step_count, self.sim.time_s
        self.recorder.log_beacon(step, now, vertex, f"beacon {beacon.id}\n{beacon.data!r}")
        edges = [(self.beacon_vertex[a], self.beacon_vertex[b])
                 for a, b in self.minds[i].map_edges()
                 if a in self.beacon_vertex and b in self.beacon_vertex]
        nodes = {v: self.spec.vertices[v] for e in edges for v in e}
        nodes.setdefault(vertex, self.spec.vertices[vertex])
        self.recorder.log_explored_graph(step, now, i, nodes, edges)

    def _vertex_under(self, i: int) -> str | None:
        """The vertex whose centre robot ``i`` stands on (the station's knowledge)."""
        xy = self.sim.poses()[i, :2]
        d = np.hypot(*(self._vertices - xy).T)
        j = int(np.argmin(d))
        return self._vertex_ids[j] if d[j] < ON_VERTEX_M else None

    def _event(self, i: int | None, text: str) -> None:
        if self.recorder is not None:
            self.recorder.log_event(self.sim.step_count, self.sim.time_s, text, i)

    # ------------------------------------------------------------------ metrics
    def result(self, wall: float = 0.0) -> EmbodiedResult:
        """The measurements so far (``wall``: wall-clock seconds spent, for the rates)."""
        sim_time = self.sim.time_s
        makespan = None if self.declared is None else max(len(p) - 1 for p in self.paths)
        return EmbodiedResult(
            **outcome(self.minds, self.declared, makespan, self.paths, self.beacon_vertex,
                      {tuple(sorted(e)) for e in self.spec.edges}, arena=self.spec.name,
                      root=self.spec.root, edge_time="physics", seed=self.seed),
            collisions=self.sim.collisions.count,
            speed_changes=sum(r.activations for r in self.rules),
            sim_time_s=sim_time,
            wall_time_s=wall,
            realtime_factor=sim_time / wall if wall > 0 else math.inf,
            radio_messages=None if self.awareness is None else self.awareness.radio.total_sent,
            radio_max_messages_per_robot=(None if self.awareness is None
                                          else max(self.awareness.radio.sent.values())),
            radio_belief_agreement=None if self.awareness is None else self.awareness.agreement,
            ended_because=self.ended_because,
            stopped_robots=list(self.stopped),
            heading_error_deg=round(math.degrees(self.heading_error_rad), 3),
            faults=list(self.fault_log),
        )


def explore_embodied(spec: ArenaSpec, n_robots: int, strategy: str = "incidence-dfs",
                     config: EmbodiedConfig | None = None, seed: int | None = None,
                     recorder=None, progress: bool = False) -> EmbodiedResult:
    """Explore ``spec`` with ``n_robots`` embodied robots running ``strategy``."""
    minds = make_minds(strategy, n_robots, seed)
    run = EmbodiedExploration(spec, minds, config or EmbodiedConfig(), seed, recorder)
    return run.run(progress=progress)
