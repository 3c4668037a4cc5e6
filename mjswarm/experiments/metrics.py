"""What an embodied exploration measures, from what its robots report (a loop function).

The robots' controllers report through typed events (:mod:`algorithms.exploration.
events`, in ``Loop.reports``) and :meth:`~algorithms.robot.Controller.telemetry`; this
loop function never reads a controller's attributes. Ground truth (true poses, the
nearest vertex) is the world's. It keeps each robot's path of vertices, who declared
completion where and when, who stopped and why, the collision rule's activations, relay
trips, infeasibility verdicts and the largest odometry heading error, and says when the
run is over (:meth:`ExplorationMetrics.should_stop`).

Events are accounted at the state the robots observed in the tick (as when they decided):
the time and true poses taken at the start of the tick. A path gains a vertex at a vertex
call after an arrival; a declaration counts at the vertex call that decides ``"done"``
(the :class:`~algorithms.exploration.events.Declared` that follows carries the same map),
and of two declarations in one tick the last counts (``Paths(keep="last")``: the graph
worlds keep the first; the embodied world keeps its own rule, so its results stay as
they are).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping

import networkx as nx

from algorithms.exploration.events import (
    Infeasible,
    RelayTrip,
    SpeedChanged,
    SpeedRuleFired,
    Stopped,
    VertexCalled,
)
from mjswarm.experiments.results import Paths
from mjswarm.worlds.loop import Loop, LoopFunctions


class Roster:
    """What the loop functions of one run share about the team, learnt from reports and
    from the world (never from controllers): who is done (stopped, declared, cut off
    with its part finished, switched off, never to be launched or docked) and when a
    robot last reached a vertex (or was launched)."""

    def __init__(self, docked=()) -> None:
        self.docked = frozenset(docked)
        #: stopped, declared, cut off, switched off or never to be launched
        self.finished: set[int] = set()
        self.failed: set[int] = set()  # switched off (faults)
        #: robots cut off from the root that finished their part: robot ->
        #: (time s, the vertex it stands on, its map as pairs of beacon ids)
        self.cut_off: dict[int, tuple[float, str, tuple]] = {}
        #: robots of the depot that can never be launched: the root closed
        self.unlaunched: set[int] = set()
        self.last_progress_s = 0.0

    def is_done(self, i: int) -> bool:
        return i in self.finished or i in self.docked

    @property
    def count_done(self) -> int:
        return len(self.finished | self.docked)


class ExplorationMetrics(LoopFunctions):
    """Args:
        world: the run's world (its true poses and clock).
        roster: the shared :class:`Roster`.
        nearest: ``nearest(i) -> (vertex, distance m)``, where robot ``i`` stands now.
        root: where every path starts.
        stall_timeout_s: end the run when no robot reached a vertex for this long (None:
            never; the tethered robots judge stalls themselves).
        stall_verdict: ``stall_verdict(paths)``, the verdict on rule 5's stall: whether
            it is infeasible, and its text.
    """

    def __init__(self, world, roster: Roster, nearest: Callable, root: str,
                 stall_timeout_s: float | None, stall_verdict: Callable) -> None:
        self.world, self.roster, self.nearest = world, roster, nearest
        self.stall_timeout_s = stall_timeout_s
        self.stall_verdict = stall_verdict
        #: the paths and the declaration; of two declarations in one tick the last counts
        self.record = Paths(world.n, root, keep="last")
        self.beacon_vertex: dict[str, str] = {}
        self.stopped: list[dict] = []
        self.speed_changes = 0
        self.relay_trips = 0
        self.infeasible = False
        self.heading_error_rad = 0.0
        self.ended_because = "max time"
        self._observed = (0.0, None)  # (time s, true poses) at the start of the tick
        self._loop: Loop | None = None

    def switched_off(self, i: int, reason: str) -> None:
        """A robot switched off (a fault) stops, unless it had stopped or declared."""
        if i not in self.roster.finished:
            self._stop(i, reason, self.world.time_s)
        self.roster.finished.add(i)
        self.roster.failed.add(i)

    def before_step(self, loop: Loop) -> None:
        self._observed = (self.world.time_s, self.world.true_poses().copy())

    def after_step(self, loop: Loop) -> None:
        now, poses = self._observed
        called = set()
        for i, event in loop.reports:
            kind = type(event)
            if kind is VertexCalled:
                self._vertex_called(loop, i, event, now)
                called.add(i)
            elif kind is SpeedRuleFired:
                self.speed_changes += event.count
            elif kind is SpeedChanged:
                loop.event(f"R{i + 1} speed {event.old_m_s:.3f} -> {event.new_m_s:.3f} m/s", i)
            elif kind is Stopped:
                if i not in self.roster.finished:
                    self._stop(i, event.reason, now)
                self.roster.finished.add(i)
            elif kind is RelayTrip:
                self.relay_trips += 1
            elif kind is Infeasible:
                self.infeasible = True
        controllers = loop.controllers
        for i in loop.stepped:
            if type(i) is int:  # a robot on the floor, not a fixed radio node
                state = controllers[i].telemetry()
                if i in called or state.get("on_edge"):
                    self._heading(state.get("heading_rad"), poses[i, 2])

    def _vertex_called(self, loop: Loop, i: int, call: VertexCalled, now: float) -> None:
        vertex = self.nearest(i)[0]  # where it stands (its beacon was served)
        if call.arrived:
            self.record.arrive(i, vertex)
            self.roster.last_progress_s = now
            loop.event(f"R{i + 1} at {vertex}", i)
        if call.beacon_id is not None:
            self.beacon_vertex.setdefault(call.beacon_id, vertex)
        if call.action == "done":
            self.record.declare(now, i, vertex, call.map_edges)
            self.roster.finished.add(i)
            loop.event(f"R{i + 1} declares completion at {vertex}", i)
            loop.event(f"R{i + 1} declared completion at {vertex}")
        elif call.action == "cut off":
            self.roster.cut_off[i] = (now, vertex, call.map_edges)
            self.roster.finished.add(i)
            loop.event(f"R{i + 1} finished the part it can reach at {vertex} "
                       "(cut off from the root)", i)

    def _heading(self, heading: float | None, true_yaw: float) -> None:
        """``heading_error_deg``: odometry against the truth, on lanes and at vertex calls
        (mid-scan the odometry over-reads rotation until the scan's own calibration
        corrects it)."""
        if heading is not None:
            error = abs(math.remainder(heading - true_yaw, 2 * math.pi))
            self.heading_error_rad = max(self.heading_error_rad, error)

    def _stop(self, i: int, reason: str, now: float) -> None:
        self.stopped.append({"robot": i + 1, "reason": reason, "at_s": round(now, 2)})
        if self._loop is not None:
            self._loop.event(f"R{i + 1} stopped: {reason}", i)

    def initialize(self, loop: Loop) -> None:
        self._loop = loop

    def should_stop(self, loop: Loop) -> bool:
        """Whether the run is over (and why, in ``ended_because``)."""
        if self.declared is not None:
            self.ended_because = "completed"
        elif self.infeasible:
            self.ended_because = self.stall_verdict(self.paths)[1]
        elif self.roster.count_done >= self.world.n:
            self.ended_because = "all robots stopped"
        elif (self.stall_timeout_s is not None
              and self.world.time_s - self.roster.last_progress_s > self.stall_timeout_s):
            self.ended_because = "stalled"
        else:
            return False
        return True

    @property
    def paths(self) -> list[list[str]]:
        """Each robot's path of vertices (:class:`~mjswarm.experiments.results.Paths`)."""
        return self.record.paths

    @property
    def declared(self) -> tuple[float, int, str] | None:
        """``(time s, robot index, vertex)`` of the declaration that counts, or None."""
        return self.record.declared

    @property
    def declared_map(self) -> tuple:
        """The declaring robot's map (pairs of beacon ids)."""
        return self.record.declared_map

    @property
    def traversals(self) -> int:
        return sum(len(p) - 1 for p in self.paths)

    @property
    def makespan(self) -> int | None:
        """The most edges any robot had traversed at completion (None: not completed)."""
        return None if self.declared is None else max(len(p) - 1 for p in self.paths)


def team_cut_off(roster: Roster, n_robots: int, ended: str) -> dict | None:
    """The team's completion when no robot left can get to the root, or
    None. The root closed, or every robot that could still reach it failed: no robot
    can declare then (its reach never holds the root: ``incidence_matrix``'s rule), so
    the verdict is the experimenter's, as "all robots stopped" (``ended``) is: every
    robot failed, cannot be launched (the root closed), or is cut off and finished the
    part it can reach (``CUT_OFF``: that part is its whole component of the graph
    without the closed vertices), and one robot at least did not fail (a team whose
    robots all failed finished nothing). The part the team could still reach is then
    the cut-off robots' components. Returns the cut-off robots (:attr:`Roster.cut_off`)."""
    if ended != "all robots stopped":
        return None
    team = [i for i in range(n_robots) if i not in roster.docked]
    if any(i not in roster.failed and i not in roster.unlaunched and i not in roster.cut_off
           for i in team) or all(i in roster.failed for i in team):
        return None  # a robot stopped for another reason, or nobody is left
    return roster.cut_off


def reachable_part(edges: Iterable[tuple[str, str]],
                   sources: Iterable[tuple[str, float]],
                   closed: Mapping[str, tuple[int, float]],
                   mapped: Iterable[tuple[str, str]] = ()) -> tuple[set[tuple[str, str]],
                                                                    list[dict]]:
    """Ground truth of a run with closed vertices (``closed``: vertex -> (robot
    index whose body closed it, time s), as the stations recorded them; ``sources``:
    where the team can still go from, and until when (s): the root until the end
    (``math.inf``), or each robot cut off from it where and when it finished its part).

    Returns the edges (sorted pairs) among the vertices reachable from a source without
    entering a vertex closed before that source's time (the part a team can finish:
    empty if the root itself closed with nobody out), and every other edge the team
    could not reach, with why:
    ``{"edge": [u, v], "why": text}``, the why naming the closed vertex it touches, or
    the closed vertices it lies beyond. An edge of ``mapped`` (the declared map, sorted
    pairs) was reached, before its vertex closed, and is not listed."""
    mapped = set(mapped)
    g = nx.Graph(list(edges))
    open_part = g.subgraph(set(g) - set(closed))
    part = set()
    for source, until_s in sources:
        shut = {v for v, (_, at_s) in closed.items() if at_s < until_s}
        if source not in part and source not in shut:
            part |= nx.node_connected_component(g.subgraph(set(g) - shut), source)

    def closed_by(v: str) -> str:
        robot, at_s = closed[v]
        return f"{v} closed by R{robot + 1} stopped in its area at {at_s:.1f} s"

    reachable, unreachable = set(), []
    for u, v in sorted(tuple(sorted(e)) for e in g.edges):
        if u in part and v in part:
            reachable.add((u, v))
            continue
        if (u, v) in mapped:
            continue
        ends = [w for w in (u, v) if w in closed]
        if ends:
            why = "vertex " + " and ".join(closed_by(w) for w in ends)
        else:
            beyond = nx.node_connected_component(open_part, u)
            gates = sorted({w for x in beyond for w in g[x] if w in closed})
            why = "beyond vertex " + " and ".join(closed_by(w) for w in gates)
        unreachable.append({"edge": [u, v], "why": why})
    return reachable, unreachable
