"""Nagavarapu et al. exploration under a connectivity constraint, in the graph world with a radio
(:class:`~mjswarm.worlds.radiograph.RadioGraphWorld`), on the one loop.

Robots are :class:`~algorithms.exploration.graph_explorer.TetheredExplorer` controllers;
the base station and the docked robot are :class:`~algorithms.exploration.tether.
FixedNode` controllers of the world's fixed radio nodes, stepped by the loop. The
experiment is one loop function (:class:`ConnectedExploration`): paths, the declaration,
rule 5's verdict and the ground truth of the radio graph.

``connectivity``:

* ``"none"``: Nagavarapu et al. unchanged (robots never wait; no messages).
* ``"connected"`` / ``"biconnected"``: each robot keeps its tether of one / two parents
  (:mod:`algorithms.exploration.tether`; with ``biconnected`` robot 0 docks at the base,
  rule 1, and explores nothing) and
  stuck robots are brought relays (:mod:`algorithms.exploration.relay`); robots walk
  edges both ways and may stop part-way.

One tick (the world's two phases, :mod:`mjswarm.worlds.radiograph`), for every robot in
descending index (the order of Nagavarapu et al.'s Fig. 9 run):

1. move phase: every robot and the base read the messages delivered at the last tick's
   end; robots at a vertex whose time has come (they reached it in the last tick, or
   their idling is over) let their strategy decide, all bookkeeping first, as in the
   graph world; every robot that wants to move asks its tether whether it may take its
   step; the steps are taken together;
2. answer phase: robots that wanted to move and could not, or could use a parent nearer
   the base, ask for adoption; every robot beats; then the radio delivers;
3. ground truth (the loop function): the radio graph of the base and the robots, with
   networkx, counts the ticks in which some robot has no route to the base, and those in
   which the graph is not biconnected (one robot failing would cut someone off).

The run ends when a robot declares completion, when a robot declares a stall (rule 5 of
the tether: the result is ``infeasible`` if the team has fewer robots than the arena
needs, :mod:`mjswarm.experiments.reach`, else ``stalled``; with the explored share of the
true edges), or
at ``max_time``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import networkx as nx
import numpy as np

from algorithms.exploration import Strategy
from algorithms.exploration.events import Declared, Infeasible
from algorithms.exploration.graph_explorer import TetheredExplorer
from algorithms.exploration.relay import ConnectedExplorer, Flooder
from algorithms.exploration.tether import (
    BASE,
    BaseStation,
    FixedNode,
    Tether,
    docked,
    initial_parents,
)
from mjswarm.core.radio import BASE_MAST_M
from mjswarm.errors import MjswarmError
from mjswarm.experiments.graph_exploration import default_max_time
from mjswarm.experiments.minds import strategy_name
from mjswarm.experiments.reach import robots_needed
from mjswarm.experiments.results import ExplorationResult, Paths, traversed_edges
from mjswarm.worlds.graphworld import GraphWorld
from mjswarm.worlds.loop import Loop, LoopFunctions
from mjswarm.worlds.radiograph import ANSWER, TICKS_PER_UNIT, RadioGraphWorld
from mjswarm.worlds.wall_sight import wall_blocker

CONNECTIVITY = ("none", "connected", "biconnected")
#: Parents each robot keeps under each constraint (rule 1 of the tether).
NEED = {"connected": 1, "biconnected": 2}


def stall_verdict(robots: int, range_m: float, paths: list[list], edges: int,
                  needed: int, working: int | None = None) -> tuple[bool, str]:
    """The verdict on a team that declared a stall (rule 5 of the tether): whether it is
    infeasible (fewer ``working`` robots, by default all ``robots``, than the arena
    ``needed``, :func:`~mjswarm.experiments.reach.robots_needed`: no strategy could
    complete it) or the team's stall, and its text, with the share of the ``edges`` true
    edges its ``paths`` (vertex sequences, one per robot) covered."""
    explored = traversed_edges(paths)
    working = robots if working is None else working
    infeasible = working < needed
    text = (f"{'infeasible' if infeasible else 'stalled'} with {robots} robots at range "
            f"{range_m:g} m: explored {len(explored)} of {edges} edges; ")
    if working < robots:
        text += f"{working} still working; "
    if infeasible:
        return True, text + f"every edge needs at least {needed}"
    return False, text + f"{needed} could reach every edge"


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
        infeasible: whether the team declared a stall (rule 5) with fewer robots than
            the arena needs (:func:`~mjswarm.experiments.reach.robots_needed`).
        stalled: whether it declared a stall with as many or more.
        robots_needed: after a stall, the fewest robots that could reach every edge.
        reason: the verdict on a stall, with the explored share of the true edges; None
            otherwise.
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
    stalled: bool = False
    robots_needed: int | None = None
    reason: str | None = None


class ConnectedExploration(LoopFunctions):
    """The loop function of a connected exploration (module docstring): where the robots
    went, who declared, rule 5's verdict and the radio graph's ground truth."""

    def __init__(self, world: RadioGraphWorld, strategy: str, connectivity: str, *,
                 seed: int | None = None, arena: str = "<graph>") -> None:
        self.world, self.strategy, self.connectivity = world, strategy, connectivity
        self.seed, self.arena = seed, arena
        root = world.graph.root
        self.paths = Paths(world.n, root, keep="first")
        self.infeasible: int | None = None
        self.ticks = self.cut = self.fragile = 0
        self._base_xy = world.pos[root][None]
        #: with walls, ground truth's line-of-sight test: nodes by index, the base last
        self._where: dict = {}
        self._blocked = None if world.walls is None else wall_blocker(
            world.walls, self._where, {world.n: world.mast_m,
                                       **dict.fromkeys(world.docked, world.mast_m)})

    def after_step(self, loop: Loop) -> None:
        w = self.world
        if w.phase == ANSWER:  # the move phase is over
            self.ticks = w.tick
            for i, event in loop.reports:
                if isinstance(event, Declared):
                    self.paths.declare(w.time_s, i, w.at[i], event.map_edges)
                    return  # the run ends: the steps of this tick do not count
            for i in w.arrived:
                self.paths.arrive(i, w.at[i])
            return
        if self.infeasible is None and any(isinstance(e, Infeasible) for _, e in loop.reports):
            self.infeasible = self.ticks
        graph = self._radio_graph(np.vstack([w.xy, self._base_xy]))
        self.cut += not nx.is_connected(graph)
        self.fragile += not nx.is_biconnected(graph)

    def should_stop(self, loop: Loop) -> bool:
        return self.paths.declared is not None or self.infeasible is not None

    def _radio_graph(self, xy: np.ndarray) -> nx.Graph:
        """Ground truth: the radio graph of the robots and the base (the last node): the
        pairs within range, less those the walls block."""
        g = nx.Graph()
        g.add_nodes_from(range(len(xy)))
        d2 = ((xy[:, None] - xy[None]) ** 2).sum(axis=-1)
        pairs = np.transpose(np.nonzero(np.triu(d2 <= self.world.range_m**2, 1)))
        if self._blocked is not None and len(pairs):
            self._where.update(enumerate(xy))
            pairs = pairs[~self._blocked(pairs)]
        g.add_edges_from(map(tuple, pairs))
        return g

    def result(self, loop: Loop) -> ConnectedExplorationResult:
        w, declared, paths = self.world, self.paths.declared, self.paths.paths
        g = w.graph
        dropped = {b.id: v for v, b in w.beacons.items() if b.id is not None}
        fields = self.paths.outcome(self.strategy, None if declared is None else declared[0],
                                    dropped, g.edges, arena=self.arena, root=g.root,
                                    edge_time=g.edge_time, seed=self.seed)
        needed = None if self.infeasible is None else robots_needed(
            g.pos, list(g.edges), g.root, w.range_m, w.walls, w.mast_m, self.connectivity)
        infeasible, reason = (False, None) if self.infeasible is None else stall_verdict(
            w.n, w.range_m, paths, len(g.edges), needed)
        ticks = max(self.ticks, 1)
        return ConnectedExplorationResult(
            **fields, connectivity=self.connectivity, radio_range_m=w.range_m,
            messages=w.radio.total_sent, connected_share=1.0 - self.cut / ticks,
            cut_ticks=self.cut, biconnected_share=1.0 - self.fragile / ticks,
            fragile_ticks=self.fragile,
            relay_trips=sum(c.telemetry().get("relay_trips", 0)
                            for c in loop.controllers.values()),
            infeasible=infeasible, stalled=self.infeasible is not None and not infeasible,
            robots_needed=needed, reason=reason)


def connected_controllers(minds: Sequence[Strategy], radio_range_m: float,
                          connectivity: str, report: bool = False,
                          walls: bool = False) -> dict:
    """The controllers of a run: a tethered explorer around each mind (robot 0 docked at
    the base under ``biconnected``, rule 1 of the tether) and, under a constraint, the
    base station (``BASE``); with ``report`` the explorers report their vertex calls; with
    ``walls`` they know that walls may cut their links."""
    need, constrained = NEED.get(connectivity, 1), connectivity != "none"
    controllers = {BASE: FixedNode(BaseStation(Flooder()))} if constrained else {}
    for i, mind in enumerate(minds):
        if need == 2 and i == 0:
            controllers[i] = FixedNode(docked(Flooder()))
            continue
        tether = Tether(i, radio_range_m, initial_parents(i, need), ticks_per_unit=TICKS_PER_UNIT)
        controllers[i] = TetheredExplorer(ConnectedExplorer(i, mind, tether), constrained,
                                          report, walls)
    return controllers


def run_connected(world: GraphWorld, minds: list[Strategy], radio_range_m: float,
                  connectivity: str = "connected", *, seed: int | None = None,
                  max_time: float | None = None, arena: str = "<graph>",
                  functions: Sequence[LoopFunctions] = (),
                  report: bool = False, walls: Sequence | None = None,
                  mast_m: float = BASE_MAST_M) -> ConnectedExplorationResult:
    """Explore ``world``'s graph with ``minds`` (one per robot) from the root, with a
    radio of range ``radio_range_m`` (m), keeping ``connectivity`` (module docstring),
    until a declaration, rule 5's verdict or ``max_time`` time units (default: the graph
    world's); ``functions`` are more loop functions (a recording); with ``report`` the
    robots report their vertex calls (for a recording); ``walls`` (the arena's corridor
    walls, :func:`~mjswarm.arena.geometry.corridor_walls`) block links as they do the
    MuJoCo robots' radio, the base's antenna ``mast_m`` above the root (None: the open
    model, range alone)."""
    if connectivity not in CONNECTIVITY:
        raise MjswarmError(f"connectivity must be one of {', '.join(CONNECTIVITY)}, "
                           f"got '{connectivity}'")
    radio_world = RadioGraphWorld(world, radio_range_m, walls, mast_m)
    need_robots(connectivity, len(minds))
    radio_world.reset(len(minds), base=connectivity != "none", dock=NEED.get(connectivity) == 2)
    experiment = ConnectedExploration(radio_world, strategy_name(minds), connectivity,
                                      seed=seed, arena=arena)
    loop = Loop(radio_world, connected_controllers(minds, radio_range_m, connectivity, report,
                                                   walls is not None),
                [experiment, *functions])
    max_time = default_max_time(world) if max_time is None else max_time
    return loop.run(max_ticks=2 * math.floor(max_time * TICKS_PER_UNIT))[0]
