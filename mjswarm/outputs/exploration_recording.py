"""Recording an embodied exploration: a loop function the caller hands in.

:class:`ExplorationRecording` writes, with a :class:`~mjswarm.outputs.recording.Recorder`,
what the experiment's loop functions and the robots report, never reading a controller's
attributes: every tick the world's ground truth (poses, the sensor record, bearings) and
each robot's speed from its telemetry; at each vertex call (the robots' typed
:class:`~algorithms.exploration.events.VertexCalled` events) the beacon's contents and
the robot's map, its beacon ids drawn at the arena vertices where they were first read;
the experiment's events (:meth:`~mjswarm.worlds.loop.Loop.event`) and contacts; and,
with connectivity tables, the radio graph with each robot's belief against the truth
(``truth``: the experiment's truth function, handed in so that outputs import no
experiment) five times a second.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from algorithms.exploration.events import VertexCalled
from mjswarm.arena.spec import ArenaSpec
from mjswarm.core.contacts import contact_event
from mjswarm.worlds.loop import Loop, LoopFunctions


class ExplorationRecording(LoopFunctions):
    """Records an embodied exploration of ``spec`` with ``recorder`` (module docstring).
    ``truth(graph, reference, robots) -> {robot: answer}``: with it, and robots that keep
    connectivity tables, beliefs against the truth every ``every`` ticks."""

    def __init__(self, recorder, spec: ArenaSpec, truth: Callable | None = None,
                 every: int = 10) -> None:
        self.recorder, self.spec, self.truth, self.every = recorder, spec, truth, every
        self._vertices = np.array(list(spec.vertices.values()))
        self._ids = list(spec.vertices)
        self._beacon_vertex: dict[str, str] = {}
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
        for i, event in loop.reports:
            if type(event) is VertexCalled:
                self._vertex_call(world, i, event)
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

    def _vertex_call(self, world, i: int, call: VertexCalled) -> None:
        """The beacon's contents and the robot's map (beacon ids shown as arena vertices)."""
        xy = world.true_poses()[i, :2]
        vertex = self._ids[int(np.hypot(*(self._vertices - xy).T).argmin())]
        if call.beacon_id is not None:
            self._beacon_vertex.setdefault(call.beacon_id, vertex)
        step, now = self._observed
        self.recorder.log_beacon(step, now, vertex, f"beacon {call.beacon_id}\n{call.beacon_text}")
        where = self._beacon_vertex
        edges = [(where[a], where[b]) for a, b in call.map_edges if a in where and b in where]
        nodes = {v: self.spec.vertices[v] for e in edges for v in e}
        nodes.setdefault(vertex, self.spec.vertices[vertex])
        self.recorder.log_explored_graph(step, now, i, nodes, edges)

    def on_event(self, loop: Loop, text: str, robot: int | None) -> None:
        """An experiment's event, at the current tick."""
        self.recorder.log_event(loop.ticks, loop.world.time_s, text, robot)
