"""Recording an exploration, in any world: loop functions the caller hands in.

:class:`ExplorationRecording` (the embodied world) and :class:`GraphExplorationRecording`
(the graph world and the radio graph world) write, with a
:class:`~mjswarm.outputs.recording.Recorder`, what the experiment's loop functions and
the robots report, never reading a controller's attributes: every tick the world's ground
truth (poses; in the embodied world the sensor record and bearings) and each robot's
telemetry; at each vertex call (the robots' typed
:class:`~algorithms.exploration.events.VertexCalled` events) the beacon's contents, the
robot's map (its beacon ids drawn at the arena vertices where they were first read), the
incidence matrix it carries (a markdown table as Nagavarapu et al. print it: rows are vertices,
columns edges, entries the incidence angles, negative for completed and out edges) and
its decision as its state; the experiment's events (:meth:`~mjswarm.worlds.loop.Loop.event`)
and contacts; and the radio graph: with connectivity tables, each robot's belief against
the truth (``truth``: the experiment's truth function, handed in so that outputs import no
experiment) five times a second; in the radio graph world, who hears whom, the base, and
each robot's tether to its parent (from its telemetry).

Graph-world recordings run on a time-unit timeline: ``sim_time`` counts time units (shown
as seconds: 1 s = one edge of the unit-time graph world) and ``step`` tenths of a unit;
robots glide along their edges in ten samples per time unit.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from fractions import Fraction

import numpy as np

from algorithms.exploration.events import Declared, VertexCalled
from algorithms.exploration.relay import MODES
from mjswarm.arena.spec import ArenaSpec
from mjswarm.core.contacts import contact_event, robot_name
from mjswarm.worlds.loop import Loop, LoopFunctions

#: Samples per time unit of a graph-world recording (the radio graph world's ticks).
SAMPLES_PER_UNIT = 10


def angle_text(theta: float) -> str:
    """An incidence-matrix entry as Nagavarapu et al. print it: a multiple of pi (``-3π/2``)
    when it is one with a denominator up to 12; a measured angle within 0.05 rad of a
    multiple of pi/4 as that multiple after ``≈`` (an angle near 0 is near 2π: angles lie
    in (0, 2π]); else radians to two decimals."""
    if theta == 0:
        return "0"
    f = Fraction(theta / math.pi).limit_denominator(12)
    near = ""
    if abs(float(f) * math.pi - theta) > 1e-6:
        quarter = round(theta / (math.pi / 4))
        if abs(quarter * math.pi / 4 - theta) > 0.05:
            return f"{theta:.2f}"
        near, f = "≈", Fraction(quarter or (8 if theta > 0 else -8), 4)
    sign = near + ("-" if f < 0 else "")
    num, den = abs(f.numerator), f.denominator
    head = "π" if num == 1 else f"{num}π"
    return sign + (head if den == 1 else f"{head}/{den}")


def edge_label(a: str, b: str) -> str:
    """The paper's name of the edge between vertices ``a`` and ``b``: ``e56`` for v5-v6
    (``e9,10`` when a number has two digits), ``a-b`` for other names."""
    ma, mb = re.fullmatch(r"v(\d+)", a), re.fullmatch(r"v(\d+)", b)
    if ma and mb:
        i, j = sorted((int(ma[1]), int(mb[1])))
        return f"e{i}{j}" if i < 10 and j < 10 else f"e{i},{j}"
    return "-".join(sorted((a, b)))


class ArenaNames:
    """Names a robot's beacon ids and incidence-matrix ends with the arena's vertices and
    edges (ground truth, for reviewers): a beacon id is the vertex where it was first
    read, the end ``(tag, theta)`` the edge leaving that vertex nearest to ``theta``."""

    def __init__(self, spec: ArenaSpec) -> None:
        self.spec = spec
        self.ids = list(spec.vertices)
        self.xy = np.array(list(spec.vertices.values()), float)
        self.vertex_of: dict[str, str] = {}
        self._fan: dict[str, list[tuple[float, str]]] = {v: [] for v in spec.vertices}
        for a, b in spec.edges:
            for u, w in ((a, b), (b, a)):
                (x0, y0), (x1, y1) = spec.vertices[u], spec.vertices[w]
                self._fan[u].append((math.atan2(y1 - y0, x1 - x0), w))

    def nearest(self, xy) -> str:
        """The arena vertex nearest to the point ``xy`` (m)."""
        return self.ids[int(np.hypot(*(self.xy - np.asarray(xy)[:2]).T).argmin())]

    def saw(self, beacon_id: str | None, vertex: str) -> None:
        """Beacon ``beacon_id`` was read at ``vertex`` (the first reading names it)."""
        if beacon_id is not None:
            self.vertex_of.setdefault(beacon_id, vertex)

    def row(self, tag: str) -> str:
        v = self.vertex_of.get(tag)
        return tag if v is None else f"{v} ({tag})"

    def far_end(self, tag: str, theta: float) -> str | None:
        """The vertex reached from beacon ``tag``'s vertex along the edge at ``theta``."""
        v = self.vertex_of.get(tag)
        if v is None or not self._fan[v]:
            return None
        gap = lambda a: abs(math.remainder(a - theta, 2 * math.pi))  # noqa: E731
        return min(self._fan[v], key=lambda f: gap(f[0]))[1]

    def column(self, ends) -> str:
        if len(ends) == 2:
            a, b = (self.vertex_of.get(t) for t, _ in ends)
            return edge_label(a, b) if a and b else f"{ends[0][0]}-{ends[1][0]}"
        (tag, theta), = ends
        v, u = self.vertex_of.get(tag), self.far_end(tag, theta)
        return edge_label(v, u) if v and u else f"{tag}@{angle_text(theta)}"

    def map(self, map_edges, here: str) -> tuple[dict[str, tuple[float, float]], list]:
        """A map (pairs of beacon ids) as arena vertices -> positions (m) and edges."""
        where = self.vertex_of
        edges = [(where[a], where[b]) for a, b in map_edges if a in where and b in where]
        nodes = {v: self.spec.vertices[v] for e in edges for v in e}
        nodes.setdefault(here, self.spec.vertices[here])
        return nodes, edges


def matrix_markdown(matrix, names: ArenaNames, title: str) -> str:
    """``matrix`` (an :class:`~algorithms.exploration.incidence_matrix.IncidenceMatrix`)
    as a markdown table under ``title``: a row per known vertex, a column per edge in
    Algorithm 2's order (completed, out, unexplored), the entries as Nagavarapu et al. print them."""
    if matrix is None:
        return f"**{title}**\n\n(no incidence matrix)"
    tags, columns, dense = matrix.to_array()
    statuses = ["completed" if len(c) == 2 else "out" if dense[tags.index(c[0][0]), j] < 0
                else "unexplored" for j, c in enumerate(columns)]
    counts = {s: statuses.count(s) for s in ("completed", "out", "unexplored")}
    head = ["vertex", *(names.column(c) for c in columns)]
    lines = [f"**{title}**", "",
             f"{len(tags)} vertices x {len(columns)} edges: {counts['completed']} completed, "
             f"{counts['out']} out, {counts['unexplored']} unexplored", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for i, tag in enumerate(tags):
        lines.append("| " + " | ".join([names.row(tag),
                                         *(angle_text(x) for x in dense[i])]) + " |")
    return "\n".join(lines)


def beacon_markdown(call: VertexCalled, vertex: str, names: ArenaNames) -> str:
    """What the beacon at ``vertex`` holds after ``call``."""
    return matrix_markdown(call.matrix, names, f"beacon {call.beacon_id} at {vertex}")


class _Calls:
    """What both recordings do at a robot's vertex call (module docstring)."""

    def __init__(self, recorder, spec: ArenaSpec) -> None:
        self.recorder, self.names = recorder, ArenaNames(spec)

    def vertex_call(self, step: int, now: float, i: int, xy, call: VertexCalled) -> None:
        rec, names = self.recorder, self.names
        vertex = names.nearest(xy)
        names.saw(call.beacon_id, vertex)
        rec.log_beacon(step, now, vertex, beacon_markdown(call, vertex, names))
        nodes, edges = names.map(call.map_edges, vertex)
        rec.log_explored_graph(step, now, i, nodes, edges)
        what = call.action if call.angle_rad is None else \
            f"{call.action} {names.column(((call.beacon_id, call.angle_rad),))}" \
            if call.beacon_id is not None else call.action
        rec.log_matrix(step, now, i, matrix_markdown(
            call.matrix, names, f"In({robot_name(i)}) at {vertex}, t = {now:g}: {what}"))
        rec.log_state(step, now, i, call.action)
        rec.log_event(step, now, f"{robot_name(i)} at {vertex}: {what}", i)


class ExplorationRecording(LoopFunctions):
    """Records an embodied exploration of ``spec`` with ``recorder`` (module docstring).
    ``truth(graph, reference, robots) -> {robot: answer}``: with it, and robots that keep
    connectivity tables, beliefs against the truth every ``every`` ticks."""

    #: it reads the robots' VertexCalled reports
    reads_vertex_calls = True

    def __init__(self, recorder, spec: ArenaSpec, truth: Callable | None = None,
                 every: int = 10) -> None:
        self.recorder, self.spec, self.truth, self.every = recorder, spec, truth, every
        self._calls = _Calls(recorder, spec)
        self._contacts = 0
        self._observed = (0, 0.0)
        self._sample = None
        self._speed: np.ndarray | None = None

    def initialize(self, loop: Loop) -> None:
        n = loop.world.n
        self._speed = np.array([loop.controllers[i].telemetry().get("speed_m_s", 0.0)
                                for i in range(n)])

    def before_step(self, loop: Loop) -> None:
        world = loop.world
        self._observed = (loop.ticks, world.time_s)
        tables = self.truth is not None and world.radio is not None and not world.fixed
        if tables and loop.ticks % self.every == 0 and loop.ticks:
            graph = world.radio.graph()
            self._sample = (list(graph.edges), self.truth(graph, 0, range(1, world.n)))

    def after_step(self, loop: Loop) -> None:
        world, rec = loop.world, self.recorder
        calls = [(i, e) for i, e in loop.reports if type(e) is VertexCalled]
        if calls:
            poses, (step, now) = world.true_poses(), self._observed
            for i, event in calls:
                self._calls.vertex_call(step, now, i, poses[i, :2], event)
        for i in loop.stepped:
            if type(i) is int:
                self._speed[i] = loop.controllers[i].telemetry().get("speed_m_s", 0.0)
        step, now = loop.ticks, world.time_s
        if self._sample is not None:
            links, truths = self._sample
            self._sample = None
            beliefs = {i: "biconnected" if loop.controllers[i].telemetry().get("biconnected")
                       else "not" for i in truths}
            rec.log_radio(step, now, [tuple(e) for e in links], beliefs, truths)
        readings = world.sim.readings()
        poses = world.true_poses()
        rec.log_tick(step, now, poses, readings["line"], readings["ir"], self._speed.copy(),
                     [list(b.items()) for b in world.bearing_readings()],
                     readings["encoder"], readings["battery"])
        events = world.contact_events() or []
        for _, i, j in events[self._contacts:]:
            rec.log_event(step, now, contact_event(i, j, poses))
        self._contacts = len(events)

    def on_event(self, loop: Loop, text: str, robot: int | None) -> None:
        """An experiment's event, at the current tick."""
        self.recorder.log_event(loop.ticks, loop.world.time_s, text, robot)


class GraphExplorationRecording(LoopFunctions):
    """Records an exploration of ``spec`` in the graph world or the radio graph world
    with ``recorder`` (made with ``sensors=False``; module docstring): robots glide
    along their edges, ten samples per time unit; with a radio, the radio graph (the base
    as node ``base``) and every robot's tether to its first parent each tick."""

    reads_vertex_calls = True

    def __init__(self, recorder, spec: ArenaSpec) -> None:
        self.recorder, self.spec = recorder, spec
        self._calls = _Calls(recorder, spec)
        self._now = 0.0
        self._poses: np.ndarray | None = None
        self._legs: list | None = None  # per robot: (from xy, t0, to xy, t1)
        self._yaw: np.ndarray | None = None
        self._ended = False

    def initialize(self, loop: Loop) -> None:
        world = loop.world
        self._poses = world.true_poses()
        self._yaw = np.zeros(world.n)
        self._legs = [(p[:2], 0.0, p[:2], 0.0) for p in self._poses]

    def before_step(self, loop: Loop) -> None:
        self._now = loop.world.time_s
        self._poses = loop.world.true_poses()

    def after_step(self, loop: Loop) -> None:
        world, now = loop.world, self._now
        step = round(now * SAMPLES_PER_UNIT)
        for i, event in loop.reports:
            if type(event) is VertexCalled:
                self._calls.vertex_call(step, now, i, self._poses[i, :2], event)
            elif type(event) is Declared:
                self.recorder.log_state(step, now, i, "declared")
        if world.radio is None:
            self._glide(loop, now)
        elif world.phase == "move":  # a whole tick is over: where everyone is now
            self._tick(loop)

    def _glide(self, loop: Loop, now: float) -> None:
        """Graph world: the robots stepped at ``now`` set out; samples up to the next
        event (the world's time now)."""
        world, legs = loop.world, self._legs
        after = world.true_poses()
        for i in loop.stepped:
            start, end = self._poses[i, :2], after[i, :2]
            legs[i] = (start, now, end, float(world.arrival[i]) if (end != start).any() else now)
            if (end != start).any():
                self._yaw[i] = math.atan2(end[1] - start[1], end[0] - start[0])
        upto = world.time_s if not world.idle else now
        times = np.arange(now, max(upto, now + 1e-9), 1.0 / SAMPLES_PER_UNIT)
        for t in times:
            poses = np.column_stack([self._where(t), self._yaw])
            self.recorder.log_tick(round(t * SAMPLES_PER_UNIT), float(t), poses)

    def _where(self, t: float) -> np.ndarray:
        xy = []
        for start, t0, end, t1 in self._legs:
            share = 1.0 if t1 <= t0 else min(max((t - t0) / (t1 - t0), 0.0), 1.0)
            xy.append(np.asarray(start) + share * (np.asarray(end) - np.asarray(start)))
        return np.array(xy, float).reshape(-1, 2)

    def _tick(self, loop: Loop) -> None:
        """Radio graph world: poses, telemetry, the radio graph and the tethers."""
        world, rec = loop.world, self.recorder
        now = world.time_s
        step = round(now * SAMPLES_PER_UNIT)
        poses = world.true_poses()
        moved = poses[:, :2] - self._poses[:, :2]
        going = np.hypot(moved[:, 0], moved[:, 1]) > 1e-12
        self._yaw[going] = np.arctan2(moved[going, 1], moved[going, 0])
        state = {i: dict(loop.controllers[i].telemetry()) for i in range(world.n)
                 if i in loop.controllers}
        rec.log_tick(step, now, np.column_stack([poses[:, :2], self._yaw]), state=state)
        for i, values in state.items():
            mode = values.get("mode")
            if mode is not None:
                rec.log_state(step, now, i, MODES[int(mode)], "mode", changes_only=True)
        base = {name: xy for name, xy in world.fixed.items()}
        edges = [tuple(e) for e in world.radio.graph().edges]
        parents = {i: int(v["parent"]) for i, v in state.items() if "parent" in v}
        rec.log_radio(step, now, [(a, b) for a, b in edges
                                  if type(a) is int and type(b) is int],
                      fixed=base,
                      fixed_links=[(a if type(a) is int else b, a if type(a) is not int else b)
                                   for a, b in edges if (type(a) is int) != (type(b) is int)],
                      tethers=parents)

    def on_event(self, loop: Loop, text: str, robot: int | None) -> None:
        now = loop.world.time_s
        self.recorder.log_event(round(now * SAMPLES_PER_UNIT), now, text, robot)

