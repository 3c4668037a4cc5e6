"""The graph world with a radio: seed 003 exploration under a connectivity constraint.

Not yet on the one loop (:mod:`mjswarm.worlds.loop`): a run (``_ConnectedRun``) is
still world, loop and ground truth in one class, because its tick has a phase the loop
does not have: robots answer what they hear after everyone has moved, and those answers
are delivered at the next tick's start. On the loop they would be delivered one tick
later, and the connected-exploration results would change; it lives with the
experiments until that is settled.

Time runs in ticks of ``1 / TICKS_PER_UNIT`` time units. A robot crosses an edge in its
duration (one time unit, or proportional to its length: ``edge_time`` as in
:class:`~mjswarm.worlds.graphworld.GraphWorld`) at constant speed along the straight
segment between the vertices' positions (metres), unless it waits. The base station stands
at the root. Radio links join robots, and the base, within ``radio_range_m`` of each other
(:class:`~mjswarm.core.radio.Radio`: one tick latency, every message counted).

``connectivity``:

* ``"none"``: seed 003 unchanged (robots never wait; no messages).
* ``"connected"`` / ``"biconnected"``: each robot keeps its tether of one / two parents
  (:mod:`algorithms.exploration.tether`; with ``biconnected`` robot 0 docks at the base,
  rule 1, and explores nothing) and
  stuck robots are brought relays (:mod:`algorithms.exploration.relay`); robots walk
  edges both ways and may stop part-way.

One tick, for every robot in descending index (the order of seed 003's Fig. 9 run):

1. deliver the radio, and let every robot and the base read its messages;
2. robots that reached a vertex in the last tick (and idle robots whose time unit is up)
   let their strategy decide, all bookkeeping first, as in the graph world;
3. every robot that wants to move asks its tether whether it may take its step; the steps
   are taken together;
4. robots that wanted to move and could not, or could use a parent nearer the base, ask
   for adoption; every robot beats;
5. ground truth (loop functions only): the radio graph of the base and the robots, with
   networkx, counts the ticks in which some robot has no route to the base, and those in
   which the graph is not biconnected (one robot failing would cut someone off).

The run ends when a robot declares completion, when a robot declares a stall (rule 5 of
the tether: the result is ``infeasible``, with the explored share of the true edges), or
at ``max_time``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import networkx as nx
import numpy as np

from algorithms.exploration import Beacon, Strategy
from algorithms.exploration.relay import ConnectedExplorer, Flooder
from algorithms.exploration.tether import BASE, BaseStation, Tether, docked, initial_parents
from mjswarm.core.radio import Radio
from mjswarm.errors import MjswarmError
from mjswarm.experiments.minds import strategy_name
from mjswarm.experiments.results import ExplorationResult, outcome
from mjswarm.worlds.graphworld import GraphWorld

CONNECTIVITY = ("none", "connected", "biconnected")
#: Parents each robot keeps under each constraint (rule 1 of the tether).
NEED = {"connected": 1, "biconnected": 2}
#: Control ticks per time unit (one edge in the unit-time graph world).
TICKS_PER_UNIT = 10


def infeasible_reason(robots: int, range_m: float, paths: list[list], edges: int) -> str:
    """The verdict of a team that declared a stall (rule 5 of the tether), with the share
    of the ``edges`` true edges its ``paths`` (vertex sequences, one per robot) covered."""
    explored = {tuple(sorted(e)) for p in paths for e in zip(p, p[1:])}
    return (f"infeasible with {robots} robots at range {range_m:g} m: explored "
            f"{len(explored)} of {edges} edges")


def need_robots(connectivity: str, robots: int) -> None:
    """Refuse a ``biconnected`` team of one: its first robot docks at the base (rule 1 of
    :mod:`algorithms.exploration.tether`), so nobody would explore."""
    if NEED.get(connectivity) == 2 and robots < 2:
        raise MjswarmError("connectivity biconnected needs at least 2 robots: the first "
                           "docks at the base (rule 1 of the tether)")


@dataclass
class ConnectedExplorationResult(ExplorationResult):
    """An exploration under a connectivity constraint (times in time units).

    Attributes (beyond :class:`~mjswarm.experiments.results.ExplorationResult`'s):
        connectivity: the constraint.
        radio_range_m: the radio range (m).
        messages: radio transmissions, base included.
        connected_share: share of ticks in which every robot had a route to the base
            (ground truth).
        cut_ticks: ticks in which some robot had none.
        biconnected_share: share of ticks in which the radio graph of the base and the
            robots was biconnected (ground truth).
        fragile_ticks: ticks in which it was not.
        relay_trips: relay missions the robots set out on (rule 6 of
            :mod:`algorithms.exploration.relay`).
        infeasible: whether the team declared that it cannot go on.
        reason: why, with the explored share of the true edges; None otherwise.
    """

    connectivity: str = "none"
    radio_range_m: float = math.inf
    messages: int = 0
    connected_share: float = 1.0
    cut_ticks: int = 0
    biconnected_share: float = 1.0
    fragile_ticks: int = 0
    relay_trips: int = 0
    infeasible: bool = False
    reason: str | None = None


class RadioGraphWorld:
    """A :class:`~mjswarm.worlds.graphworld.GraphWorld`'s graph, with positions, time in
    ticks, a base at the root and a radio of range ``radio_range_m`` (m)."""

    def __init__(self, world: GraphWorld, radio_range_m: float, connectivity: str = "connected"):
        if connectivity not in CONNECTIVITY:
            raise MjswarmError(f"connectivity must be one of {', '.join(CONNECTIVITY)}, "
                               f"got '{connectivity}'")
        if not (math.isfinite(radio_range_m) and radio_range_m > 0):
            raise MjswarmError(f"radio range must be a positive number of metres, got {radio_range_m}")
        self.world = world
        self.range_m = radio_range_m
        self.connectivity = connectivity
        self.pos = {v: np.array(p, float) for v, p in world.graph.nodes(data="pos")}

    def run(self, minds: list[Strategy], *, seed: int | None = None,
            max_time: float | None = None, arena: str = "<graph>") -> ConnectedExplorationResult:
        """Explore with ``minds`` (one per robot) from the root (module docstring)."""
        need_robots(self.connectivity, len(minds))
        if max_time is None:
            max_time = 50 * (len(self.world.edges) + 1) + 100
        run = _ConnectedRun(self, minds)
        last_tick = math.floor(max_time * TICKS_PER_UNIT)
        while run.declared is None and run.infeasible is None and run.ticks < last_tick:
            run.tick()
        return run.result(seed, arena)

    def _step(self, e: tuple[str, str], progress: float,
              sense: int) -> tuple[float, tuple[float, float]]:
        """One tick's walk on edge ``e`` (``progress`` of it behind the robot) on along it
        (``sense`` +1) or back (-1): the share of the edge covered, and the displacement (m)."""
        v, u = e
        share = min(1.0 / (self.world.duration[e] * TICKS_PER_UNIT),
                    1.0 - progress if sense > 0 else progress)
        d = sense * share * (self.pos[u] - self.pos[v])
        return share, (float(d[0]), float(d[1]))

    def _around(self, radio: Radio, i: int, xy: np.ndarray) -> dict:
        """Robot ``i``'s range-and-bearing sensing of its radio neighbours (m, relative)."""
        here = xy[i]
        return {r: tuple(xy[len(xy) - 1 if r == BASE else r] - here) for r in radio.neighbors(i)}

    def _radio_graph(self, xy: np.ndarray) -> nx.Graph:
        """Ground truth: the radio graph of the robots and the base (the last node)."""
        g = nx.Graph()
        n = len(xy)
        g.add_nodes_from(range(n))
        d2 = ((xy[:, None] - xy[None]) ** 2).sum(axis=-1)
        g.add_edges_from(zip(*np.nonzero(np.triu(d2 <= self.range_m**2, 1))))
        return g


class _ConnectedRun:
    """One run of a :class:`RadioGraphWorld`: its state, and one tick in the phases of
    the module docstring (:meth:`tick`)."""

    def __init__(self, radio_world: RadioGraphWorld, minds: list[Strategy]) -> None:
        self.rw, self.minds = radio_world, minds
        w, k = radio_world.world, len(minds)
        self.constrained = radio_world.connectivity != "none"
        need = NEED.get(radio_world.connectivity, 1)
        # rule 1 for biconnected: robot 0 docks at the base (it stands on the root)
        self.dock = docked(Flooder()) if need == 2 else None
        self.robots = [None if self.dock is not None and i == 0 else
                       ConnectedExplorer(i, minds[i], Tether(
                           i, radio_world.range_m, initial_parents(i, need),
                           ticks_per_unit=TICKS_PER_UNIT))
                       for i in range(k)]
        self.base = BaseStation(Flooder())
        self.beacons = {v: Beacon() for v in w.graph}
        self.beacon_vertex: dict[str, str] = {}
        self.at: list[str | None] = [w.root] * k  # vertex, or None on an edge
        self.edge: list[tuple[str, str] | None] = [None] * k
        self.progress = [0.0] * k  # share of the edge behind the robot
        self.xy = np.array([radio_world.pos[w.root]] * (k + 1))  # robots, then the base
        self.arrived_by: list[float | None] = [None] * k
        self.wake = [0] * k  # tick at which a robot at a vertex decides
        self.paths = [[w.root] for _ in range(k)]
        self.radio = Radio(list(range(k)) + [BASE], range_m=radio_world.range_m)
        self.radio.move(self.xy)
        self.declared: tuple[float, int, str] | None = None
        self.infeasible: int | None = None
        self.cut = self.fragile = self.ticks = 0
        self.order = [i for i in range(k - 1, -1, -1) if self.robots[i] is not None]
        self.around: list[dict] = []

    def tick(self) -> None:
        """Hear, decide, move, answer, and the ground truth."""
        self.ticks = tick = self.ticks + 1
        if self.constrained:
            self._hear(tick)
        self._decide(tick)
        if self.declared is not None:
            return
        wanted, moved = self._move(tick)
        if self.constrained:
            self._answer(tick, wanted, moved)
        graph = self.rw._radio_graph(self.xy)
        self.cut += not nx.is_connected(graph)
        self.fragile += not nx.is_biconnected(graph)

    def _send(self, sender, messages) -> None:
        for m in messages:
            self.radio.send(sender, m.payload, m.to)

    def _hear(self, tick: int) -> None:
        """Deliver (the links are those of the last tick's end); everyone reads."""
        radio, xy = self.radio, self.xy
        radio.step()
        self.around = [self.rw._around(radio, i, xy) for i in range(len(self.minds))]
        for i in self.order:
            self._send(i, self.robots[i].hear(tick, radio.receive(i), self.around[i]))
        self._send(BASE, self.base.step(radio.receive(BASE)))
        if self.dock is not None:
            self._send(0, self.dock.step(radio.receive(0)))

    def _decide(self, tick: int) -> None:
        """Robots at a vertex whose time has come: all bookkeeping first, then the
        decisions one after another (the graph world's order)."""
        w, at, robots, beacons = self.rw.world, self.at, self.robots, self.beacons
        deciding = [i for i in self.order if at[i] is not None and self.wake[i] <= tick]
        for i in deciding:
            robots[i].arrive(beacons[at[i]], w.angles[at[i]], self.arrived_by[i])
        for i in deciding:
            v = at[i]
            decision = robots[i].on_vertex(beacons[v], w.angles[v], self.arrived_by[i])
            if beacons[v].id is not None and beacons[v].id not in self.beacon_vertex:
                self.beacon_vertex[beacons[v].id] = v
            if decision.action == "go":
                u = w.nearest_exit(v, decision.angle)[0]
                at[i], self.edge[i], self.progress[i] = None, (v, u), 0.0
                self.arrived_by[i] = w.angle_of[(u, v)]
            elif decision.action == "idle":
                self.arrived_by[i], self.wake[i] = None, tick + TICKS_PER_UNIT
            elif decision.action == "done":
                self.declared = (tick / TICKS_PER_UNIT, i, v)
                return
            else:
                raise ValueError(f"robot {i + 1} answered an unknown decision {decision!r}")

    def _move(self, tick: int) -> tuple[dict[int, tuple[float, float]], set[int]]:
        """Every robot on an edge takes its step if its tether allows; the steps it
        wanted and could not take, and who moved."""
        w, rw, robots = self.rw.world, self.rw, self.robots
        wanted: dict[int, tuple[float, float]] = {}
        moved = set()
        for i in self.order:
            if self.edge[i] is None:
                continue
            sense = robots[i].direction(self.progress[i]) if self.constrained else 1
            if sense == 0:
                continue
            v, u = self.edge[i]
            share, step = rw._step(self.edge[i], self.progress[i], sense)
            if self.constrained and not robots[i].tether.may_step(step, self.around[i]):
                wanted[i] = step
                continue
            moved.add(i)
            self.progress[i] += sense * share
            if sense > 0 and self.progress[i] >= 1.0 - 1e-9:
                self.at[i], self.edge[i], self.wake[i] = u, None, tick + 1
                self.paths[i].append(u)
            elif sense < 0 and self.progress[i] <= 1e-9:
                self.at[i], self.edge[i], self.wake[i] = v, None, tick + 1
                self.arrived_by[i] = w.angle_of[(v, u)]
                robots[i].arrived_back()
            self.xy[i] = rw.pos[v] + self.progress[i] * (rw.pos[u] - rw.pos[v])
        return wanted, moved

    def _answer(self, tick: int, wanted: dict, moved: set[int]) -> None:
        """After the moves: adoption requests and beats from the new places; the team's
        stall verdict (rule 5)."""
        self.radio.move(self.xy)
        for i in self.order:
            self._send(i, self.robots[i].after(tick, wanted.get(i), i in moved,
                                               self.rw._around(self.radio, i, self.xy)))
        if any(self.robots[i].tether.stalled(tick) for i in self.order):
            self.infeasible = tick

    def result(self, seed: int | None, arena: str) -> ConnectedExplorationResult:
        rw, w, declared, paths = self.rw, self.rw.world, self.declared, self.paths
        fields = outcome(strategy_name(self.minds), declared,
                         () if declared is None else self.minds[declared[1]].map_edges(),
                         None if declared is None else declared[0], paths,
                         self.beacon_vertex, w.edges, arena=arena, root=w.root,
                         edge_time=w.edge_time, seed=seed)
        reason = None if self.infeasible is None else infeasible_reason(
            len(self.minds), rw.range_m, paths, len(w.edges))
        ticks = max(self.ticks, 1)
        return ConnectedExplorationResult(
            **fields, connectivity=rw.connectivity, radio_range_m=rw.range_m,
            messages=self.radio.total_sent, connected_share=1.0 - self.cut / ticks,
            cut_ticks=self.cut, biconnected_share=1.0 - self.fragile / ticks,
            fragile_ticks=self.fragile,
            relay_trips=sum(self.robots[i].relay_trips for i in self.order),
            infeasible=self.infeasible is not None, reason=reason)
