"""The vertex stations as a loop function: the beacon service and vertex entry.

Nagavarapu et al.'s robots kept apart on edges with the bearing-rate rule and spent only a moment
at a vertex; ours scan there for about ten seconds, and a robot's sidesteps between the
vertex centre and its lane cross the lanes of the other edges at that vertex. So a vertex
area holds one robot at a time, and each vertex has a *station* (the paper's central
station, which knew its own vertices, emulated the beacons; ours also grants entry) that
decides who that is. The protocol, both its sides and why no circular wait forms, is
:mod:`algorithms.exploration.entry`; this module runs the stations' side
(:class:`~algorithms.exploration.entry.EntryStations`) in the loop's hooks, delivers its
answers over the uplink, and shows it the bodies (:class:`BodySight`: ground truth, as
the paper's station saw who stood on its vertex; the arena's edges at each vertex,
:func:`mjswarm.arena.geometry.vertex_fans`, are what the paper's station knew).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from algorithms.exploration.entry import EntryStations
from algorithms.exploration.events import VertexCalled
from mjswarm.arena import ArenaSpec
from mjswarm.arena.geometry import VERTEX_CLEAR_RADIUS_M, junction_depths, vertex_fans
from mjswarm.worlds.loop import Loop, LoopFunctions

#: A robot is on a vertex when within this distance of its centre (m).
ON_VERTEX_M = 0.05


#: Robot-by-vertex distances from which :class:`NearestVertex` asks a k-d tree: below, the
#: whole matrix costs less than the tree's query (the main job's 4 robots by 10 vertices:
#: about 4 us against 14 us a state).
NEAREST_TREE_FROM = 4096


class NearestVertex:
    """Which vertex each robot of ``sim`` is nearest to, and how far (m): what the
    stations see. Worked out once per world state, for every robot on the floor at once
    (``present``, the world's live mask; robots waiting in the depot are asked about
    one by one, if ever), by a k-d tree over the vertices (a robot-by-vertex distance
    matrix took 5.3 of 9.4 s of a 1000-robot ``lattice:30x30`` run's first 20 s;
    ``tree.query`` is ``O(N log V)``), or by the whole matrix below ``NEAREST_TREE_FROM``
    robot-vertex pairs (the same vertices: a robot exactly halfway between two is the
    only case the two could answer apart)."""

    def __init__(self, sim, spec: ArenaSpec, present: np.ndarray | None = None) -> None:
        self.sim = sim
        self._xy = np.array(list(spec.vertices.values()))
        self._tree = (cKDTree(self._xy) if sim.n * len(self._xy) >= NEAREST_TREE_FROM
                      else None)
        self._ids = list(spec.vertices)
        self._present = np.ones(sim.n, bool) if present is None else present
        self._version = -1
        self._nearest: list = []
        self._distance: list = []

    def __call__(self, i: int) -> tuple[str, float]:
        sim = self.sim
        if self._version != sim.state_version:
            rows = np.flatnonzero(self._present)
            nearest, distance = np.zeros(sim.n, np.intp), np.full(sim.n, np.nan)
            nearest[rows], distance[rows] = self._find(sim.poses()[rows, :2])
            self._nearest, self._distance = nearest.tolist(), distance.tolist()
            self._version = sim.state_version
        if not self._present[i]:  # in the depot: asked alone
            (v,), (d,) = self._find(sim.poses()[i:i + 1, :2])
            return self._ids[v], float(d)
        return self._ids[self._nearest[i]], self._distance[i]

    def _find(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The nearest vertex of each point ``xy`` (m), by index, and its distance (m)."""
        if self._tree is not None:
            nearest = self._tree.query(xy)[1]
        else:
            gap = xy[:, None, :] - self._xy[None, :, :]
            nearest = np.einsum("nvk,nvk->nv", gap, gap).argmin(axis=1)
        v = self._xy[nearest]
        return nearest, np.hypot(xy[:, 0] - v[:, 0], xy[:, 1] - v[:, 1])


class BodySight:
    """What the stations see of the bodies (:class:`~algorithms.exploration.entry.
    StationSight`), from ground truth: who is nearest which vertex, and the corridor
    stretches that a vertex's edges share."""

    def __init__(self, spec: ArenaSpec, world, nearest: NearestVertex) -> None:
        self.spec, self.world, self.nearest = spec, world, nearest
        self.fans, self.junctions = vertex_fans(spec), junction_depths(spec)

    def clear_of_areas(self, robot: int) -> bool:
        return self.nearest(robot)[1] >= VERTEX_CLEAR_RADIUS_M

    def in_area(self, robot: int, vertex: str) -> bool:
        near, distance = self.nearest(robot)
        return near == vertex and distance < VERTEX_CLEAR_RADIUS_M

    def body_closes(self, robot: int) -> str | None:
        vertex, distance = self.nearest(robot)
        if distance < VERTEX_CLEAR_RADIUS_M or distance < self._junction_depth(robot, vertex):
            return vertex
        return None

    def present(self, robot: int) -> bool:
        return bool(self.world.present[robot])

    def _junction_depth(self, i: int, vertex: str) -> float:
        """How far from ``vertex``'s centre the corridor robot ``i`` stands in is still
        shared with the vertex's other edges (m; :func:`~mjswarm.arena.geometry.
        junction_depths`): beyond the vertex area where edges meet at less than about
        84 degrees. A body there blocks robots turning in and out of those edges too, and
        cannot be passed, so it closes the vertex as one in its area does."""
        x, y = self.world.true_poses()[i, :2] - self.spec.vertices[vertex]
        heading = math.atan2(y, x)
        _, towards = min(self.fans[vertex], key=lambda fan: abs(
            math.remainder(fan[0] - heading, 2 * math.pi)))
        return self.junctions[(vertex, towards)]


class StationService(LoopFunctions):
    """The vertex stations as a loop function: the beacon service (which vertex's beacon a
    robot may read now) and the entry protocol (:mod:`algorithms.exploration.entry`)
    over ``uplink``. ``avoid``: vertex entry is on (else a robot's vertex is the one its
    decision leads to, and any robot on a centre reads its beacon)."""

    def __init__(self, spec: ArenaSpec, world, uplink, nearest: NearestVertex,
                 avoid: bool) -> None:
        self.world, self.uplink, self.nearest, self.avoid = world, uplink, nearest, avoid
        #: the stations' side of vertex entry
        self.entry = EntryStations(vertex_fans(spec), world.n, avoid,
                                   BodySight(spec, world, nearest))
        self.loop: Loop | None = None

    @property
    def closed(self) -> dict[str, tuple[int, float]]:
        """Closed vertices: vertex -> (robot whose body closed it, time s)."""
        return self.entry.closed

    @property
    def gave_up(self) -> int:
        """Requests dropped because their robot gave up its place in a queue."""
        return self.entry.gave_up

    def initialize(self, loop: Loop) -> None:
        self.loop = loop

    def switched_off(self, i: int, reason: str) -> None:
        """Robot ``i`` was switched off (a fault): its holds go, and a vertex whose area
        its body is in closes."""
        if self.world.present[i]:  # one still in the depot holds nothing
            self.entry.release(i, self.world.time_s)
            self._send()

    # ------------------------------------------------------------------ beacons
    def beacon_at(self, i: int) -> str | None:
        """The vertex whose beacon robot ``i`` may read now: the one whose centre it
        stands on, if the station there granted it that vertex (or launched it there), or
        has granted it the next one and not yet seen it leave."""
        vertex, distance = self.nearest(i)
        if distance >= ON_VERTEX_M:
            return None
        entry = self.entry
        if self.avoid and vertex != entry.target[i] and vertex != entry.leaving[i]:
            return None
        return vertex

    # ------------------------------------------------------------------ hooks
    def launched(self, i: int, vertex: str) -> None:
        """Robot ``i`` was put on ``vertex``'s centre: it holds it."""
        self.entry.launched(i, vertex)

    def before_step(self, loop: Loop) -> None:
        """The stations' mail, then their grants."""
        now_s = self.world.time_s
        for message in self.uplink.receive():
            self.entry.receive(message.sender, message.payload, now_s)
        self.entry.serve(now_s)
        self._send(loop)

    def after_step(self, loop: Loop) -> None:
        """Without vertex entry, a robot's vertex is the one its decision leads to."""
        if self.avoid:
            return
        for i, event in loop.reports:
            if type(event) is VertexCalled and event.action == "go":
                self.entry.decided(i, self.nearest(i)[0], event.angle_rad)

    def _send(self, loop: Loop | None = None) -> None:
        """Deliver the stations' answers in order, and log what they granted."""
        for i, payload in self.entry.outbox:
            self.uplink.reply(i, payload)
        for i, note in self.entry.notes:
            (loop or self.loop).event(note, i)
        self.entry.outbox, self.entry.notes = [], []
