"""A strategy as the controller of a robot in the graph worlds.

In a graph world a robot has no body: each vertex call is an observation whose beacon is
the vertex's store and whose :class:`~algorithms.robot.VertexSense` is a perfect scan of
the vertex (incidence angles, and the angle of the edge it arrived by), and its decision
is a command: ``edge_rad`` to leave along an edge, nothing to idle, a
:class:`~algorithms.exploration.events.Declared` event to declare completion. The
strategy is the same object that runs inside the embodied
:class:`~algorithms.exploration.explorer.Explorer`.
"""

from __future__ import annotations

from algorithms.exploration.base import Strategy
from algorithms.exploration.events import Declared
from algorithms.robot import STOP, Command, Controller, Observation


class GraphExplorer(Controller):
    """Runs ``strategy`` at the vertex calls of a graph world (module docstring); build
    one with :func:`graph_explorer`, which adds the strategy's arrival bookkeeping when it
    has any."""

    def __init__(self, strategy: Strategy) -> None:
        self.strategy = strategy

    def step(self, observation: Observation) -> Command:
        vertex = observation.vertex
        if vertex is None:
            return STOP
        decision = self.strategy.on_vertex(observation.beacon, vertex.angles_rad,
                                           vertex.arrived_by_rad)
        if decision.action == "go":  # positional: a call per decision
            return Command(0.0, 0.0, None, (), None, decision.angle)
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


def graph_explorer(strategy: Strategy) -> GraphExplorer:
    """The controller that runs ``strategy`` in a graph world."""
    keeps_books = type(strategy).arrive is not Strategy.arrive
    return (BookkeepingExplorer if keeps_books else GraphExplorer)(strategy)
