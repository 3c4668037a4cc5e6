"""The fast, abstract graph world of seed 003's simulations: no physics, beacons at
vertices, K robots starting at the root, synchronous discrete time.

Every edge takes one time unit (``edge_time="unit"``, the paper's "each edge is considered
being traversed in same time"), or a time proportional to its length
(``edge_time="length"``: length divided by the mean edge length, so a lattice gives the
same numbers either way; times are then rounded to 1e-9 time units). Robots arriving at
the same time are handled one after another in descending robot index, each seeing the
beacons as the previous one left them (see :mod:`algorithms.exploration.base` for why).
A robot that answers ``IDLE`` is asked again one time unit later.

The world is the "loop functions" side: it owns the beacons (one
:class:`~algorithms.exploration.base.Beacon` per vertex), gives each robot the exact
incidence angles at its vertex, moves robots along the edges they choose, and measures.
A run ends when a robot declares completion, or unsuccessfully at ``max_time``.

Metrics (:class:`ExplorationResult`): ``makespan`` is the time of the declaration (seed
003's "number of edge traversals" to complete); ``total_traversals`` and
``traversals_per_robot`` count the edge traversals finished by then; ``map_edges`` is the
declaring robot's map translated from beacon ids to arena vertex ids (the world knows where
each beacon was dropped); ``map_correct`` says whether it equals the true edge set.
"""

from __future__ import annotations

import heapq
import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass

import networkx as nx
import numpy as np

from algorithms.exploration import STRATEGIES, Beacon, Decision, Strategy
from algorithms.exploration.base import angle_gap, normalize_angle
from mjswarm.errors import MjswarmError

EDGE_TIMES = ("unit", "length")

#: Builds robot ``index``'s mind for a team of ``n_robots``, with its tie-breaking rng.
StrategyFactory = Callable[[int, int, np.random.Generator | None], Strategy]

#: Called after every robot decision: (time, robot index, vertex, decision, mind).
Observer = Callable[[float, int, str, Decision, Strategy], None]


@dataclass
class ExplorationResult:
    """One run's measurements (robots numbered from 1 as R1, R2, ... in seed 003)."""

    arena: str
    strategy: str
    robots: int
    root: str
    edge_time: str
    seed: int | None
    completed: bool
    makespan: float | None
    total_traversals: int
    traversals_per_robot: list[int]
    declared_by: int | None
    declared_at: str | None
    map_edges: list[tuple[str, str]]
    map_correct: bool
    paths: list[list[str]]

    def to_dict(self) -> dict:
        """JSON-ready dict (tuples become lists)."""
        d = asdict(self)
        d["map_edges"] = [list(e) for e in self.map_edges]
        return d


def outcome(
    minds: Sequence[Strategy], declared: tuple[float, int, str] | None,
    makespan: float | None, paths: list[list[str]], beacon_vertex: Mapping[str, str],
    true_edges: set[tuple[str, str]], **run,
) -> dict:
    """The :class:`ExplorationResult` fields every world computes the same way, given the
    declaration ``(time, robot index, vertex)`` or None, the makespan, each robot's path,
    where each beacon was dropped, the true edges (sorted pairs) and the run's own fields
    (``arena``, ``root``, ``edge_time``, ``seed``). The declaring robot's map is
    translated from beacon ids to arena vertices."""
    per_robot = [len(p) - 1 for p in paths]
    map_edges: list[tuple[str, str]] = []
    if declared is not None:
        pairs = ((beacon_vertex[a], beacon_vertex[b]) for a, b in minds[declared[1]].map_edges())
        map_edges = sorted((u, v) if u <= v else (v, u) for u, v in pairs)
    return dict(
        run,
        strategy=getattr(minds[0], "name", type(minds[0]).__name__),
        robots=len(minds),
        completed=declared is not None,
        makespan=makespan,
        total_traversals=sum(per_robot),
        traversals_per_robot=per_robot,
        declared_by=None if declared is None else declared[1] + 1,
        declared_at=None if declared is None else declared[2],
        map_edges=map_edges,
        map_correct=declared is not None and set(map_edges) == true_edges,
        paths=paths,
    )


class GraphWorld:
    """A graph to explore: networkx graph with node attribute ``pos`` = (x, y) metres."""

    def __init__(self, graph: nx.Graph, root: str, *, edge_time: str = "unit"):
        if edge_time not in EDGE_TIMES:
            raise MjswarmError(f"edge time must be one of {', '.join(EDGE_TIMES)}, got '{edge_time}'")
        if root not in graph:
            raise MjswarmError(f"root '{root}' is not a vertex of the graph")
        if graph.number_of_nodes() > 1 and not nx.is_connected(graph):
            raise MjswarmError("the graph to explore is not connected")
        self.graph = graph
        self.root = root
        self.edge_time = edge_time
        pos = {}
        for v, p in graph.nodes(data="pos"):
            if p is None:
                raise MjswarmError(f"vertex '{v}' has no 'pos' attribute")
            pos[v] = (float(p[0]), float(p[1]))
        #: vertex -> sorted incidence angles (radians, (0, 2*pi]).
        self.angles: dict[str, tuple[float, ...]] = {}
        #: (vertex, angle) -> neighbour reached along that edge.
        self.towards: dict[tuple[str, float], str] = {}
        #: (vertex, neighbour) -> angle of the edge at vertex.
        self.angle_of: dict[tuple[str, str], float] = {}
        for v in graph:
            fan = sorted(
                (normalize_angle(math.atan2(pos[u][1] - pos[v][1], pos[u][0] - pos[v][0])), u)
                for u in graph[v]
            )
            for (a, _), (b, _) in itertools.pairwise(fan):
                if b - a < 1e-9:
                    raise MjswarmError(f"vertex '{v}' has two edges at the same angle")
            self.angles[v] = tuple(a for a, _ in fan)
            for a, u in fan:
                self.towards[(v, a)] = u
                self.angle_of[(v, u)] = a
        lengths = {(u, v): math.dist(pos[u], pos[v]) for u, v in graph.edges}
        mean = sum(lengths.values()) / len(lengths) if lengths else 1.0
        #: (u, v) -> time to traverse the edge (either direction), time units.
        self.duration: dict[tuple[str, str], float] = {}
        for (u, v), length in lengths.items():
            self.duration[(u, v)] = self.duration[(v, u)] = 1 if edge_time == "unit" else length / mean
        #: The true edge set, as sorted vertex pairs (metrics only).
        self.edges = {tuple(sorted(e)) for e in graph.edges}
        #: vertex -> {angle: (neighbour, duration, angle of the edge at the neighbour)}: the
        #: moves of :meth:`run`, worked out once for every run of the world.
        self._exits: dict[str, dict[float, tuple[str, float, float]]] = {v: {} for v in graph}
        for (v, a), u in self.towards.items():
            self._exits[v][a] = (u, self.duration[(v, u)], self.angle_of[(u, v)])

    def explore(
        self,
        n_robots: int,
        strategy: str | StrategyFactory = "incidence-dfs",
        *,
        seed: int | None = None,
        max_time: float | None = None,
        observer: Observer | None = None,
        arena: str = "<graph>",
    ) -> ExplorationResult:
        """Explore with ``n_robots`` robots running ``strategy`` (a name from
        ``STRATEGIES`` or a factory); ``seed`` (``None``: each strategy's canonical tie
        rules) randomises tie-breaking."""
        minds = make_minds(strategy, n_robots, seed)
        return self.run(minds, seed=seed, max_time=max_time, observer=observer, arena=arena)

    def run(
        self,
        minds: list[Strategy],
        *,
        seed: int | None = None,
        max_time: float | None = None,
        observer: Observer | None = None,
        arena: str = "<graph>",
    ) -> ExplorationResult:
        """Run ``minds`` (one per robot, R1 first) from the root until a declaration or
        ``max_time`` (default 50 (E + 1) + 100 time units). ``seed`` and ``arena`` are
        only recorded in the result."""
        k = len(minds)
        if max_time is None:
            max_time = 50 * (len(self.edges) + 1) + 100
        angles, exits, unit = self.angles, self._exits, self.edge_time == "unit"
        # the bookkeeping pass is skipped when every mind keeps Strategy's empty arrive()
        bookkeeping = any(type(m).arrive is not Strategy.arrive for m in minds)
        beacons = {v: Beacon() for v in self.graph}
        beacon_vertex: dict[str, str] = {}
        position = [self.root] * k
        arrived_by: list[float | None] = [None] * k
        arrival_time = [0] * k
        paths = [[self.root] for _ in range(k)]
        events = [(0, -i) for i in range(k)]
        heapq.heapify(events)
        declared = None
        while events and declared is None:
            t = events[0][0]
            if t > max_time:
                break
            batch = []  # every robot at a vertex at time t, in descending index
            while events and events[0][0] == t:
                batch.append(-heapq.heappop(events)[1])
            if bookkeeping:  # all bookkeeping first ...
                for i in batch:
                    minds[i].arrive(beacons[position[i]], angles[position[i]], arrived_by[i])
            for i in batch:  # ... then the decisions, one after another
                v = position[i]
                beacon = beacons[v]
                decision = minds[i].on_vertex(beacon, angles[v], arrived_by[i])
                if beacon.id is not None and beacon.id not in beacon_vertex:
                    beacon_vertex[beacon.id] = v
                if observer is not None:
                    observer(t, i, v, decision, minds[i])
                if decision.action == "go":
                    u, duration, back = (exits[v].get(decision.angle)
                                         or self.nearest_exit(v, decision.angle))
                    # times are whole steps with unit edges; with length-proportional
                    # edges they are rounded to 1e-9 time units, so that arrivals equal up
                    # to rounding errors are simultaneous (and handled in robot order)
                    done_at = t + duration if unit else round(t + duration, 9)
                    position[i], arrived_by[i], arrival_time[i] = u, back, done_at
                    paths[i].append(u)
                    heapq.heappush(events, (done_at, -i))
                elif decision.action == "idle":
                    arrived_by[i] = None
                    heapq.heappush(events, (t + 1, -i))
                elif decision.action == "done":
                    declared = (t, i, v)
                    break
                else:
                    raise ValueError(f"robot {i + 1} answered an unknown decision {decision!r}")
        if declared is not None:
            for j in range(k):  # traversals still under way at the declaration do not count
                if arrival_time[j] > declared[0]:
                    paths[j].pop()
        return ExplorationResult(**outcome(
            minds, declared, None if declared is None else declared[0], paths, beacon_vertex,
            self.edges, arena=arena, root=self.root, edge_time=self.edge_time, seed=seed))

    def nearest_exit(self, vertex: str, angle: float) -> tuple[str, float, float]:
        """The move along the edge at ``vertex`` nearest to ``angle``: the neighbour, the
        duration and the edge's angle at the neighbour."""
        best = min(self.angles[vertex], key=lambda a: angle_gap(a, angle))
        return self._exits[vertex][best]


#: Largest team any run takes: the largest the benchmarks measure. The graph world's
#: minds take about 0.4 MB a robot (arena1 with 10,000 robots: 3.9 GB, 67 s; measured
#: with ``/usr/bin/time mjswarm explore --world graph --arena arena1 --robots 10000``).
MAX_ROBOTS = 1000


def make_minds(
    strategy: str | StrategyFactory, n_robots: int, seed: int | None = None
) -> list[Strategy]:
    """One mind per robot; ``strategy`` is a name from ``STRATEGIES`` or a factory.
    With a ``seed``, robot i gets the generator ``default_rng([seed, i])``."""
    if isinstance(n_robots, bool) or not isinstance(n_robots, int) or n_robots < 1:
        raise MjswarmError(f"need at least one robot, got {n_robots}")
    if n_robots > MAX_ROBOTS:
        raise MjswarmError(f"at most {MAX_ROBOTS} robots, got {n_robots} (the largest team "
                           "the benchmarks measure; the graph world's minds alone take "
                           "about 0.4 MB a robot)")
    if isinstance(strategy, str):
        if strategy not in STRATEGIES:
            raise MjswarmError(
                f"unknown strategy '{strategy}' (choose from {', '.join(STRATEGIES)})"
            )
        strategy = STRATEGIES[strategy]
    return [
        strategy(i, n_robots, None if seed is None else np.random.default_rng([seed, i]))
        for i in range(n_robots)
    ]


def explore(
    graph: nx.Graph,
    root: str,
    n_robots: int,
    strategy: str | StrategyFactory = "incidence-dfs",
    *,
    edge_time: str = "unit",
    **options,
) -> ExplorationResult:
    """Explore ``graph`` from ``root``; shorthand for
    ``GraphWorld(graph, root, edge_time=edge_time).explore(n_robots, strategy, **options)``."""
    return GraphWorld(graph, root, edge_time=edge_time).explore(n_robots, strategy, **options)
