"""What exploring robots report to the experimenter (``Command.events``): immutable values,
read by loop functions only, never by another robot.

A controller's events are its log, as a real robot's is read after a run: the loop
collects them each tick into ``Loop.reports`` as ``(robot, event)`` pairs, and loop
functions (metrics, recordings) learn from them what the robot did, never from its
attributes. Beacons appear in them by id only.
"""

from __future__ import annotations

from typing import Any, NamedTuple


class Declared(NamedTuple):
    """The robot declared the exploration complete (Theorem 1) at the vertex it stands
    on; ``map_edges`` is its map, as pairs of beacon ids."""

    map_edges: tuple[tuple[str, str], ...]


class VertexCalled(NamedTuple):
    """The robot called its strategy at the vertex it stands on: whether it had just
    arrived by an edge (else a launch, an idle wake-up or a walk back), what it decided
    (``"go"`` along ``angle_rad``, ``"idle"``, ``"done"`` or ``"cut off"``), the beacon's
    id after the call, what the beacon holds (its text, for reviewers), the robot's map
    then (pairs of beacon ids) and the incidence matrix the beacon and the robot hold
    after the call (an immutable :class:`~algorithms.exploration.incidence_matrix.
    IncidenceMatrix`; None for a strategy whose beacons hold none)."""

    arrived: bool
    action: str
    angle_rad: float | None
    beacon_id: str | None
    beacon_text: str
    map_edges: tuple[tuple[str, str], ...]
    matrix: Any = None


def vertex_called(arrived: bool, decision, beacon, map_edges) -> VertexCalled:
    """The report of a vertex call, in every world: whether the robot had just arrived by
    an edge, its strategy's ``decision`` (a :class:`~algorithms.exploration.base.
    Decision`), the ``beacon`` after the call (its id, its text and the matrix it holds,
    if any) and the robot's map then (``map_edges``, pairs of beacon ids)."""
    data = beacon.data
    return VertexCalled(arrived, decision.action, decision.angle, beacon.id, repr(data),
                        tuple(map_edges), getattr(data, "matrix", None))


class Stopped(NamedTuple):
    """The robot stopped for good (lost its line, no beacon, an entry denied ...)."""

    reason: str


class SpeedChanged(NamedTuple):
    """On a lane, its speed changed from ``old_m_s`` to ``new_m_s`` (m/s)."""

    old_m_s: float
    new_m_s: float


class SpeedRuleFired(NamedTuple):
    """Its collision rule acted (eq. (27)) ``count`` times this tick: the papers'
    "speed changes"."""

    count: int


class RelayTrip(NamedTuple):
    """It set out on a relay mission (rule 6 of :mod:`algorithms.exploration.relay`)."""


class Infeasible(NamedTuple):
    """Its tether judged the exploration infeasible (rule 5 of
    :mod:`algorithms.exploration.tether`); it stands for good."""
