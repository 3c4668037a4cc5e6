"""Embodied exploration: the graph strategies on MuJoCo robots, as loop functions.

Every robot is an :class:`~algorithms.exploration.explorer.Explorer` controller
(navigator, exploration strategy, collision rule, vertex entry, optionally a
connectivity table), run in a :class:`~mjswarm.worlds.sparkworld.SparkWorld` by the one
:class:`~mjswarm.worlds.loop.Loop`. :class:`EmbodiedExploration` builds the world and the
robots and composes the experiment of small loop functions (ARGoS's term), each in a
module of its own: ground truth of connectivity (:mod:`mjswarm.experiments.awareness`),
faults (:mod:`mjswarm.experiments.faults`), launching (:mod:`mjswarm.experiments.
launching`), the vertex stations with the beacon service (:mod:`mjswarm.experiments.
stations`, :mod:`mjswarm.experiments.beacon_hand`) and the metrics
(:mod:`mjswarm.experiments.metrics`); the base station and a docked robot are
controllers of fixed radio nodes, stepped by the loop. None of them reads a
controller's attributes: the robots report through typed events and telemetry. A
recording is a loop function the caller hands in. One tick::

    before: truth sample (tables) -> faults -> launch -> stations' mail and grants
            -> the beacons handed to the world -> the observed state (metrics)
    loop:   sense base, docked robot and robots -> control -> act -> world step
    after:  metrics from reports and telemetry -> beliefs against truth -> tether truth
            -> recording; stop when completed, infeasible, all stopped or stalled

Choices it makes, beyond the paper:

* **Beacons** are a store keyed by the arena's vertex (Nagavarapu et al. emulated beacons with a
  central station over XBee, "separate information for each vertex"; so do we). A robot
  gets the beacon in its observation only while it stands on the vertex centre (within
  ``ON_VERTEX_M``; the station knows who stands on its centre, as the paper's station
  knew which vertex was calling), and only if the station granted it that vertex (or it
  was launched there).
* **Vertex entry** (our addition, needed once robots have bodies): a vertex area holds
  one robot at a time; the protocol is :mod:`algorithms.exploration.entry`, carried by
  the stations' link (:class:`~mjswarm.core.radio.Uplink`, one tick each way, counted in
  ``station_messages``), and the grants are :mod:`mjswarm.experiments.stations`' (which also
  explains why no circular wait can form); a robot that waits too long in a queue for
  a grant gives up its place and plans round that edge (step 8, counted in
  ``queue_give_ups``). ``--no-collision-avoidance`` turns this off
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
  disjoint access paths to R1 (Le et al.). Its *belief* is ``biconnected`` when it has
  two such paths; the *truth* (:func:`mjswarm.experiments.awareness.truth`) is whether it shares a
  biconnected component of three or more with R1 in the radio graph; both are sampled
  five times a second into ``radio_belief_agreement``. Robots in the depot or failed
  are off the air.
* **Exploration that stays connected** (``connectivity``): a base station at
  the root joins the robots' radio (links need line of sight, as between robots); every
  robot keeps its tether (:mod:`algorithms.exploration.tether`) from a radio-ranging
  sensor (range and bearing of its radio neighbours); the base adopts, beats and floods
  on; with ``biconnected`` the first robot in the launch order docks at the base (rule
  1: it stays in the depot, its radio on the base's mast, as the graph world's first
  robot stands on the root, and answers as the base does); relays on demand (rule 6)
  walk back along edges by turning on their lane, and the stations let a relay onto its
  requester's lane (:mod:`algorithms.exploration.entry`).
  A time unit of rules 5 and 6 is the edge the robots are told to expect (``expected_edge_m``,
  by default the arena's mean edge: a stated assumption, as the speed is) at the run's
  speed plus a scan. Ground
  truth every tick: networkx on the radio graph with the base (``cut_ticks``, ``fragile_ticks``).
  The robots' own stall verdict (rule 5) replaces the ``stall_timeout_s`` check.
  Tables (connectivity awareness) are off in these runs.
* **Metrics**: ``makespan`` is the largest number of edges any robot had traversed when
  completion was declared (the synchronous world's step count; Nagavarapu et al. counts "edge
  traversals"), ``total_traversals`` the sum; ``collisions`` are robot-robot contact events
  (ground truth, never seen by robots); ``speed_changes`` the collision rule's activations
  (eq. 27); ``heading_error_deg`` the largest odometry heading error of any robot, on
  lanes and at vertex calls (ground truth).
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable, Sequence

import numpy as np
from tqdm import tqdm

from algorithms.collision import CollisionRule, epsilons
from algorithms.connectivity import ConnectivityTable
from algorithms.exploration import Beacon, Strategy
from algorithms.exploration.entry import STATION
from algorithms.exploration.explorer import Explorer
from algorithms.exploration.relay import Flooder
from algorithms.exploration.tether import (
    BASE,
    BaseStation,
    FixedNode,
    Tether,
    docked,
    initial_parents,
)
from mjswarm.arena import ArenaSpec
from mjswarm.arena.builder import arena_world_spec
from mjswarm.core.bearing import BearingSensor
from mjswarm.arena.geometry import corridor_walls
from mjswarm.core.radio import (BASE_MAST_M, FADE_MARGIN_M, FADE_TOP_M, Radio, Uplink,
                                 sight_blocker)
from mjswarm.core.simulation import Simulation
from mjswarm.errors import RunInterrupted
from mjswarm.experiments.awareness import BeliefSampling, TetherTruth
from mjswarm.experiments.embodied import (  # noqa: F401 - the experiment's public names
    BEACON_LABEL,
    TETHER_MARGIN_M,
    TURN_RESERVE_M,
    EmbodiedConfig,
    EmbodiedResult,
    check_config,
    same_lane_bearing,
    stall_timeout,
    tether_unit_ticks,
)
from mjswarm.experiments.beacon_hand import BeaconHand
from mjswarm.experiments.faults import Faults
from mjswarm.experiments.launching import Launching, depot
from mjswarm.experiments.metrics import (
    ExplorationMetrics,
    Roster,
    reachable_part,
    team_cut_off,
)
from mjswarm.experiments.minds import make_minds, strategy_name
from mjswarm.experiments.radio_exploration import NEED, stall_verdict
from mjswarm.experiments.reach import robots_needed
from mjswarm.experiments.results import outcome
from mjswarm.experiments.stations import NearestVertex, StationService
from mjswarm.worlds.loop import Loop, LoopFunctions, Scene
from mjswarm.worlds.navigation import calibration, conventions
from mjswarm.worlds.sparkworld import SparkWorld
from mjswarm.worlds.wall_sight import wall_blocker

#: Wall seconds between status lines when progress goes to a log, not a terminal.
STATUS_EVERY_S = 30.0
#: Building the world is reported (with its wall time) when it takes longer than this
#: (s); on a terminal a transient line shows while it is being built.
BUILD_NOTE_S = 2.0


class EmbodiedExploration(LoopFunctions):
    """One embodied exploration run: build the world and the robots, compose the loop
    functions, run, and the result. ``functions``: more loop functions that watch the run
    (a recording, :class:`mjswarm.outputs.exploration_recording.ExplorationRecording`; a
    video), added after the experiment's own."""

    def __init__(self, spec: ArenaSpec, minds: list[Strategy], config: EmbodiedConfig,
                 seed: int | None = None, functions: Sequence[LoopFunctions] = (),
                 progress: bool = False) -> None:
        """Check every parameter, then build the world (``progress``: say on stderr what
        is being built, and how long it took: a thousand robots take seconds)."""
        k = len(minds)
        order = check_config(spec, k, config)
        self.spec, self.minds, self.config, self.seed = spec, minds, config, seed
        self._needed: int | None = None  # robots_needed, once asked
        terminal = progress and sys.stderr.isatty()
        if terminal:  # a transient line, cleared when the world is built
            print(f"explore: building {spec.name} with {k} robot(s) ...", end="\r",
                  file=sys.stderr, flush=True)
        built = time.perf_counter()
        order = self._build_world(order)
        self.robots = self._build_robots()
        controllers: dict = dict(enumerate(self.robots))
        if self.world.fixed:  # the base station at the root, on the robots' radio
            controllers[BASE] = FixedNode(BaseStation(Flooder()))
        for i in self.world.docked:  # rule 1: the first robot docks at the base
            controllers[i] = FixedNode(docked(Flooder()))
        self.loop = Loop(self.world, controllers, [*self._functions(order), *functions])
        took = time.perf_counter() - built
        if terminal:
            print("\033[K", end="", file=sys.stderr, flush=True)
        if progress and took > BUILD_NOTE_S:
            print(f"explore: built {spec.name} with {k} robot(s) in {took:.1f} s",
                  file=sys.stderr, flush=True)

    def _build_world(self, order: list[int]) -> list[int]:
        """The simulation, the world with its beacons, stations' link, base and radio;
        the launch order without a docked robot."""
        spec, config, seed, k = self.spec, self.config, self.seed, len(self.minds)
        tied = config.connectivity != "none"
        self.sim = Simulation(arena_world_spec(spec, depot(spec, k)), seed=seed or 0,
                              line_noise_m=config.line_noise_m, ir_noise_m=config.ir_noise_m,
                              wheel_slip=config.wheel_slip, physics=config.physics)
        bearing = BearingSensor(
            self.sim, math.radians(config.bearing_fov_deg), config.bearing_range_m,
            math.radians(config.bearing_noise_deg), seed=seed or 0)
        self.world = SparkWorld(self.sim, bearing, present=np.zeros(k, bool), ranging=tied,
                                beacons={v: Beacon() for v in spec.vertices})
        self.uplink = Uplink(STATION)
        self.world.uplinks[STATION] = self.uplink
        root_xy = tuple(spec.vertices[spec.root])
        if tied:
            self.world.fixed = {BASE: root_xy}
        if NEED.get(config.connectivity) == 2:
            self.world.docked = {order[0]: root_xy}
            order = order[1:]
        if tied:  # the leash backs off a fading link before it is cut
            self.world.fading = wall_blocker(
                corridor_walls(spec), self.world.positions,
                dict.fromkeys([*self.world.fixed, *self.world.docked], BASE_MAST_M),
                grow_m=FADE_MARGIN_M, grow_top_m=FADE_TOP_M)
        if config.radio_range_m is not None:
            self.world.attach_radio(Radio([*range(k), *self.world.fixed],
                                          range_m=config.radio_range_m,
                                          blocked=sight_blocker(
                                              self.sim, {**self.world.fixed, **self.world.docked},
                                              BASE_MAST_M),
                                          neighbours=self.sim.neighbours))
        return order

    def _build_robots(self) -> list[Explorer]:
        """One :class:`Explorer` per mind (a docked robot's never steps)."""
        config, sim, world = self.config, self.sim, self.world
        tied = config.connectivity != "none"
        cal, conv = calibration(sim.geometry, sim.physics), conventions(sim.geometry)
        eps = config.epsilons or epsilons(len(self.minds))
        ticks = tether_unit_ticks(self.spec, config, sim.control_dt_s)
        need, first = NEED.get(config.connectivity, 1), next(iter(world.docked), None)
        return [
            Explorer(mind, cal, conv, config.speed_m_s,
                     CollisionRule(config.speed_m_s, e, dt=sim.control_dt_s,
                                   same_lane=same_lane_bearing(config.bearing_range_m))
                     if config.collision_avoidance else None,
                     config.turn_rate_rad_s, config.idle_wait_s,
                     ConnectivityTable(i, 0) if config.radio_range_m is not None and not tied
                     else None,
                     sim.control_dt_s,
                     Tether(i, config.radio_range_m, initial_parents(i, need, first),
                            margin_m=TETHER_MARGIN_M, ticks_per_unit=ticks,
                            reserve_m=TURN_RESERVE_M)
                     if tied and i not in world.docked else None)
            for i, (mind, e) in enumerate(zip(self.minds, eps))]

    def _functions(self, order: list[int]) -> list[LoopFunctions]:
        """The experiment's loop functions, in the order their hooks run."""
        spec, config, world = self.spec, self.config, self.world
        tied = config.connectivity != "none"
        k = len(self.minds)
        self.roster = Roster(world.docked)
        nearest = NearestVertex(self.sim, spec, world.present)
        self.beliefs = (BeliefSampling(world) if world.radio is not None and not tied
                        else None)
        self.stations = StationService(spec, world, self.uplink, nearest,
                                       config.collision_avoidance)
        self.launching = Launching(spec, world, order, config.launch_interval_s,
                                   self.stations, self.roster)
        self.metrics = ExplorationMetrics(
            world, self.roster, nearest, spec.root, None if tied else stall_timeout(spec, config),
            lambda paths: stall_verdict(k, config.radio_range_m, paths, len(spec.edges),
                                        self.robots_needed(),
                                        k - len(self.metrics.stopped)))
        self.faults = Faults(world, config.faults, switched_off=(
            self.stations.switched_off, self.launching.switched_off, self.metrics.switched_off))
        self.tether_truth = TetherTruth(world) if tied else None
        return [f for f in (self.beliefs, self.faults, self.launching, self.stations,
                            BeaconHand(world, self.stations), self.metrics,
                            self.tether_truth, self) if f is not None]

    # ------------------------------------------------------------------ running
    def run(self, progress: bool = False) -> EmbodiedResult:
        """Run the loop (:meth:`Loop.run`) until a loop function ends the run or
        ``max_sim_time_s``; the result.

        ``progress``: on a terminal, a bar of simulated seconds (there is no honest total:
        a run ends when a robot declares completion) with the edge traversals so far;
        elsewhere (logs, CI) a status line on stderr every ``STATUS_EVERY_S`` of wall
        time and one at the end. Ctrl-C raises :class:`RunInterrupted` with the result so
        far."""
        ticks = int(self.config.max_sim_time_s / self.sim.control_dt_s)
        bar = tqdm(unit="sim s", desc=f"explore {self.spec.name}", leave=False,
                   disable=not (progress and sys.stderr.isatty()))
        log = progress and bar.disable
        self._shown, self._start = 0, time.perf_counter()
        self._last_status = self._start
        try:
            self.loop.run(max_ticks=ticks, on_tick=lambda loop: self.ticked(bar, log))
        except KeyboardInterrupt:
            self.metrics.ended_because = "interrupted"
            raise RunInterrupted(self._end(bar, log)) from None
        return self._end(bar, log)

    def ticked(self, bar: tqdm, log: bool) -> None:
        """After each tick: the progress display."""
        now = int(self.sim.time_s)
        if now > self._shown:
            bar.update(now - self._shown)
            self._shown = now
            bar.set_postfix(edges=self.metrics.traversals, refresh=False)
        if log and time.perf_counter() - self._last_status >= STATUS_EVERY_S:
            self._last_status = time.perf_counter()
            print(self._status(self._last_status - self._start), file=sys.stderr, flush=True)

    def _end(self, bar: tqdm, log: bool) -> EmbodiedResult:
        """Close the progress display, mark the end of the run, and the result."""
        bar.close()
        wall = time.perf_counter() - self._start
        result = self.result(wall=wall)
        self.loop.event(f"run ended: {result.ended_because}")
        if log:
            print(self._status(wall), file=sys.stderr, flush=True)
        return result

    def step(self) -> None:
        """One control tick of the loop (for tests and scripts that drive it by hand)."""
        self.loop.step()

    def _status(self, wall_s: float) -> str:
        """One line for logs: where the run is."""
        world = self.world
        launched = sum(1 for j in range(world.n) if (world.present[j] or j in self.roster.failed)
                       and j not in world.docked)
        return (f"explore {self.spec.name}: {self.sim.time_s:.0f} s simulated in "
                f"{wall_s:.0f} s, {self.metrics.traversals} edge traversals, "
                f"{launched} of {world.n} robots launched"
                f"{', 1 docked at the base' if world.docked else ''}, "
                f"{len(self.metrics.stopped)} stopped")

    def robots_needed(self) -> int:
        """The fewest robots that could reach every edge under the run's constraint and
        radio (:func:`~mjswarm.experiments.reach.robots_needed`; computed once)."""
        if self._needed is None:
            spec, config = self.spec, self.config
            self._needed = robots_needed(spec.vertices, spec.edges, spec.root,
                                         config.radio_range_m, corridor_walls(spec),
                                         BASE_MAST_M, config.connectivity)
        return self._needed

    def _stall(self) -> dict:
        """The result's fields on rule 5's verdict (:func:`stall_verdict`)."""
        m = self.metrics
        if not m.infeasible:
            return {}
        infeasible, reason = m.stall_verdict(m.paths)
        return {"infeasible": infeasible, "stalled": not infeasible, "reason": reason,
                "robots_needed": self.robots_needed()}

    def closed_items(self) -> list[tuple[str, tuple[int, float]]]:
        """The closed vertices (:attr:`StationService.closed`), in the order they closed."""
        return sorted(self.stations.closed.items(), key=lambda item: item[1][1])

    @property
    def declared(self) -> tuple[float, int, str] | None:
        """(time s, robot, vertex) of the completion declared, or None."""
        return self.metrics.declared

    def scene(self, loop: Loop) -> Scene:
        """Pictures mark the vertices whose beacon has been dropped (m)."""
        return Scene([self.spec.vertices[v] for v, b in self.world.beacons.items()
                      if b.id is not None], BEACON_LABEL)

    # ------------------------------------------------------------------ result
    def result(self, loop: Loop | None = None, wall: float = 0.0) -> EmbodiedResult:
        """The measurements so far (``wall``: wall-clock seconds spent, for the rates)."""
        m, sim, radio = self.metrics, self.sim, self.world.radio
        connected, biconnected = (None, None) if self.tether_truth is None else \
            self.tether_truth.shares()
        truth = self.tether_truth
        true_edges = {tuple(sorted(e)) for e in self.spec.edges}
        closed, ended, unreachable = self.stations.closed, m.ended_because, []
        # a team cut off from its root completes with nobody declaring, its map
        # the union of the cut-off robots' maps (team_cut_off)
        cut_off = team_cut_off(self.roster, self.world.n, ended) if closed else None
        declared_map, makespan = m.declared_map, m.makespan
        if cut_off is not None:
            declared_map = sorted({e for _, _, edges in cut_off.values() for e in edges})
            makespan, ended = max(len(p) - 1 for p in m.paths), "completed"
        found = outcome(strategy_name(self.minds), m.declared, declared_map, makespan,
                        m.paths, m.beacon_vertex, true_edges, arena=self.spec.name,
                        root=self.spec.root, edge_time="physics", seed=self.seed)
        if closed:  # the part it could reach (EmbodiedResult's fields)
            found["completed"] = found["completed"] or cut_off is not None
            sources = [(self.spec.root, math.inf)] if cut_off is None else [
                (v, t) for t, v, _ in cut_off.values()]
            mapped = set(found["map_edges"])
            reachable, unreachable = reachable_part(true_edges, sources, closed, mapped)
            found["map_correct"] = found["completed"] and reachable <= mapped <= true_edges
            if ended == "completed" and unreachable:
                ended = "completed reachable part"
        return EmbodiedResult(
            **found,
            collisions=sim.collisions.count,
            speed_changes=m.speed_changes,
            sim_time_s=sim.time_s,
            wall_time_s=wall,
            realtime_factor=sim.time_s / wall if wall > 0 else math.inf,
            radio_messages=None if radio is None else radio.total_sent,
            radio_max_messages_per_robot=None if radio is None else max(radio.sent.values()),
            radio_belief_agreement=None if self.beliefs is None else self.beliefs.agreement,
            station_messages=self.uplink.sent_up + self.uplink.sent_down,
            queue_give_ups=self.stations.gave_up,
            connectivity=self.config.connectivity,
            cut_ticks=0 if truth is None else truth.cut_ticks,
            fragile_ticks=0 if truth is None else truth.fragile_ticks,
            connected_share=connected,
            biconnected_share=biconnected,
            **self._stall(),
            relay_trips=m.relay_trips,
            ended_because=ended,
            closed_vertices=[{"vertex": v, "robot": r + 1, "at_s": round(t, 2)}
                             for v, (r, t) in self.closed_items()],
            unreachable_edges=unreachable,
            cut_off_robots=[{"robot": i + 1, "vertex": v, "at_s": round(t, 2)}
                            for i, (t, v, _) in sorted(self.roster.cut_off.items())],
            stopped_robots=list(m.stopped),
            heading_error_deg=round(math.degrees(m.heading_error_rad), 3),
            faults=self.faults.log(),
        )


def explore_embodied(spec: ArenaSpec, n_robots: int,
                     strategy: str | Callable[..., Strategy] = "incidence-dfs",
                     config: EmbodiedConfig | None = None, seed: int | None = None,
                     functions: Sequence[LoopFunctions] = (),
                     progress: bool = False) -> EmbodiedResult:
    """Explore ``spec`` with ``n_robots`` embodied robots running ``strategy`` (a name
    from ``STRATEGIES`` or a factory ``(index, n_robots, rng) -> Strategy``), watched by
    ``functions`` (a recording, a video)."""
    minds = make_minds(strategy, n_robots, seed)
    run = EmbodiedExploration(spec, minds, config or EmbodiedConfig(), seed, functions,
                              progress=progress)
    return run.run(progress=progress)
