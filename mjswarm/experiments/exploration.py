"""Embodied exploration: the graph strategies on MuJoCo robots (issue 5), as loop functions.

Every robot is an :class:`~algorithms.exploration.explorer.Explorer` controller
(navigator, exploration strategy, collision rule, vertex entry, optionally a
connectivity table), run in a :class:`~mjswarm.worlds.sparkworld.SparkWorld` by the one
:class:`~mjswarm.worlds.loop.Loop`. :class:`EmbodiedExploration` is the experiment's loop
functions (ARGoS's term): it owns the beacons and the vertex stations, launches robots,
injects faults, measures and records. Choices it makes, beyond the paper:

* **Beacons** are a store keyed by the arena's vertex (seed 003 emulated beacons with a
  central station over XBee, "separate information for each vertex"; so do we). A robot
  gets the beacon in its observation only while it stands on the vertex centre (within
  ``ON_VERTEX_M``; the station knows who stands on its centre, as the paper's station
  knew which vertex was calling), and only if the station granted it that vertex (or it
  was launched there).
* **Vertex entry** (our addition, needed once robots have bodies): a vertex area holds
  one robot at a time; the protocol is :mod:`algorithms.exploration.entry`, carried by
  the stations' link (:class:`~mjswarm.core.radio.Uplink`, one tick each way, counted in
  ``station_messages``), and the grants are :mod:`mjswarm.experiments.stations`' (which also
  explains why no circular wait can form). ``--no-collision-avoidance`` turns this off
  together with the speed rule.
* **Robots that stop** (the explorer's reasons, or a fault) release every vertex they
  hold, stay where they are as obstacles (a vertex whose area the body still occupies
  stays closed) and are listed in ``stopped_robots`` with the reason and the time. A run
  ends early, not completed, when no robot has reached a vertex for ``stall_timeout_s``
  (``ended_because``: ``"completed"``, ``"stalled"``, ``"all robots stopped"`` or
  ``"max time"``).
* **Launching from the root**: robots wait in a depot outside the arena and are put on the
  root centre one at a time (as the paper's robots were placed by hand), in ``launch_order``,
  at least ``launch_interval_s`` apart, whenever the root is free. Each starts with compass
  heading 0 along the world's +x, the common reference direction of the incidence angles.
* **Connectivity awareness** (``radio_range_m``): robots carry radios (range R, one tick of
  latency, links blocked by walls) and each keeps a connectivity table of internally
  disjoint access paths to R1 (seed 004). Its *belief* is ``biconnected`` when it has
  two such paths; the *truth* (:func:`mjswarm.experiments.awareness.truth`) is whether it shares a
  biconnected component of three or more with R1 in the radio graph; both are sampled
  five times a second into ``radio_belief_agreement``. Robots in the depot or failed
  are off the air.
* **Exploration that stays connected** (``connectivity``, issue 17): a base station at
  the root joins the robots' radio (links need line of sight, as between robots); every
  robot keeps its tether (:mod:`algorithms.exploration.tether`) from a radio-ranging
  sensor (range and bearing of its radio neighbours); the base adopts, beats and floods
  on; with ``biconnected`` the first robot in the launch order docks at the base (rule
  1: it stays in the depot, its radio on the base's mast, as the graph world's first
  robot stands on the root, and answers as the base does); relays on demand (rule 6)
  walk back along edges by turning on their lane, and the stations let a relay onto its
  requester's lane (:mod:`algorithms.exploration.entry`).
  A time unit of rules 5 and 6 is the mean edge at the run's speed plus a scan. Ground
  truth every tick: networkx on the radio graph with the base (``cut_ticks``, ``fragile_ticks``).
  The robots' own stall verdict (rule 5) replaces the ``stall_timeout_s`` check.
  Tables (connectivity awareness) are off in these runs.
* **Metrics**: ``makespan`` is the largest number of edges any robot had traversed when
  completion was declared (the synchronous world's step count; seed 003 counts "edge
  traversals"), ``total_traversals`` the sum; ``collisions`` are robot-robot contact events
  (ground truth, never seen by robots); ``speed_changes`` the collision rule's activations
  (eq. 27); ``heading_error_deg`` the largest odometry heading error of any robot, on
  lanes and at vertex calls (ground truth).
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import networkx as nx
import numpy as np
from tqdm import tqdm

from algorithms.collision import PAPER_SPEED_M_S, CollisionRule, epsilons
from algorithms.connectivity import ConnectivityTable
from algorithms.exploration import Beacon, Strategy
from algorithms.exploration.entry import (
    STATION,
    EntryDenied,
    EntryGranted,
    EntryRequest,
    Halted,
    LeftVertex,
    TurnedBack,
    VertexClear,
    Withdraw,
)
from algorithms.exploration.explorer import Explorer, VertexCall
from algorithms.exploration.relay import Flooder
from algorithms.exploration.tether import BASE, BaseStation, Tether, docked, initial_parents
from algorithms.navigation import NavigatorState
from mjswarm.arena import ArenaSpec
from mjswarm.arena.builder import arena_world_spec
from mjswarm.arena.geometry import LANE_OFFSET_M, VERTEX_CLEAR_RADIUS_M
from mjswarm.experiments.awareness import BICONNECTED, NOT
from mjswarm.experiments.awareness import truth as awareness_truth
from mjswarm.core.bearing import BearingSensor
from mjswarm.core.contacts import contact_event
from mjswarm.core.robot import spark_v_geometry
from mjswarm.errors import MjswarmError, RunInterrupted
from mjswarm.experiments.faults import Fault, check_fault, is_user_fault
from mjswarm.experiments.minds import make_minds, strategy_name
from mjswarm.experiments.radio_exploration import (
    CONNECTIVITY,
    NEED,
    infeasible_reason,
    need_robots,
)
from mjswarm.experiments.results import ExplorationResult, outcome
from mjswarm.worlds.loop import Loop, LoopFunctions, Scene
from mjswarm.worlds.navigation import calibration, conventions
from mjswarm.core.radio import Radio, Uplink, sight_blocker
from mjswarm.core.simulation import Simulation
from mjswarm.worlds.sparkworld import SparkWorld
from mjswarm.experiments.stations import VertexStations
from mjswarm.core.world import Pose2D

#: The tether's leash keeps parents within the radio range less this (m): a control
#: period's drive at top speed (4 mm), turns and the one-tick-old ranging, with room.
TETHER_MARGIN_M = 0.02
#: Of the leash, what only a walk back may use (m, the tether's ``reserve_m``): a U-turn
#: sidesteps two lane offsets across its edge, with room for the odometry's back-up to
#: where its lane ended.
TURN_RESERVE_M = 2 * LANE_OFFSET_M + 0.02
#: Height (m) of the base station's antenna at the root: above the robots (0.07 m tall),
#: so that a robot standing on the root does not shadow the others; walls still block.
BASE_MAST_M = 1.0
#: What pictures of a run say the marked vertices are.
BEACON_LABEL = "beacon dropped (vertex explored)"
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
#: Building the world is reported (with its wall time) when it takes longer than this
#: (s); on a terminal a transient line shows while it is being built.
BUILD_NOTE_S = 2.0


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
            (:mod:`mjswarm.experiments.awareness`); None: no radio.
        faults: injected faults (:mod:`mjswarm.experiments.faults`).
        line_noise_m, ir_noise_m: standard deviation of the line and IR rangefinders'
            Gaussian noise (m).
        wheel_slip: scale of the wheel-slip model (:class:`mjswarm.core.simulation.Simulation`).
        physics: ``"dynamic"`` (MuJoCo's contact physics) or ``"kinematic"`` (the fast
            tier, :mod:`mjswarm.core.kinematic`).
        connectivity: ``"none"``, ``"connected"`` or ``"biconnected"`` (both need
            ``radio_range_m``): every robot keeps its tether of one or two parents to a
            base station at the root (:mod:`algorithms.exploration.tether`; see the
            module docstring); with ``"biconnected"`` the first robot in
            ``launch_order`` docks at the base (rule 1) and is never launched.
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
    physics: str = "dynamic"
    connectivity: str = "none"


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
    #: why the run ended: "completed", "stalled", "all robots stopped", "max time",
    #: "interrupted" (Ctrl-C; what was measured until then) or the infeasibility verdict
    ended_because: str = ""
    #: robots that stopped for good: ``{"robot": R, "reason": ..., "at_s": t}``
    stopped_robots: list[dict] = field(default_factory=list)
    #: largest |odometry heading - true heading| of any robot over the run (deg), on lanes
    #: and at vertex calls
    heading_error_deg: float = 0.0
    #: injected faults and when they took effect: ``{"fault": text, "fired": True,
    #: "at_s": t}``; a fault whose time the run did not reach has ``"fired": False`` and
    #: ``"at_s": None``
    faults: list[dict] = field(default_factory=list)
    #: with a radio: messages sent in all, by the busiest robot, and the share of sampled
    #: robot beliefs ("biconnected" or not) that equalled the truth
    radio_messages: int | None = None
    radio_max_messages_per_robot: int | None = None
    radio_belief_agreement: float | None = None
    #: vertex-entry messages between robots and stations, both ways
    #: (:mod:`algorithms.exploration.entry`)
    station_messages: int = 0
    #: the connectivity constraint, and the ground truth on it: ticks (with a robot on the
    #: floor) in which some robot had no radio route to the base, or the radio graph with
    #: the base was not biconnected, and their shares
    connectivity: str = "none"
    cut_ticks: int = 0
    fragile_ticks: int = 0
    connected_share: float | None = None
    biconnected_share: float | None = None
    #: whether the robots declared the exploration infeasible (rule 5 of the tether)
    infeasible: bool = False
    reason: str | None = None
    #: relay missions the robots set out on (rule 6 of :mod:`algorithms.exploration.relay`)
    relay_trips: int = 0


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


class EmbodiedExploration(LoopFunctions):
    """One embodied exploration run: build the world and the robots, run, measure."""

    def __init__(self, spec: ArenaSpec, minds: list[Strategy], config: EmbodiedConfig,
                 seed: int | None = None, recorder=None, progress: bool = False) -> None:
        """Check every parameter, then build the world (``progress``: say on stderr what
        is being built, and how long it took: a thousand robots take seconds)."""
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
        if config.radio_range_m is not None and not config.radio_range_m > 0:
            raise MjswarmError(f"radio range must be positive, got {config.radio_range_m} m")
        if config.connectivity not in CONNECTIVITY:
            raise MjswarmError(f"connectivity must be one of {', '.join(CONNECTIVITY)}, "
                               f"got '{config.connectivity}'")
        tied = config.connectivity != "none"
        if tied and config.radio_range_m is None:
            raise MjswarmError(f"connectivity {config.connectivity} needs a radio range")
        need_robots(config.connectivity, k)
        self.spec, self.minds, self.config, self.seed = spec, minds, config, seed
        for fault in config.faults:
            check_fault(fault, self)
        top = spark_v_geometry().max_speed_m_s
        if config.speed_m_s > top:
            raise MjswarmError(f"speed {config.speed_m_s} m/s exceeds the robot's top speed "
                               f"{top:.2f} m/s")
        self.recorder = recorder
        terminal = progress and sys.stderr.isatty()
        if terminal:  # a transient line, cleared when the world is built
            print(f"explore: building {spec.name} with {k} robot(s) ...", end="\r",
                  file=sys.stderr, flush=True)
        built = time.perf_counter()
        xs = [x for x, _ in spec.vertices.values()]
        ys = [y for _, y in spec.vertices.values()]
        depot = [Pose2D(min(xs) + DEPOT_SPACING_M * i, min(ys) - DEPOT_OFFSET_M, 0.0)
                 for i in range(k)]
        self.sim = Simulation(arena_world_spec(spec, depot), seed=seed or 0,
                              line_noise_m=config.line_noise_m, ir_noise_m=config.ir_noise_m,
                              wheel_slip=config.wheel_slip, physics=config.physics)
        geometry = self.sim.geometry
        bearing = BearingSensor(
            self.sim, math.radians(config.bearing_fov_deg), config.bearing_range_m,
            math.radians(config.bearing_noise_deg), seed=seed or 0)
        self.world = SparkWorld(self.sim, bearing, present=np.zeros(k, bool),
                                beacon_at=self._beacon_at, ranging=tied)
        self.uplink = Uplink(STATION)
        self.world.uplinks[STATION] = self.uplink
        self.base = self.dock = None
        root_xy = tuple(spec.vertices[spec.root])
        if tied:  # the base station at the root, on the robots' radio
            self.world.fixed = {BASE: root_xy}
            self.base = BaseStation(Flooder())
        if NEED.get(config.connectivity) == 2:  # rule 1: the first robot docks at the base
            self.world.docked = {order[0]: root_xy}
            self.dock = docked(Flooder())
            order = order[1:]
        if config.radio_range_m is not None:
            self.world.attach_radio(Radio([*range(k), *self.world.fixed],
                                          range_m=config.radio_range_m,
                                          blocked=sight_blocker(
                                              self.sim, {**self.world.fixed, **self.world.docked},
                                              BASE_MAST_M)))
        avoid = config.collision_avoidance
        cal, conv = calibration(geometry), conventions(geometry)
        self.robots = [
            Explorer(mind, cal, conv, config.speed_m_s,
                     CollisionRule(config.speed_m_s, e, dt=self.sim.control_dt_s,
                                   same_lane=same_lane_bearing(config.bearing_range_m))
                     if avoid else None,
                     config.turn_rate_rad_s, config.idle_wait_s,
                     ConnectivityTable(i, 0) if config.radio_range_m is not None and not tied
                     else None,
                     self.sim.control_dt_s,
                     self._tether(i) if tied and i not in self.world.docked else None)
            for i, (mind, e) in enumerate(zip(minds, eps))]
        self.beacons = {v: Beacon() for v in spec.vertices}
        self.beacon_vertex: dict[str, str] = {}
        self.launch_queue = order
        self.dead = [False] * k  # failed by an injected fault: radio off too
        self.stations = VertexStations(spec)
        #: each robot's vertex: the one it stands on or was granted; the one it is leaving
        self.target: list[str | None] = [None] * k
        self.leaving: list[str | None] = [None] * k
        #: the vertex each robot last asked to leave (where a walk back takes it), and
        #: the angle it asked for
        self.came_from: list[str | None] = [None] * k
        self.asked: list[float | None] = [None] * k
        #: robots granted a vertex whose previous holder has not yet left it
        self.awaiting_clear: set[int] = set()
        self.paths = [[spec.root] for _ in range(k)]
        self._calls_seen = [0] * k
        self._contacts_logged = 0
        self.last_launch = -math.inf
        self.last_progress_s = 0.0
        self.declared: tuple[float, int, str] | None = None
        self.stopped: list[dict] = []
        self._reported: set[int] = set()  # robots in ``stopped``
        self._last_speed = [config.speed_m_s] * k  # for the recording's speed-change events
        self.heading_error_rad = 0.0
        self.pending_faults = sorted(config.faults, key=lambda f: f.at_s)
        self.fault_log: list[dict] = []
        self.ended_because = "max time"
        self.cut_ticks = self.fragile_ticks = self.tied_ticks = 0
        self.agree = self.samples = 0
        self._truth: dict[int, str] | None = None  # this tick's truth, on sampled ticks
        self._beliefs: dict[int, str] = {}
        self._links: list = []
        longest = max(math.dist(spec.vertices[u], spec.vertices[v]) for u, v in spec.edges)
        self.stall_timeout_s = (config.stall_timeout_s if config.stall_timeout_s is not None
                                else max(STALL_MIN_S, STALL_EDGE_FACTOR * longest / config.speed_m_s))
        self._vertices = np.array(list(spec.vertices.values()))
        self._vertex_ids = list(spec.vertices)
        self._nearest_version = -1  # _nearest_vertex's cache
        #: (step count, time s, true poses) of the state the robots observed this tick,
        #: and the clock the accounting reads (:meth:`_now`)
        self._observed: tuple[int, float, np.ndarray] | None = None
        self._clock: tuple[int, float, np.ndarray] | None = None
        self.loop = Loop(self.world, dict(enumerate(self.robots)), [self])
        took = time.perf_counter() - built
        if terminal:
            print("\033[K", end="", file=sys.stderr, flush=True)
        if progress and took > BUILD_NOTE_S:
            print(f"explore: built {spec.name} with {k} robot(s) in {took:.1f} s",
                  file=sys.stderr, flush=True)

    @property
    def active(self) -> list[bool]:
        """Which robots have been launched."""
        return [bool(p) or d for p, d in zip(self.world.present, self.dead)]

    @property
    def done(self) -> list[bool]:
        """Which robots are finished: stopped, failed or declared."""
        return [r.halted is not None or r.declared or d or i in self.world.docked
                for i, (r, d) in enumerate(zip(self.robots, self.dead))]

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
        try:
            for _ in range(ticks):
                self.step()
                if self.loop.stopped:  # should_stop: finished() said why
                    break
                now = int(self.sim.time_s)
                if now > shown:
                    bar.update(now - shown)
                    shown = now
                    bar.set_postfix(edges=self._traversals(), refresh=False)
                if log and time.perf_counter() - last_status >= STATUS_EVERY_S:
                    last_status = time.perf_counter()
                    print(self._status(last_status - start), file=sys.stderr, flush=True)
        except KeyboardInterrupt:
            self.ended_because = "interrupted"
            raise RunInterrupted(self._end(bar, log, start)) from None
        return self._end(bar, log, start)

    def _end(self, bar: tqdm, log: bool, start: float) -> EmbodiedResult:
        """Close the progress display, mark the end in the recording, and the result."""
        bar.close()
        self._event(None, f"run ended: {self.ended_because}")
        if log:
            print(self._status(time.perf_counter() - start), file=sys.stderr, flush=True)
        return self.result(wall=time.perf_counter() - start)

    def step(self) -> None:
        """One control tick of the loop."""
        self.loop.step()

    def _traversals(self) -> int:
        return sum(len(p) - 1 for p in self.paths)

    def _status(self, wall_s: float) -> str:
        """One line for logs: where the run is."""
        return (f"explore {self.spec.name}: {self.sim.time_s:.0f} s simulated in "
                f"{wall_s:.0f} s, {self._traversals()} edge traversals, "
                f"{sum(a for j, a in enumerate(self.active) if j not in self.world.docked)} "
                f"of {len(self.active)} robots launched"
                f"{', 1 docked at the base' if self.world.docked else ''}, "
                f"{len(self.stopped)} stopped")

    def finished(self) -> bool:
        """Whether the run is over (and why, in ``ended_because``)."""
        if self.declared is not None:
            self.ended_because = "completed"
        elif any(r.infeasible for r in self.robots):
            self.ended_because = self._infeasible_reason()
        elif all(self.done):
            self.ended_because = "all robots stopped"
        elif self.base is None and self.sim.time_s - self.last_progress_s > self.stall_timeout_s:
            self.ended_because = "stalled"
        else:
            return False
        return True

    # ------------------------------------------------------------------ hooks
    def before_step(self, loop: Loop) -> None:
        """Faults, launches, the stations' mail, grants; the radio's truth, five times a
        second."""
        radio = self.world.radio
        if self.base is not None:
            for m in self.base.step(radio.receive(BASE)):
                radio.send(BASE, m.payload, m.to)
            for i in self.world.docked:
                if not self.dead[i]:
                    for m in self.dock.step(radio.receive(i)):
                        radio.send(i, m.payload, m.to)
        elif radio is not None and self.sim.step_count % 10 == 0 and self.sim.step_count:
            graph = radio.graph()
            self._truth = awareness_truth(graph, 0, range(1, len(self.robots)))
            self._links, self._beliefs = list(graph.edges), {}
        self._inject_faults()
        self._launch_if_free()
        for message in self.uplink.receive():
            self._station_receives(message.sender, message.payload)
        if self.config.collision_avoidance:
            granted = self.stations.grant()
            for i, vertex in granted:  # a cycle's grants all take effect at once ...
                self.leaving[i], self.target[i] = self.target[i], vertex
            for i, vertex in granted:  # ... before anyone is told whether its vertex is clear
                clear = not any(v == vertex for j, v in enumerate(self.leaving) if j != i)
                if not clear:
                    self.awaiting_clear.add(i)
                self.uplink.reply(i, EntryGranted(clear, self.asked[i]))
                self._event(i, f"R{i + 1} granted {vertex}")
        self._observed = (self.sim.step_count, self.sim.time_s, self.sim.poses().copy())

    def _robot_ticked(self, i: int) -> None:
        """What robot ``i`` did this tick, for the metrics and the recording."""
        robot = self.robots[i]
        if self._truth is not None and i in self._truth:
            self._beliefs[i] = self._belief(i)
        nav = robot.nav
        if nav.state is NavigatorState.ON_EDGE:
            self._measure_heading(i)
        for call in robot.calls[self._calls_seen[i]:]:
            self._vertex_call(i, call)
        self._calls_seen[i] = len(robot.calls)
        if robot.halted is not None and i not in self._reported:
            self._stopped(i, robot.halted)
        if robot.speed_m_s != self._last_speed[i] and nav.on_lane:
            self._event(i, f"R{i + 1} speed {self._last_speed[i]:.3f} -> "
                           f"{robot.speed_m_s:.3f} m/s")
        self._last_speed[i] = robot.speed_m_s

    def after_step(self, loop: Loop) -> None:
        """The tick's robots (accounted at the state they observed, as when they
        decided), then the radio's truth and the recording of the new state."""
        sim = self.sim
        self._clock = self._observed
        for i in loop.stepped:
            self._robot_ticked(i)
        self._clock = None
        if self._truth is not None:
            self._sample_beliefs()
        if self.base is not None and any(self.world.present):
            graph = self.world.radio.graph()  # ground truth, every tick
            self.tied_ticks += 1
            self.cut_ticks += not nx.is_connected(graph)
            self.fragile_ticks += not nx.is_biconnected(graph)
        if self.recorder is not None:
            readings = sim.readings()
            bearings = self.world.bearing_readings()
            poses = sim.poses()
            self.recorder.log_tick(sim.step_count, sim.time_s, poses, readings["line"],
                                   readings["ir"], np.array(self._last_speed),
                                   [list(b.items()) for b in bearings],
                                   readings["encoder"], readings["battery"])
            for _, i, j in sim.collisions.events[self._contacts_logged:]:
                self._event(None, contact_event(i, j, poses))
            self._contacts_logged = sim.collisions.count

    def should_stop(self, loop: Loop) -> bool:
        return self.finished()

    def scene(self, loop: Loop) -> Scene:
        """Pictures mark the vertices whose beacon has been dropped (m)."""
        return Scene([self.spec.vertices[v] for v, b in self.beacons.items()
                      if b.id is not None], BEACON_LABEL)

    # ------------------------------------------------------------------ stations
    def _beacon_at(self, i: int) -> Beacon | None:
        """The beacon robot ``i`` can read now: its vertex's, if it stands on the centre
        and the station there granted it the vertex (or launched it there)."""
        vertex, distance = self._nearest_vertex(i)
        if distance >= ON_VERTEX_M:
            return None
        if self.config.collision_avoidance and self.target[i] != vertex:
            return None
        return self.beacons[vertex]

    def _station_receives(self, i: int, payload) -> None:
        if isinstance(payload, EntryRequest):
            vertex = self.target[i]
            ahead, off = self.stations.edge_towards(vertex, payload.angle_rad)
            if off > DEPARTURE_TOLERANCE_RAD:
                self.uplink.reply(i, EntryDenied(
                    f"its departure angle at {vertex} is {math.degrees(off):.0f} deg from "
                    "every edge there"))
                return
            self.came_from[i], self.asked[i] = vertex, payload.angle_rad
            if payload.part_way:  # a relay's last leg: onto the lane, not into ``ahead``
                self.leaving[i], self.target[i] = vertex, None
                self.uplink.reply(i, EntryGranted(False, payload.angle_rad))
                return
            self.stations.request(i, vertex, ahead, self.sim.time_s)
        elif isinstance(payload, TurnedBack):
            self._turned_back(i, payload.from_lane)
        elif isinstance(payload, Withdraw):
            self._withdraw(i)

        elif isinstance(payload, LeftVertex):
            left, self.leaving[i] = self.leaving[i], None
            self.stations.release(i, left)
            self._tell_clear()
        elif isinstance(payload, Halted):
            self._release(i)

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
        station gave it to another robot (a swap: no answer, and it goes on); else it asks
        for it as from a centre, and the grant tells it when it may turn, or enter."""
        back = self.came_from[i]
        if not from_lane and self.leaving[i] == back and self.stations.holder.get(back) != i:
            return
        self.awaiting_clear.discard(i)
        self.stations.release(i, self.target[i])
        if self.leaving[i] == back:  # it had not left that area: it is its own again
            self.leaving[i], self.target[i] = None, back
            self.uplink.reply(i, EntryGranted(clear=True))
        else:  # from its lane, or its corridor: as a request from a centre
            self.target[i], self.asked[i] = None, None  # the grant answers no EntryRequest
            self.stations.request(i, None, back, self.sim.time_s)
        self._tell_clear()

    def _release(self, i: int) -> None:
        """Robot ``i`` stopped for good: its holds go; a station whose vertex area the
        body still occupies keeps the vertex closed (it sees the body, as it sees who
        stands on its centre)."""
        self.stations.release_all(i)
        vertex, distance = self._nearest_vertex(i)
        if distance < VERTEX_CLEAR_RADIUS_M:
            self.stations.occupy(i, vertex)
        self.leaving[i] = None
        self.awaiting_clear.discard(i)
        self._tell_clear()

    def _tell_clear(self) -> None:
        """Tell the robots waiting for a vertex whose previous holder has now left it."""
        for j in sorted(self.awaiting_clear):
            if self.target[j] not in self.leaving:
                self.awaiting_clear.discard(j)
                self.uplink.reply(j, VertexClear())

    def _launch_if_free(self) -> None:
        if not self.launch_queue:
            return
        if self.sim.time_s - self.last_launch < self.config.launch_interval_s:
            return
        root = np.array(self.spec.vertices[self.spec.root])
        near = np.hypot(*(self.sim.poses()[:, :2] - root).T) < ROOT_CLEAR_M
        active, done = self.active, self.done  # each a pass over the team: once
        if any(active[j] and not done[j] for j in np.flatnonzero(near)):
            return
        if self.config.collision_avoidance and self.spec.root in self.stations.holder:
            return
        i = self.launch_queue.pop(0)
        self.world.place(i, Pose2D(root[0], root[1], 0.0))
        self.last_launch = self.last_progress_s = self.sim.time_s
        if self.config.collision_avoidance:
            self.stations.occupy(i, self.spec.root)
        self.target[i] = self.spec.root
        self._event(i, f"R{i + 1} launched at {self.spec.root}")

    # ------------------------------------------------------------------ robots
    def _vertex_call(self, i: int, call: VertexCall) -> None:
        vertex = self._nearest_vertex(i)[0]  # where it stands (its beacon was served)
        if call.arrived:
            self.paths[i].append(vertex)
            self.last_progress_s = self._now()[1]
            self._event(i, f"R{i + 1} at {vertex}")
        self._measure_heading(i)
        if call.beacon.id is not None:
            self.beacon_vertex.setdefault(call.beacon.id, vertex)
        if self.recorder is not None:
            self._record_vertex_call(i, vertex, call.beacon)
        if call.decision.action == "done":
            self.declared = (self._now()[1], i, vertex)
            self._event(i, f"R{i + 1} declares completion at {vertex}")
            self._event(None, f"R{i + 1} declared completion at {vertex}")
        elif call.decision.action == "go" and not self.config.collision_avoidance:
            self.target[i] = self.stations.edge_towards(vertex, call.decision.angle)[0]

    def _stopped(self, i: int, reason: str) -> None:
        self._reported.add(i)
        self.stopped.append({"robot": i + 1, "reason": reason, "at_s": round(self._now()[1], 2)})
        self._event(i, f"R{i + 1} stopped: {reason}")

    def fail(self, i: int, reason: str) -> None:
        """Robot ``i`` fails (a fault): it stops where it is, off the air, and its holds
        go as for any robot that stops."""
        robot = self.robots[i]
        if robot.halted is None and not robot.declared and not self.dead[i]:
            robot.halted = reason
            self._stopped(i, reason)
        self.dead[i] = True
        if i in self.launch_queue:  # not launched yet: it never will be
            self.launch_queue.remove(i)
            return
        self.loop.halt(i)
        self.world.set_on_air(i, False)
        self._release(i)

    def _measure_heading(self, i: int) -> None:
        """Track ``heading_error_deg``: sampled where the heading is in use, on a lane and
        at vertex calls (mid-scan the odometry over-reads rotation until the scan's own
        calibration corrects it)."""
        true_yaw = self._now()[2][i, 2]
        error = abs(math.remainder(self.robots[i].nav.odometry.theta - true_yaw, 2 * math.pi))
        self.heading_error_rad = max(self.heading_error_rad, error)

    def _belief(self, i: int) -> str:
        return BICONNECTED if self.robots[i].table.is_doubly_connected() else NOT

    def _sample_beliefs(self) -> None:
        """Tables' beliefs against the truth, for R2..RK (R1 is the reference): each
        robot's belief once its table has seen this tick's links (robots not stepped keep
        theirs), against the radio graph of this tick."""
        radio, truth = self.world.radio, self._truth
        beliefs = {i: self._beliefs.get(i) or self._belief(i) for i in truth}
        self._truth = None
        self.samples += len(truth)
        self.agree += sum(beliefs[i] == truth[i] for i in truth)
        if self.recorder is not None:
            self.recorder.log_radio(self.sim.step_count, self.sim.time_s,
                                    [tuple(e) for e in self._links], beliefs, truth)

    def _inject_faults(self) -> None:
        """Apply the faults whose time has come (:mod:`mjswarm.experiments.faults`), at the control
        tick nearest to it."""
        now = self.sim.time_s + self.sim.control_dt_s / 2.0
        while self.pending_faults and self.pending_faults[0].at_s <= now:
            fault = self.pending_faults.pop(0)
            fault.apply(self)
            self.fault_log.append({"fault": str(fault), "fired": True,
                                   "at_s": round(self.sim.time_s, 2)})
            self._event(None, f"fault: {fault}")

    def _record_vertex_call(self, i: int, vertex: str, beacon: Beacon) -> None:
        """Beacon contents and the robot's map (beacon ids shown as arena vertices)."""
        step, now, _ = self._now()
        self.recorder.log_beacon(step, now, vertex, f"beacon {beacon.id}\n{beacon.data!r}")
        edges = [(self.beacon_vertex[a], self.beacon_vertex[b])
                 for a, b in self.minds[i].map_edges()
                 if a in self.beacon_vertex and b in self.beacon_vertex]
        nodes = {v: self.spec.vertices[v] for e in edges for v in e}
        nodes.setdefault(vertex, self.spec.vertices[vertex])
        self.recorder.log_explored_graph(step, now, i, nodes, edges)

    def _nearest_vertex(self, i: int) -> tuple[str, float]:
        """The vertex nearest to robot ``i`` and its distance (m): what the stations see.
        Every robot's is computed once per world state (each robot's observation asks)."""
        sim = self.sim
        if self._nearest_version != sim.state_version:
            xy = sim.poses()[:, :2]
            d = np.hypot(xy[:, None, 0] - self._vertices[None, :, 0],
                         xy[:, None, 1] - self._vertices[None, :, 1])
            self._nearest = d.argmin(axis=1)
            self._nearest_m = d[np.arange(len(xy)), self._nearest]
            self._nearest_version = sim.state_version
        return self._vertex_ids[self._nearest[i]], float(self._nearest_m[i])

    def _tether(self, i: int) -> Tether:
        """Robot ``i``'s tether: a time unit (rules 5 and 6 count in them) is what the
        graph world's edge stands for, the mean edge at the run's speed and the scan at
        the vertex it leads to (one full turn)."""
        need = NEED[self.config.connectivity]
        spec, cfg = self.spec, self.config
        mean_m = float(np.mean([math.dist(spec.vertices[u], spec.vertices[v])
                                for u, v in spec.edges]))
        unit_s = mean_m / cfg.speed_m_s + 2.0 * math.pi / cfg.turn_rate_rad_s
        ticks = max(1, round(unit_s / self.sim.control_dt_s))
        first = next(iter(self.world.docked), None)
        return Tether(i, self.config.radio_range_m, initial_parents(i, need, first),
                      margin_m=TETHER_MARGIN_M, ticks_per_unit=ticks,
                      reserve_m=TURN_RESERVE_M)

    def _infeasible_reason(self) -> str:
        return infeasible_reason(len(self.robots), self.config.radio_range_m, self.paths,
                                 len(self.spec.edges))

    def _now(self) -> tuple[int, float, np.ndarray]:
        """The step count, simulated time (s) and true poses the accounting refers to:
        while the tick's robots are accounted (:meth:`after_step`), the state they
        observed; else the world's present state."""
        if self._clock is not None:
            return self._clock
        return self.sim.step_count, self.sim.time_s, self.sim.poses()

    def _event(self, i: int | None, text: str) -> None:
        if self.recorder is not None:
            step, now, _ = self._now()
            self.recorder.log_event(step, now, text, i)

    # ------------------------------------------------------------------ metrics
    def result(self, loop: Loop | None = None, wall: float = 0.0) -> EmbodiedResult:
        """The measurements so far (``wall``: wall-clock seconds spent, for the rates)."""
        sim_time = self.sim.time_s
        makespan = None if self.declared is None else max(len(p) - 1 for p in self.paths)
        radio = self.world.radio
        return EmbodiedResult(
            **outcome(strategy_name(self.minds), self.declared,
                      () if self.declared is None else self.minds[self.declared[1]].map_edges(),
                      makespan, self.paths, self.beacon_vertex,
                      {tuple(sorted(e)) for e in self.spec.edges}, arena=self.spec.name,
                      root=self.spec.root, edge_time="physics", seed=self.seed),
            collisions=self.sim.collisions.count,
            speed_changes=sum(r.rule.activations for r in self.robots if r.rule is not None),
            sim_time_s=sim_time,
            wall_time_s=wall,
            realtime_factor=sim_time / wall if wall > 0 else math.inf,
            radio_messages=None if radio is None else radio.total_sent,
            radio_max_messages_per_robot=None if radio is None else max(radio.sent.values()),
            radio_belief_agreement=(self.agree / self.samples if radio is not None
                                    and self.samples else None),
            station_messages=self.uplink.sent_up + self.uplink.sent_down,
            connectivity=self.config.connectivity,
            cut_ticks=self.cut_ticks,
            fragile_ticks=self.fragile_ticks,
            connected_share=(1.0 - self.cut_ticks / self.tied_ticks) if self.tied_ticks else None,
            biconnected_share=(1.0 - self.fragile_ticks / self.tied_ticks) if self.tied_ticks
            else None,
            infeasible=any(r.infeasible for r in self.robots),
            relay_trips=sum(r.connected.relay_trips for r in self.robots if r.connected),
            reason=self._infeasible_reason() if any(r.infeasible for r in self.robots) else None,
            ended_because=self.ended_because,
            stopped_robots=list(self.stopped),
            heading_error_deg=round(math.degrees(self.heading_error_rad), 3),
            faults=[*self.fault_log, *({"fault": str(f), "fired": False, "at_s": None}
                                       for f in self.pending_faults if is_user_fault(f))],
        )


def explore_embodied(spec: ArenaSpec, n_robots: int,
                     strategy: str | Callable[..., Strategy] = "incidence-dfs",
                     config: EmbodiedConfig | None = None, seed: int | None = None,
                     recorder=None, progress: bool = False) -> EmbodiedResult:
    """Explore ``spec`` with ``n_robots`` embodied robots running ``strategy`` (a name
    from ``STRATEGIES`` or a factory ``(index, n_robots, rng) -> Strategy``)."""
    minds = make_minds(strategy, n_robots, seed)
    run = EmbodiedExploration(spec, minds, config or EmbodiedConfig(), seed, recorder)
    return run.run(progress=progress)
