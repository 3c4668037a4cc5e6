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
* **The speed rule applies on edges** (on a lane, seed 003 Sec. 4 "traversing an
  edge"); in the vertex area (turns, scans, the sidesteps between lane and vertex
  centre) robots move at S and are kept apart by vertex entry. Applied at the vertex
  centre too, the rule's "beta = 0: stop" would stop a robot facing a robot on the next
  vertex along its edge, which may be waiting to enter this vertex: a deadlock.
* **Vertex entry** (our addition, needed once robots have bodies): a robot that enters a
  corridor (has seen 5 cm of its left wall, at least 0.31 m from either end vertex) asks
  the station of the vertex ahead for entry over its radio link and waits on its lane
  while another robot holds the vertex. It holds the vertex until it is in the corridor
  of its next edge. Seed 003's robots spent a second or two at a vertex; ours scan for
  about ten, and a robot's approach and departure sidesteps near a vertex centre cross
  the lanes of the neighbouring edges. ``--no-collision-avoidance`` turns this off
  together with the speed rule.
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
import time
from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from algorithms.collision import CollisionRule, epsilons
from algorithms.exploration import Beacon, Strategy
from algorithms.exploration.base import AngleMismatch
from algorithms.navigation import NavigatorState
from mjswarm.arena import ArenaSpec
from mjswarm.arena.builder import arena_world_spec
from mjswarm.awareness import TableAwareness
from mjswarm.bearing import BearingSensor
from mjswarm.errors import MjswarmError
from mjswarm.graphworld import ExplorationResult, make_minds
from mjswarm.navigation import NavigationDriver, percepts
from mjswarm.simulation import Simulation
from mjswarm.world import Pose2D

#: A robot is on a vertex when within this distance of its centre (m).
ON_VERTEX_M = 0.05
#: The root counts as free for a launch when no active robot is this close to it (m).
ROOT_CLEAR_M = 0.35
DEPOT_SPACING_M = 0.4
DEPOT_OFFSET_M = 1.5


@dataclass
class EmbodiedConfig:
    """Parameters of an embodied run (SI units).

    Attributes:
        speed_m_s: the initial speed S of every robot (seed 003's experiments: 0.05).
        collision_avoidance: the speed rule and the vertex-entry check (see module doc).
        epsilons: per-robot eps_k (eq. 28); default :func:`algorithms.collision.epsilons`.
        launch_interval_s: least time between two launches from the root.
        launch_order: robot indices in launch order (default 0, 1, ...).
        idle_wait_s: how long a robot whose strategy answered IDLE waits before asking again.
        max_sim_time_s: give up after this much simulated time.
        turn_rate_rad_s: in-place turn and scan rate.
        bearing_fov_deg, bearing_range_m, bearing_noise_deg: the bearing sensor.
        radio_range_m: with a range (m), robots carry radios and keep connectivity tables
            (:mod:`mjswarm.awareness`); None: no radio.
    """

    speed_m_s: float = 0.05
    collision_avoidance: bool = True
    epsilons: list[float] | None = None
    launch_interval_s: float = 2.0
    launch_order: list[int] | None = None
    idle_wait_s: float = 2.0
    max_sim_time_s: float = 3600.0
    turn_rate_rad_s: float = 1.0
    bearing_fov_deg: float = 60.0
    bearing_range_m: float = 1.0
    bearing_noise_deg: float = 0.0
    radio_range_m: float | None = None


@dataclass
class EmbodiedResult(ExplorationResult):
    """An embodied run's measurements: the graph world's keys plus physics ones.

    ``edge_time`` is ``"physics"``; ``makespan`` counts edges (see the module docstring).
    """

    collisions: int = 0
    speed_changes: int = 0
    sim_time_s: float = 0.0
    wall_time_s: float = 0.0
    realtime_factor: float = 0.0
    #: robots that stopped: lost their line, or their angles no longer match the beacons
    lost_robots: list[int] = field(default_factory=list)
    #: with a radio: messages sent in all, by the busiest robot, and the share of sampled
    #: robot beliefs ("biconnected" or not) that equalled the truth
    radio_messages: int | None = None
    radio_max_messages_per_robot: int | None = None
    radio_belief_agreement: float | None = None


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
        eps = config.epsilons or epsilons(k)
        if len(eps) != k:
            raise MjswarmError(f"need {k} epsilons, got {len(eps)}")
        self.spec, self.minds, self.config, self.seed = spec, minds, config, seed
        self.recorder = recorder
        xs = [x for x, _ in spec.vertices.values()]
        ys = [y for _, y in spec.vertices.values()]
        depot = [Pose2D(min(xs) + DEPOT_SPACING_M * i, min(ys) - DEPOT_OFFSET_M, 0.0)
                 for i in range(k)]
        self.sim = Simulation(arena_world_spec(spec, depot), seed=seed or 0)
        if self.sim.geometry.max_speed_m_s < config.speed_m_s:
            raise MjswarmError(
                f"speed {config.speed_m_s} m/s exceeds the robot's top speed "
                f"{self.sim.geometry.max_speed_m_s:.2f} m/s")
        self.driver = NavigationDriver(self.sim, [0.0] * k, config.speed_m_s,
                                       config.turn_rate_rad_s)
        self.bearing = BearingSensor(
            self.sim, math.radians(config.bearing_fov_deg), config.bearing_range_m,
            math.radians(config.bearing_noise_deg), seed=seed or 0)
        self.rules = [CollisionRule(config.speed_m_s, e, dt=self.sim.control_dt_s) for e in eps]
        self.beacons = {v: Beacon() for v in spec.vertices}
        self.beacon_vertex: dict[str, str] = {}
        self.launch_queue = order
        self.active = [False] * k
        self.done = [False] * k
        self.waiting_since: list[float | None] = [None] * k  # IDLE
        # vertex entry: vertex -> robot holding it; each robot's vertex ahead (requested or
        # held) and the vertex it is leaving (held until it is clear of it)
        self.holder: dict[str, int] = {}
        self.ahead: list[str | None] = [None] * k
        self.leaving: list[str | None] = [None] * k
        self.paths = [[spec.root] for _ in range(k)]
        self.handled_events = [0] * k
        self.last_launch = -math.inf
        self.declared: tuple[float, int, str] | None = None
        self.confused: list[int] = []  # robots whose angles stopped matching the beacons
        self.awareness = None
        if config.radio_range_m is not None:
            if config.radio_range_m <= 0:
                raise MjswarmError(f"radio range must be positive, got {config.radio_range_m} m")
            self.awareness = TableAwareness(self.sim, config.radio_range_m)
        self._vertices = np.array(list(spec.vertices.values()))
        self._vertex_ids = list(spec.vertices)

    # ------------------------------------------------------------------ loop
    def run(self, progress: bool = False) -> EmbodiedResult:
        cfg = self.config
        start = time.perf_counter()
        ticks = int(cfg.max_sim_time_s / self.sim.control_dt_s)
        bar = tqdm(total=round(cfg.max_sim_time_s), unit="sim s", disable=not progress,
                   desc=f"explore {self.spec.name}", leave=False)
        shown = 0
        for _ in range(ticks):
            self.step()
            if self.declared is not None or all(self.done):
                break
            now = int(self.sim.time_s)
            if now > shown:
                bar.update(now - shown)
                shown = now
                bar.set_postfix(edges=sum(len(p) - 1 for p in self.paths))
        bar.close()
        return self.result(time.perf_counter() - start)

    def step(self) -> None:
        """One control tick: launch, sense, decide, act, simulate."""
        sim, cfg = self.sim, self.config
        self._launch_if_free()
        speeds = np.zeros(sim.n)
        bearings = self.bearing.read() if cfg.collision_avoidance else None
        v = np.zeros(sim.n)
        w = np.zeros(sim.n)
        for i, (nav, percept) in enumerate(zip(self.driver.navigators, percepts(sim))):
            if not self.active[i] or self.done[i]:
                continue
            vi, wi = nav.update(percept)
            self._handle_events(i)
            speed = cfg.speed_m_s
            if cfg.collision_avoidance:
                if nav.on_lane:  # the rule governs edge traversals
                    speed = self.rules[i].update(bearings[i])
                else:
                    self.rules[i].forget_bearings()
                if self._blocked_at_vertex_entry(i):
                    speed = 0.0
            factor = speed / cfg.speed_m_s
            if vi != 0.0:  # translations run at the rule's speed; turns in place do not
                vi, wi = vi * factor, wi * factor
            v[i], w[i], speeds[i] = vi, wi, speed
        sim.set_velocity(v, w)
        sim.step()
        if self.awareness is not None:
            self._radio_tick()
        if self.recorder is not None:
            self.recorder.log_tick(sim.step_count, sim.time_s, sim.poses(),
                                   sim.readings()["line"], sim.readings()["ir"], speeds,
                                   [list(b.items()) for b in bearings] if bearings else
                                   [[] for _ in range(sim.n)])

    # ------------------------------------------------------------------ robots
    def _radio_tick(self) -> None:
        """Tables follow the moving radio graph; beliefs sampled 5 times a second."""
        aware = self.awareness
        aware.step(np.array(self.active))
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
        if self.config.collision_avoidance and self.spec.root in self.holder:
            return
        i = self.launch_queue.pop(0)
        self.sim.place_robot(i, Pose2D(root[0], root[1], 0.0))
        self.active[i] = True
        self.last_launch = self.sim.time_s
        self.holder.setdefault(self.spec.root, i)
        self.ahead[i] = self.spec.root
        self.driver.navigators[i].begin_at_vertex()
        self._event(i, f"r{i} launched at {self.spec.root}")

    def _handle_events(self, i: int) -> None:
        nav = self.driver.navigators[i]
        new = nav.events[self.handled_events[i]:]
        self.handled_events[i] = len(nav.events)
        for event in new:
            if event == "arrived":
                self.rules[i].crossed_vertex()  # eq. (34)
                # the scan right after a launch is no arrival: the robot came by no edge
                self._at_vertex(i, arrived=nav.arrived_angle is not None)
            elif event == "left_vertex":  # the vertex it stood on is now behind it
                self.leaving[i], self.ahead[i] = self.ahead[i], None
            elif event.startswith("lost"):
                self.done[i] = True
                self._release(i, self.ahead[i])
                self._release(i, self.leaving[i])
                self._event(i, f"r{i} {event}")
        waiting = self.waiting_since[i]
        if waiting is not None and self.sim.time_s - waiting >= self.config.idle_wait_s:
            self.waiting_since[i] = None
            self._at_vertex(i, arrived=False)

    def _at_vertex(self, i: int, arrived: bool) -> None:
        """The strategy's vertex call: beacon in, decision out."""
        nav = self.driver.navigators[i]
        vertex = self._vertex_under(i)
        if vertex is None:
            self.done[i] = True
            self._event(i, f"r{i} is not on a vertex centre after arriving; stopped")
            return
        if arrived:
            self.paths[i].append(vertex)
            self._event(i, f"r{i} at {vertex}")
        beacon = self.beacons[vertex]
        try:
            decision = self.minds[i].on_vertex(beacon, nav.edge_angles,
                                               nav.arrived_angle if arrived else None)
        except AngleMismatch as exc:  # its heading reference is broken (e.g. after a crash)
            self.done[i] = True
            self.confused.append(i)
            self._event(i, f"r{i} cannot match its angles with the beacon at {vertex}: {exc}")
            return
        if beacon.id is not None:
            self.beacon_vertex.setdefault(beacon.id, vertex)
        if self.recorder is not None:
            self._record_vertex_call(i, vertex, beacon)
        if decision.action == "go":
            angle = min(nav.edge_angles,
                        key=lambda a: abs(math.remainder(a - decision.angle, 2 * math.pi)))
            nav.depart(angle)
        elif decision.action == "idle":
            self.waiting_since[i] = self.sim.time_s
        elif decision.action == "done":
            self.declared = (self.sim.time_s, i, vertex)
            self.done[i] = True
            self._event(i, f"r{i} declares completion at {vertex}")
        else:
            raise ValueError(f"robot {i + 1} answered an unknown decision {decision!r}")

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

    def _blocked_at_vertex_entry(self, i: int) -> bool:
        """Vertex entry: a robot asks for the vertex ahead once it is in the corridor (has
        seen its left wall) and waits on its lane while another robot holds it."""
        nav = self.driver.navigators[i]
        if not (nav.in_corridor or nav.state is NavigatorState.ARRIVING):
            return False
        if self.leaving[i] is not None:  # in the next corridor: clear of the vertex left
            self._release(i, self.leaving[i])
            self.leaving[i] = None
        if self.ahead[i] is None:
            self.ahead[i] = self._vertex_ahead(i)
        return self.holder.setdefault(self.ahead[i], i) != i

    def _vertex_ahead(self, i: int) -> str:
        """The vertex the edge under robot ``i`` leads to (the station it calls): the
        nearest vertex ahead within 0.15 m of the robot's line of travel."""
        x, y, yaw = self.sim.poses()[i]
        rel = self._vertices - (x, y)
        along = rel @ (math.cos(yaw), math.sin(yaw))
        across = np.abs(rel @ (-math.sin(yaw), math.cos(yaw)))
        candidates = np.flatnonzero((along > 0.0) & (across < 0.15))
        if len(candidates) == 0:  # not heading at any vertex: ask the nearest
            return self._vertex_ids[int(np.argmin(np.hypot(*rel.T)))]
        return self._vertex_ids[int(candidates[np.argmin(along[candidates])])]

    def _release(self, i: int, vertex: str | None) -> None:
        if vertex is not None and self.holder.get(vertex) == i:
            del self.holder[vertex]

    def _event(self, i: int | None, text: str) -> None:
        if self.recorder is not None:
            self.recorder.log_event(self.sim.step_count, self.sim.time_s, text, i)

    # ------------------------------------------------------------------ metrics
    def result(self, wall: float = 0.0) -> EmbodiedResult:
        """The measurements so far (``wall``: wall-clock seconds spent, for the rates)."""
        per_robot = [len(p) - 1 for p in self.paths]
        map_edges: list[tuple[str, str]] = []
        declared_by = declared_at = None
        if self.declared is not None:
            _, i, declared_at = self.declared
            declared_by = i + 1
            map_edges = sorted(
                tuple(sorted((self.beacon_vertex[a], self.beacon_vertex[b])))
                for a, b in self.minds[i].map_edges())
        truth = {tuple(sorted(e)) for e in self.spec.edges}
        sim_time = self.sim.time_s
        return EmbodiedResult(
            arena=self.spec.name,
            strategy=getattr(self.minds[0], "name", type(self.minds[0]).__name__),
            robots=len(self.minds),
            root=self.spec.root,
            edge_time="physics",
            seed=self.seed,
            completed=self.declared is not None,
            makespan=max(per_robot) if self.declared is not None else None,
            total_traversals=sum(per_robot),
            traversals_per_robot=per_robot,
            declared_by=declared_by,
            declared_at=declared_at,
            map_edges=map_edges,
            map_correct=self.declared is not None and set(map_edges) == truth,
            paths=self.paths,
            collisions=self.sim.collisions.count,
            speed_changes=sum(r.activations for r in self.rules),
            sim_time_s=sim_time,
            wall_time_s=wall,
            realtime_factor=sim_time / wall if wall > 0 else math.inf,
            radio_messages=None if self.awareness is None else self.awareness.radio.total_sent,
            radio_max_messages_per_robot=(None if self.awareness is None
                                          else max(self.awareness.radio.sent.values())),
            radio_belief_agreement=None if self.awareness is None else self.awareness.agreement,
            lost_robots=sorted(self.confused + [
                i for i, nav in enumerate(self.driver.navigators)
                if nav.state is NavigatorState.LOST]),
        )


def explore_embodied(spec: ArenaSpec, n_robots: int, strategy: str = "incidence-dfs",
                     config: EmbodiedConfig | None = None, seed: int | None = None,
                     recorder=None, progress: bool = False) -> EmbodiedResult:
    """Explore ``spec`` with ``n_robots`` embodied robots running ``strategy``."""
    minds = make_minds(strategy, n_robots, seed)
    run = EmbodiedExploration(spec, minds, config or EmbodiedConfig(), seed, recorder)
    return run.run(progress=progress)
