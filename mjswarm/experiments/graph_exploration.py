"""Exploration in the graph world, on the one loop: the experiment is a loop function.

:class:`GraphExploration` watches a :class:`~mjswarm.worlds.graphworld.GraphWorld` run
(ground truth: where each robot goes, where each beacon was dropped) and the robots'
reports (:class:`~algorithms.exploration.events.Declared`), stops the run when a robot
declares completion, when no robot will be called again, or after ``max_time`` time
units, and gives Nagavarapu et al.'s metrics (:class:`~mjswarm.experiments.results.
ExplorationResult`). Robots are :func:`~algorithms.exploration.graph_explorer.
graph_explorer` controllers around their strategies, or any controller a user writes
against :class:`~algorithms.robot.Observation` and :class:`~algorithms.robot.Command`.

A robot's path counts an edge when the robot sets out on it; the traversals still under
way when completion is declared are taken back (they do not count).
"""

from __future__ import annotations

from collections.abc import Sequence

import networkx as nx

from algorithms.exploration import Strategy
from algorithms.exploration.events import Declared
from algorithms.exploration.graph_explorer import graph_explorer
from algorithms.robot import Controller
from mjswarm.experiments.minds import StrategyFactory, make_minds, strategy_name
from mjswarm.experiments.results import ExplorationResult, Paths
from mjswarm.worlds.graphworld import GraphWorld
from mjswarm.worlds.loop import Loop, LoopFunctions


def default_max_time(world: GraphWorld) -> float:
    """Time units after which a run gives up: 50 (E + 1) + 100."""
    return 50 * (len(world.edges) + 1) + 100


class GraphExploration(LoopFunctions):
    """Nagavarapu et al.'s metrics of one graph-world run (module docstring)."""

    def __init__(self, world: GraphWorld, strategy: str, *, seed: int | None = None,
                 max_time: float | None = None, arena: str = "<graph>") -> None:
        self.world, self.strategy, self.seed, self.arena = world, strategy, seed, arena
        self.max_time = default_max_time(world) if max_time is None else max_time
        self.paths = Paths(world.n, world.root, keep="first")
        self._now = 0.0

    def before_step(self, loop: Loop) -> None:
        self._now = self.world.time_s

    def after_step(self, loop: Loop) -> None:
        at, paths = self.world.at, self.paths
        route = paths.paths
        for i in loop.stepped:  # a robot that set out: its path gains the far end
            if at[i] != route[i][-1]:
                paths.arrive(i, at[i])
        for i, event in loop.reports:
            if isinstance(event, Declared):
                paths.declare(self._now, i, at[i], event.map_edges)

    def should_stop(self, loop: Loop) -> bool:
        world = self.world
        return self.paths.declared is not None or world.idle or world.time_s > self.max_time

    def result(self, loop: Loop) -> ExplorationResult:
        world, declared = self.world, self.paths.declared
        under_way = () if declared is None else [  # traversals under way do not count
            j for j in range(world.n) if world.arrival[j] > declared[0]]
        dropped = {b.id: v for v, b in world.beacons.items() if b.id is not None}
        return ExplorationResult(**self.paths.outcome(
            self.strategy, None if declared is None else declared[0], dropped, world.edges,
            self.paths.counted(under_way), arena=self.arena, root=world.root,
            edge_time=world.edge_time, seed=self.seed))


def run_controllers(world: GraphWorld, controllers: Sequence[Controller], strategy: str, *,
                    seed: int | None = None, max_time: float | None = None,
                    arena: str = "<graph>",
                    functions: Sequence[LoopFunctions] = ()) -> ExplorationResult:
    """Run ``controllers`` (one per robot, R1 first) in ``world`` from its root until a
    declaration or ``max_time`` (default :func:`default_max_time`); ``functions`` are more
    loop functions (a recording, a test's probe). ``strategy``, ``seed`` and ``arena``
    are only recorded in the result."""
    world.reset(len(controllers))
    experiment = GraphExploration(world, strategy, seed=seed, max_time=max_time, arena=arena)
    loop = Loop(world, dict(enumerate(controllers)), [experiment, *functions])
    return loop.run()[0]


def run_minds(world: GraphWorld, minds: list[Strategy], *, report: bool = False,
              **options) -> ExplorationResult:
    """Run each mind in its graph explorer (see :func:`run_controllers`); with
    ``report``, the robots report their vertex calls (for a recording)."""
    return run_controllers(world, [graph_explorer(m, report) for m in minds],
                           strategy_name(minds), **options)


def explore_world(world: GraphWorld, n_robots: int,
                  strategy: str | StrategyFactory = "incidence-dfs", *,
                  seed: int | None = None, **options) -> ExplorationResult:
    """Explore with ``n_robots`` robots running ``strategy`` (a name from ``STRATEGIES``
    or a factory); ``seed`` (``None``: each strategy's canonical tie rules) randomises
    tie-breaking."""
    return run_minds(world, make_minds(strategy, n_robots, seed), seed=seed, **options)


def explore(graph: nx.Graph, root: str, n_robots: int,
            strategy: str | StrategyFactory = "incidence-dfs", *, edge_time: str = "unit",
            **options) -> ExplorationResult:
    """Explore ``graph`` from ``root``; shorthand for
    ``explore_world(GraphWorld(graph, root, edge_time=edge_time), n_robots, strategy)``."""
    return explore_world(GraphWorld(graph, root, edge_time=edge_time), n_robots, strategy,
                         **options)
