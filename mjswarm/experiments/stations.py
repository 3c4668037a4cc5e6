"""Vertex stations: who may enter which vertex area (embodied exploration's vertex entry).

Seed 003's robots kept apart on edges with the bearing-rate rule and spent only a moment
at a vertex; ours scan there for about ten seconds, and a robot's sidesteps between the
vertex centre and its lane cross the lanes of the other edges at that vertex. So a vertex
area holds one robot at a time, and each vertex has a *station* (the paper's central
station, which knew its own vertices, emulated the beacons; ours also grants entry) that
decides who that is. The protocol, per robot:

1. A robot that has decided, on a vertex centre ``u``, to leave along the edge at angle
   ``a`` tells ``u``'s station so (it names the edge by its angle, in the common frame of
   the beacons); the station knows its own edges and asks the station of the far end
   ``w`` for entry on the robot's behalf (:meth:`VertexStations.request`).
2. The robot waits on ``u``'s centre until ``w`` is granted, then leaves. It holds ``w``
   from the grant and ``u`` until it is in the corridor of its edge (has seen its left
   wall): then it is clear of ``u``'s area (:meth:`VertexStations.release`).
3. A robot that stops for good (lost, failed) releases everything it holds.

**No circular wait.** A robot waits only on a vertex centre, never on a lane, so the
only waits are "robot at ``u`` wants ``w``, whose holder stands on ``w``'s centre and
wants ``x``, ...". Such a chain that closes (robots on the centres of a cycle of
vertices, each wanting the next: at least two, e.g. two robots swapping the ends of an
edge) is granted as a whole: every robot in it gets its next vertex and leaves at once; each
usually arrives after the previous holder has left (leaving takes a turn and a
sidestep; arriving, a whole edge), and otherwise waits where its lane's wall ends, clear
of the vertex area, until that robot is in its corridor (:mod:`mjswarm.experiments.exploration`). Robots never wait behind one another on a lane
either: a lane leads to one vertex, held by the one robot on it. This replaces the
scheme of issue 5, where a robot asked for the vertex ahead from its lane: a robot
stopped by the speed rule just after leaving (still holding its vertex) behind a robot
waiting on the lane for a vertex whose holder was stopped the same way closed a cycle
(issue 13: four robots on one edge of ``lattice:10x10``).

**Robots that turn back** (rule 6's relays, ours) ask for the vertex behind them from a
lane (``at`` None) and wait where that lane's wall ends. Such a robot holds nothing (it
gave up the vertex ahead when it turned, and the one behind when it reached its
corridor), so no chain of station waits closes through it; the chains above are
unchanged. One wait is not the stations': a robot that asked from its corridor, not yet
turned (too near the vertex behind for a U-turn), still stands on the lane that leads
away from that vertex, and a robot leaving that vertex along the same edge is stopped
behind it by the speed rule while it holds the vertex the first one waits for. That
deadlock is not broken here; the team's stall verdict ends such a run (seen once, on
``arena2`` with 4 robots at 2 m, while rule 6 was being built).

Grants go in the order of the requests (then robot index), so a waiting robot is served
before later ones. Ground truth used here, as the paper's station had it: the arena's
edges at each vertex (:func:`mjswarm.arena.geometry.vertex_fans`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mjswarm.arena import ArenaSpec
from mjswarm.arena.geometry import vertex_fans


@dataclass(frozen=True)
class Request:
    """Robot waiting on the centre of ``at`` (None: on a lane, turned back) to go to ``to``
    (requested at ``since_s``)."""

    at: str | None
    to: str
    since_s: float


class VertexStations:
    """The stations of every vertex of ``spec``: holds, requests, grants."""

    def __init__(self, spec: ArenaSpec) -> None:
        self._fans = vertex_fans(spec)
        self.holder: dict[str, int] = {}
        self.requests: dict[int, Request] = {}

    def edge_towards(self, vertex: str, angle: float) -> tuple[str, float]:
        """The neighbour of ``vertex`` along the edge nearest to ``angle`` (rad, common
        frame) and how far (rad) that edge's true angle is from it."""
        true, neighbour = min(
            self._fans[vertex], key=lambda an: abs(math.remainder(an[0] - angle, 2 * math.pi)))
        return neighbour, abs(math.remainder(true - angle, 2 * math.pi))

    def occupy(self, robot: int, vertex: str) -> None:
        """``robot`` was put on ``vertex`` (a launch): it holds it."""
        self.holder[vertex] = robot

    def request(self, robot: int, at: str | None, to: str, now_s: float) -> None:
        """``robot``, on the centre of ``at`` (None: on a lane), wants to go to ``to``."""
        self.requests[robot] = Request(at, to, now_s)

    def withdraw(self, robot: int) -> None:
        """``robot`` no longer asks (no effect once granted)."""
        self.requests.pop(robot, None)

    def grant(self) -> list[tuple[int, str]]:
        """Grant what can be granted now; returns ``(robot, vertex)`` pairs, in order."""
        granted = []
        for robot in self._queue():
            to = self.requests[robot].to
            if to not in self.holder:
                granted.append((robot, to))
                self._give(robot)
        for robot in self._queue():
            if robot in self.requests:  # not granted as part of an earlier cycle
                cycle = self._cycle_from(robot)
                granted += [(r, self.requests[r].to) for r in cycle]
                for r in cycle:
                    self._give(r)
        return granted

    def release(self, robot: int, vertex: str | None) -> None:
        """``robot`` is clear of ``vertex`` (no effect if someone else holds it now)."""
        if vertex is not None and self.holder.get(vertex) == robot:
            del self.holder[vertex]

    def release_all(self, robot: int) -> list[str]:
        """``robot`` stopped for good: drop its request and every hold; returns the vertices."""
        self.requests.pop(robot, None)
        held = [v for v, r in self.holder.items() if r == robot]
        for v in held:
            del self.holder[v]
        return held

    def _queue(self) -> list[int]:
        return sorted(self.requests, key=lambda r: (self.requests[r].since_s, r))

    def _give(self, robot: int) -> None:
        self.holder[self.requests.pop(robot).to] = robot

    def _cycle_from(self, robot: int) -> list[int]:
        """The robots of a closed chain of waits through ``robot`` (empty if none):
        each stands on the centre of the vertex the previous one wants."""
        chain = [robot]
        while True:
            wanted = self.requests[chain[-1]].to
            holder = self.holder.get(wanted)
            request = self.requests.get(holder) if holder is not None else None
            if request is None or request.at != wanted:
                return []  # the holder is not waiting on that centre: it will move on
            if holder == robot:
                return chain
            if holder in chain:
                return []  # a cycle that does not pass through ``robot``
            chain.append(holder)
