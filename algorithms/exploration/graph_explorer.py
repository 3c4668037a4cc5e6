"""A strategy as the controller of a robot in the graph worlds.

In a graph world a robot has no body: each vertex call is an observation whose beacon is
the vertex's store and whose :class:`~algorithms.robot.VertexSense` is a perfect scan of
the vertex (incidence angles, and the angle of the edge it arrived by), and its decision
is a command: ``edge_rad`` to leave along an edge, nothing to idle, a
:class:`~algorithms.exploration.events.Declared` event to declare completion. The
strategy is the same object that runs inside the embodied
:class:`~algorithms.exploration.explorer.Explorer`.

In the radio graph world (:mod:`mjswarm.worlds.radiograph`) a robot explores on a tether,
with relays on demand: :class:`TetheredExplorer` runs a
:class:`~algorithms.exploration.relay.ConnectedExplorer` in that world's two phases.
"""

from __future__ import annotations

from collections.abc import Mapping

from algorithms.exploration.base import Strategy, angle_gap
from algorithms.exploration.events import Declared, Infeasible, vertex_called
from algorithms.exploration.leash import Leash
from algorithms.exploration.relay import MODES, ConnectedExplorer
from algorithms.exploration.tether import BASE
from algorithms.robot import STOP, Command, Controller, Observation


class GraphExplorer(Controller):
    """Runs ``strategy`` at the vertex calls of a graph world (module docstring); build
    one with :func:`graph_explorer`, which adds the strategy's arrival bookkeeping when it
    has any. With ``report``, every call is also reported as a
    :class:`~algorithms.exploration.events.VertexCalled` event (for a recording: each
    costs the robot's map and its beacon's matrix, so sweeps go without)."""

    def __init__(self, strategy: Strategy, report: bool = False) -> None:
        self.strategy = strategy
        self.report = report
        self._go: dict[float, Command] = {}  # by angle: a command per decision, made once

    def step(self, observation: Observation) -> Command:
        vertex = observation.vertex
        if vertex is None:
            return STOP
        decision = self.strategy.on_vertex(observation.beacon, vertex.angles_rad,
                                           vertex.arrived_by_rad)
        if self.report:
            call = vertex_called(vertex.arrived_by_rad is not None, decision, observation.beacon,
                                 self.strategy.map_edges())
            events = (call, Declared(call.map_edges)) if decision.action == "done" else (call,)
            return Command(edge_rad=decision.angle if decision.action == "go" else None,
                           events=events)
        if decision.action == "go":
            command = self._go.get(decision.angle)
            if command is None:
                command = self._go[decision.angle] = Command(edge_rad=decision.angle)
            return command
        if decision.action == "done":
            return Command(events=(Declared(tuple(self.strategy.map_edges())),))
        if decision.action == "idle":
            return STOP
        raise ValueError(f"robot {self.strategy.index + 1} answered an unknown decision "
                         f"{decision!r}")


class BookkeepingExplorer(GraphExplorer):
    """A :class:`GraphExplorer` whose strategy keeps the bookkeeping of an arrival apart
    from its decision (:meth:`~algorithms.exploration.base.Strategy.arrive`, MR-DFS): the
    loop lets every robot of a tick perceive before any decides."""

    def perceive(self, observation: Observation) -> None:
        vertex = observation.vertex
        if vertex is not None:
            self.strategy.arrive(observation.beacon, vertex.angles_rad, vertex.arrived_by_rad)


def graph_explorer(strategy: Strategy, report: bool = False) -> GraphExplorer:
    """The controller that runs ``strategy`` in a graph world (``report``: it reports
    its vertex calls, :class:`GraphExplorer`)."""
    keeps_books = type(strategy).arrive is not Strategy.arrive
    return (BookkeepingExplorer if keeps_books else GraphExplorer)(strategy, report)


class TetheredExplorer(Controller):
    """A :class:`~algorithms.exploration.relay.ConnectedExplorer` as the controller of a
    robot in the radio graph world, whose ticks have a move phase and an answer phase
    (:class:`~algorithms.robot.LegSense`'s ``answering``).

    Move phase: :meth:`perceive` reads the radio (``hear``) and, at a vertex call, does
    the arrival's bookkeeping (``arrive``: every robot of the tick before any decides);
    :meth:`step` decides at a vertex call (``on_vertex``), then on an edge (or leaving
    one) asks ``direction`` and, for the step, its leash (the tether's ``may_step``, rule
    3, and the ways a wall closed: :class:`~algorithms.exploration.leash.Leash`), and
    answers with what it heard to send on; with ``walls`` (its arena's walls may cut a
    link the leash allowed) a robot on an edge whose parent's link is gone steps its last
    steps back instead, never back onto the vertex it left. Answer phase: a walk back that reached the
    vertex is told (``arrived_back``), then ``after`` (adoption requests, beats) and rule
    5's verdict, reported as :class:`~algorithms.exploration.events.Infeasible`. With
    ``constrained`` False (no constraint to keep) it only walks its strategy: it never
    hears, waits or speaks.
    """

    def __init__(self, connected: ConnectedExplorer, constrained: bool = True,
                 report: bool = False, walls: bool = False) -> None:
        self.connected = connected
        self.constrained = constrained
        self.report = report
        self.walls = walls
        self._ticks_per_unit = connected.tether.ticks_per_unit
        self._out: list = []  # what it heard to send on
        self._wanted = None  # the step the tether forbade it in this tick's move phase
        self._moved = self._back = False
        #: its leash against walls (:mod:`~algorithms.exploration.leash`)
        self.leash = Leash(connected.tether) if constrained else None

    def telemetry(self) -> Mapping[str, float]:
        """``relay_trips``: relay missions it set out on (rule 6); ``mode``: the index of
        its mode in :data:`~algorithms.exploration.relay.MODES`; ``parent``: its first
        tether parent (a robot id; -1 for the base)."""
        c = self.connected
        parent = c.tether.parents[0] if c.tether.parents else BASE
        return {"relay_trips": c.relay_trips, "mode": MODES.index(c.mode),
                "parent": -1 if parent == BASE else parent}

    def perceive(self, observation: Observation) -> None:
        if observation.leg.answering:
            return
        c, vertex = self.connected, observation.vertex
        if self.constrained:
            self._out = c.hear(self._tick(observation), observation.inbox,
                               observation.leg.around_m)
        if vertex is not None:
            c.arrive(observation.beacon, vertex.angles_rad, vertex.arrived_by_rad)

    def step(self, observation: Observation) -> Command:
        if observation.leg.answering:
            return self._answer(observation) if self.constrained else STOP
        return self._move(observation)

    def _tick(self, observation: Observation) -> int:
        return round(observation.time_s * self._ticks_per_unit)

    def _move(self, observation: Observation) -> Command:
        c, leg, vertex = self.connected, observation.leg, observation.vertex
        out, self._out = tuple(self._out), []
        was_back = self._back
        self._wanted, self._moved, self._back = None, False, False
        steps, progress, edge_rad = leg.steps_m, leg.progress, None
        if vertex is not None:
            beacon, arrived_by = observation.beacon, vertex.arrived_by_rad
            decision = c.on_vertex(beacon, vertex.angles_rad, arrived_by)
            called = (vertex_called(arrived_by is not None, decision, beacon,
                                    c.mind.map_edges()),) if self.report else ()
            if decision.action == "done":
                return Command(messages=out,
                               events=(*called, Declared(tuple(c.mind.map_edges()))))
            if decision.action == "idle":
                return Command(messages=out, events=called)
            if decision.action != "go":
                raise ValueError(f"robot {c.index + 1} answered an unknown decision "
                                 f"{decision!r}")
            edge_rad, progress = decision.angle, 0.0
            steps = _nearest(leg.exits_m, decision.angle)
            if self.leash is not None:
                self.leash.new_leg()
        if steps is None:  # standing at a vertex between calls
            return Command(messages=out)
        if self.leash is None:
            sense = 1
        elif self.walls and vertex is None and self.leash.cut_off(leg.around_m):
            sense = self.leash.undo(leg.around_m, was_back, lambda s: -s) or 0
        else:
            sense = c.direction(progress)
            # the step off a vertex joins no trail: a retrace never walks back onto it
            if sense and self.leash.check(sense, steps[sense < 0], leg.around_m, sense < 0,
                                          progress == 0.0, reserve=False) is not None:
                self._wanted, sense = steps[sense < 0], 0
        self._moved, self._back = sense != 0, sense < 0
        return Command(float(sense), 0.0, None, out, None, edge_rad,
                       called if vertex is not None else ())

    def _answer(self, observation: Observation) -> Command:
        c, leg, tick = self.connected, observation.leg, self._tick(observation)
        if self._back and leg.steps_m is None:  # the walk back reached the vertex
            c.arrived_back()
        out = c.after(tick, self._wanted, self._moved, leg.around_m,
                      cut=self.leash.cut_on_this_way(self._back))
        events = (Infeasible(),) if c.tether.stalled(tick) else ()
        return Command(messages=tuple(out), events=events)


def _nearest(exits: Mapping, angle: float):
    """The entry of ``exits`` (by incidence angle, rad) nearest to ``angle``."""
    found = exits.get(angle)
    return found if found is not None else exits[min(exits, key=lambda a: angle_gap(a, angle))]
