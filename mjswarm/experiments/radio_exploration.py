"""The graph world with a radio: seed 003 exploration under a connectivity constraint.

Not yet on the one loop (:mod:`mjswarm.worlds.loop`): :meth:`RadioGraphWorld.run` is
still world, loop and loop functions in one method, because its tick has a phase the
loop does not have (robots answer what they hear after everyone has moved, and those
answers are delivered at the next tick's start); it lives with the experiments until it
is split.

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
        w, k = self.world, len(minds)
        if max_time is None:
            max_time = 50 * (len(w.edges) + 1) + 100
        constrained = self.connectivity != "none"
        need_robots(self.connectivity, k)
        need = NEED.get(self.connectivity, 1)
        # rule 1 for biconnected: robot 0 docks at the base (it stands on the root)
        dock = docked(Flooder()) if need == 2 else None
        robots = [None if dock is not None and i == 0 else
                  ConnectedExplorer(i, minds[i], Tether(i, self.range_m, initial_parents(i, need),
                                                        ticks_per_unit=TICKS_PER_UNIT))
                  for i in range(k)]
        base = BaseStation(Flooder())
        beacons = {v: Beacon() for v in w.graph}
        beacon_vertex: dict[str, str] = {}
        at: list[str | None] = [w.root] * k  # vertex, or None on an edge
        edge: list[tuple[str, str] | None] = [None] * k
        progress = [0.0] * k  # share of the edge behind the robot
        xy = np.array([self.pos[w.root]] * (k + 1))  # robots, then the base
        arrived_by: list[float | None] = [None] * k
        wake = [0] * k  # tick at which a robot at a vertex decides
        paths = [[w.root] for _ in range(k)]
        radio = Radio(list(range(k)) + [BASE], range_m=self.range_m)
        radio.move(xy)
        declared = infeasible = None
        cut = fragile = ticks = 0
        order = [i for i in range(k - 1, -1, -1) if robots[i] is not None]
        last_tick = math.floor(max_time * TICKS_PER_UNIT)
        while declared is None and infeasible is None and ticks < last_tick:
            tick = ticks = ticks + 1
            if constrained:  # deliver; the links are those of the last tick's end
                radio.step()
                around = [self._around(radio, i, xy) for i in range(k)]
                for i in order:
                    for m in robots[i].hear(tick, radio.receive(i), around[i]):
                        radio.send(i, m.payload, m.to)
                for m in base.step(radio.receive(BASE)):
                    radio.send(BASE, m.payload, m.to)
                if dock is not None:
                    for m in dock.step(radio.receive(0)):
                        radio.send(0, m.payload, m.to)
            deciding = [i for i in order if at[i] is not None and wake[i] <= tick]
            for i in deciding:  # bookkeeping first, then decisions (graph world)
                robots[i].arrive(beacons[at[i]], w.angles[at[i]], arrived_by[i])
            for i in deciding:
                v = at[i]
                decision = robots[i].on_vertex(beacons[v], w.angles[v], arrived_by[i])
                if beacons[v].id is not None and beacons[v].id not in beacon_vertex:
                    beacon_vertex[beacons[v].id] = v
                if decision.action == "go":
                    u = w.nearest_exit(v, decision.angle)[0]
                    at[i], edge[i], progress[i], arrived_by[i] = None, (v, u), 0.0, w.angle_of[(u, v)]
                elif decision.action == "idle":
                    arrived_by[i], wake[i] = None, tick + TICKS_PER_UNIT
                elif decision.action == "done":
                    declared = (tick / TICKS_PER_UNIT, i, v)
                    break
                else:
                    raise ValueError(f"robot {i + 1} answered an unknown decision {decision!r}")
            if declared is not None:
                break
            wanted: dict[int, tuple[float, float]] = {}
            moved = set()
            for i in order:
                if edge[i] is None:
                    continue
                sense = robots[i].direction(progress[i]) if constrained else 1
                if sense == 0:
                    continue
                v, u = edge[i]
                share, step = self._step(edge[i], progress[i], sense)
                if constrained and not robots[i].tether.may_step(step, around[i]):
                    wanted[i] = step
                    continue
                moved.add(i)
                progress[i] += sense * share
                if sense > 0 and progress[i] >= 1.0 - 1e-9:
                    at[i], edge[i], wake[i] = u, None, tick + 1
                    paths[i].append(u)
                elif sense < 0 and progress[i] <= 1e-9:
                    at[i], edge[i], wake[i], arrived_by[i] = v, None, tick + 1, w.angle_of[(v, u)]
                    robots[i].arrived_back()
                xy[i] = self.pos[v] + progress[i] * (self.pos[u] - self.pos[v])
            if constrained:
                radio.move(xy)
                for i in order:
                    for m in robots[i].after(tick, wanted.get(i), i in moved,
                                             self._around(radio, i, xy)):
                        radio.send(i, m.payload, m.to)
                if any(robots[i].tether.stalled(tick) for i in order):
                    infeasible = tick
            graph = self._radio_graph(xy)
            cut += not nx.is_connected(graph)
            fragile += not nx.is_biconnected(graph)
        completed_at = None if declared is None else declared[0]
        fields = outcome(strategy_name(minds), declared,
                         () if declared is None else minds[declared[1]].map_edges(),
                         completed_at, paths, beacon_vertex, w.edges,
                         arena=arena, root=w.root, edge_time=w.edge_time, seed=seed)
        reason = None if infeasible is None else infeasible_reason(k, self.range_m, paths,
                                                                   len(w.edges))
        return ConnectedExplorationResult(
            **fields, connectivity=self.connectivity, radio_range_m=self.range_m,
            messages=radio.total_sent, connected_share=1.0 - cut / max(ticks, 1),
            cut_ticks=cut, biconnected_share=1.0 - fragile / max(ticks, 1),
            fragile_ticks=fragile, relay_trips=sum(robots[i].relay_trips for i in order),
            infeasible=infeasible is not None, reason=reason)

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
