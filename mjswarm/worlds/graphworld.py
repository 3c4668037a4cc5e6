"""The fast, abstract graph world of Nagavarapu et al.'s simulations: no physics, beacons at
vertices, K robots starting at the root, synchronous discrete time; a
:class:`~mjswarm.worlds.loop.World` of the one loop.

Every edge takes one time unit (``edge_time="unit"``, the paper's "each edge is considered
being traversed in same time"), or a time proportional to its length
(``edge_time="length"``: length divided by the mean edge length, so a lattice gives the
same numbers either way; times are then rounded to 1e-9 time units).

The loop's step advances to the next event: the robots deciding now are the active ones,
those arriving at a vertex at this time (or waking from idling), in *descending* robot
index (see :mod:`algorithms.exploration.base` for why), each seeing the beacons as the
previous one left them. A vertex call is an observation: the beacon is the vertex's
store, and :class:`~algorithms.robot.VertexSense` the exact incidence angles and the
angle of the edge the robot arrived by. The decision is a command: ``edge_rad`` leaves
along that edge (the robot arrives at the far end after the edge's duration), no edge
idles (the robot is called again one time unit later). The world owns one
:class:`~algorithms.exploration.base.Beacon` per vertex and never looks inside it; a
robot gets a :class:`~algorithms.exploration.base.BeaconHandle` on it that works until
the world steps (afterwards any use raises).
Robots run :class:`~algorithms.exploration.graph_explorer.GraphExplorer` controllers or
any other :class:`~algorithms.robot.Controller`; the experiment and its metrics are loop
functions (:mod:`mjswarm.experiments.graph_exploration`).
"""

from __future__ import annotations

import heapq
import itertools
import math

import networkx as nx
import numpy as np

from algorithms.exploration import Beacon
from algorithms.exploration.base import BeaconHandle, angle_gap, normalize_angle
from algorithms.robot import NOTHING, Command, Observation, VertexSense
from mjswarm.errors import MjswarmError
from mjswarm.worlds.loop import World

EDGE_TIMES = ("unit", "length")
_observation = tuple.__new__
_NOBODY = frozenset()


class GraphWorld(World):
    """A graph to explore: networkx graph with node attribute ``pos`` = (x, y) metres.

    The graph's geometry is worked out once; :meth:`reset` starts a run of ``n`` robots
    on the root (one world serves many runs)."""

    #: one time unit (the loop's control period: time runs in time units, not seconds)
    control_dt_s = 1.0

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
        #: vertex -> (x, y) (m)
        self.pos = pos = {}
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
        #: vertex -> what a robot senses there when it has not moved since its last call
        #: (at the start, after idling), made once
        self._resting = {v: VertexSense(self.angles[v], None) for v in graph}
        #: vertex -> {angle: (neighbour, duration, what the robot senses at the neighbour)}:
        #: the moves of :meth:`act`, worked out once for every run of the world.
        self._exits: dict[str, dict[float, tuple[str, float, VertexSense]]] = {
            v: {} for v in graph}
        for (v, a), u in self.towards.items():
            self._exits[v][a] = (u, self.duration[(v, u)],
                                 VertexSense(self.angles[u], self.angle_of[(u, v)]))
        self.uplinks = {}
        self.reset(0)

    def reset(self, n_robots: int) -> None:
        """Start a run: ``n_robots`` robots on the root at time 0, every beacon new."""
        self.n = n_robots
        self.present = np.ones(n_robots, bool)
        self.beacons = {v: Beacon() for v in self.graph}
        #: the vertex each robot stands on, or is travelling to, and when it gets there
        self.at = [self.root] * n_robots
        self.arrival = [0] * n_robots
        #: what each robot senses at its next call (the vertex it goes to, and the edge
        #: it arrives by), set when it acts
        self._sense = [self._resting[self.root]] * n_robots
        self._events = [(0, -i) for i in range(n_robots)]
        heapq.heapify(self._events)
        self._unit = self.edge_time == "unit"
        self._handles: list[BeaconHandle] = []  # handed out in this tick
        self._advance()

    def _advance(self) -> None:
        """Move time to the next event; its robots are the active ones."""
        events, batch = self._events, []
        if events:
            self._now = events[0][0]
            while events and events[0][0] == self._now:
                batch.append(-heapq.heappop(events)[1])
        self._batch = batch

    # -- the World surface ---------------------------------------------------------------
    @property
    def time_s(self) -> float:
        """The time of the current event (time units)."""
        return self._now

    @property
    def idle(self) -> bool:
        """Whether no robot will ever be called again."""
        return not self._batch

    def active(self) -> list[int]:
        return self._batch

    def on_floor(self, i) -> bool:
        return True  # every robot is in the graph from start to end

    def robots_on_floor(self) -> int:
        return self.n

    def observe(self, i: int) -> Observation:
        handle = BeaconHandle(self.beacons[self.at[i]])
        self._handles.append(handle)
        # an observation per decision: built as the tuple it is (the named constructor
        # costs a Python call more; tests/test_exploration_world.py checks the fields)
        return _observation(Observation, (i, self._now, None, None, None, None, None, None,
                                          NOTHING, NOTHING, (), _NOBODY, handle,
                                          self._sense[i], None))

    def act(self, i: int, command: Command) -> None:
        """Leave along ``command.edge_rad`` (the nearest edge), or idle one time unit."""
        now, v = self._now, self.at[i]
        if command.edge_rad is None:
            self._sense[i] = self._resting[v]
            heapq.heappush(self._events, (now + 1, -i))
            return
        u, duration, sense = (self._exits[v].get(command.edge_rad)
                              or self.nearest_exit(v, command.edge_rad))
        # times are whole steps with unit edges; with length-proportional edges they are
        # rounded to 1e-9 time units, so that arrivals equal up to rounding errors are
        # simultaneous (and handled in robot order)
        done_at = now + duration if self._unit else round(now + duration, 9)
        self.at[i], self._sense[i], self.arrival[i] = u, sense, done_at
        heapq.heappush(self._events, (done_at, -i))

    def step(self) -> None:
        for handle in self._handles:  # the tick is over: its handles no longer work
            handle.expire()
        self._handles = []
        self._advance()

    def true_poses(self) -> np.ndarray:
        """Where each robot stands, or the vertex it travels to (m; heading 0)."""
        xy = [self.pos[v] for v in self.at]
        return np.column_stack([np.array(xy, float).reshape(-1, 2), np.zeros(self.n)])

    def commanded_speeds(self) -> np.ndarray:
        return np.zeros(self.n)

    def nearest_exit(self, vertex: str, angle: float) -> tuple[str, float, VertexSense]:
        """The move along the edge at ``vertex`` nearest to ``angle``: the neighbour, the
        duration and what the robot senses on arriving there."""
        best = min(self.angles[vertex], key=lambda a: angle_gap(a, angle))
        return self._exits[vertex][best]
