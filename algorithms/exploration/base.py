"""The one interface every exploration strategy implements: a per-robot mind.

A strategy never sees true vertex ids nor the graph. At each vertex arrival the world
calls :meth:`Strategy.on_vertex` with

* ``beacon``: a :class:`Beacon` handle for the vertex the robot stands on, readable and
  writable only during that call. The world owns one beacon per vertex (Nagavarapu et al. drops a
  beacon at the first visit; the experiments emulate it with a central station) and never
  looks inside ``beacon.data``; it only reads ``beacon.id`` to map the strategy's beacon
  names to arena vertices for metrics.
* ``angles``: the incidence angles of the edges at this vertex as the robot measured them,
  radians counter-clockwise from the common +x reference, in (0, 2*pi] (Nagavarapu et al. section 2:
  "the zero angle is represented by 2*pi"). Exact in the graph world; a few degrees off on
  embodied robots, so strategies match angles by nearest value within
  :data:`ANGLE_TOLERANCE` (edges at a vertex are at least 45 degrees apart).
* ``arrived_by``: the measured angle, at this vertex, of the edge the robot arrived by;
  ``None`` when it did not move since its previous call (the start, or after idling).

It answers with a :class:`Decision`: leave along the edge at ``angle``, ``DONE``
(completion declared), ``IDLE`` (nothing to do now; the world calls again one time unit
later with ``arrived_by=None``) or, only where vertices close (a body that cannot be passed), ``CUT_OFF``.

Robots that arrive at one vertex at the same time are handled one after another, each
seeing the beacon as the previous one left it, in *descending* robot index. Nagavarapu et al.'s
Fig. 9 run fixes that order: its 10th update is R1 reaching v6 at the 5th step, so R2's
update of each step comes first, and at v4 (both robots arrive at step 2) only R2-first
reproduces the printed vertex sequences.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

TWO_PI = 2.0 * math.pi

#: Largest mismatch (radians) between a measured angle and a stored one that still
#: names the same edge; half the 45 degree minimum angle between edges at a vertex.
ANGLE_TOLERANCE = math.radians(20.0)


class AngleMismatch(ValueError):
    """A measured angle matches no stored edge angle within the tolerance."""


@dataclass(frozen=True, slots=True)
class Decision:
    """What a robot does after a vertex visit: ``go`` along ``angle``, ``done``, ``idle``
    or ``cut off``."""

    action: str
    angle: float | None = None


DONE = Decision("done")
IDLE = Decision("idle")
#: Cut off from the root by closed vertices, with every end of its reach
#: completed or blocked: the robot finished the part of the graph it can still reach and
#: stops for good (it declares nothing: see ``incidence_matrix``'s rule).
CUT_OFF = Decision("cut off")


def go(angle: float) -> Decision:
    """Leave the vertex along the edge whose incidence angle is ``angle`` (radians)."""
    return Decision("go", angle)


class Beacon:
    """A vertex's beacon as the robot sees it during one call.

    ``id`` is ``None`` until the first visitor drops the beacon and names it (Nagavarapu et al.:
    robot R1 names its beacons a1, a2, ...; see :mod:`algorithms.exploration.beacon_ids`).
    ``data`` is whatever the strategy keeps there (for Nagavarapu et al., the incidence matrix).
    ``frame`` is what an embodied robot keeps there of the frame its stored angles are in
    (the frame fusion of :func:`~algorithms.navigation.navigator.fuse_frames`): ``(offset, variance)``, how far (rad) the robots
    believe those angles lie from the common frame and how sure (rad^2); ``None`` until
    the robot that dropped the beacon writes it (:mod:`~algorithms.exploration.explorer`).
    """

    __slots__ = ("data", "frame", "id")

    def __init__(self) -> None:
        self.id: str | None = None
        self.data: Any = None
        self.frame: tuple[float, float] | None = None


class ExpiredBeacon(RuntimeError):
    """A beacon handle was used after the tick it was handed out in."""


class _Expired:
    """What an expired :class:`BeaconHandle` holds instead of its beacon: any use raises."""

    __slots__ = ()

    def _raise(self, *_):
        raise ExpiredBeacon("a beacon handle is good only during the tick it was handed out "
                            "in; keep its id instead")

    __getattr__ = __setattr__ = _raise


_EXPIRED = _Expired()


class BeaconHandle:
    """What a world hands a robot of the beacon it stands on: reads and writes go to the
    vertex's :class:`Beacon` during the tick it was handed out in; afterwards (the world
    calls :meth:`expire` when it steps) any use raises :class:`ExpiredBeacon`. A robot
    that wants to remember a vertex keeps its ``id``, never the handle.

    A decision reads and writes its beacon a few times, in every world, so the accessors
    are one attribute hop: expiring swaps the beacon for an object that raises."""

    __slots__ = ("_beacon",)

    def __init__(self, beacon: Beacon) -> None:
        self._beacon = beacon

    @property
    def id(self) -> str | None:
        return self._beacon.id

    @id.setter
    def id(self, value: str | None) -> None:
        self._beacon.id = value

    @property
    def data(self) -> Any:
        return self._beacon.data

    @data.setter
    def data(self, value: Any) -> None:
        self._beacon.data = value

    @property
    def frame(self) -> tuple[float, float] | None:
        return self._beacon.frame

    @frame.setter
    def frame(self, value: tuple[float, float] | None) -> None:
        self._beacon.frame = value

    def expire(self) -> None:
        """The tick is over: the handle no longer reaches the beacon."""
        self._beacon = _EXPIRED


class Strategy(ABC):
    """A per-robot exploration mind; one instance per robot.

    ``index`` is the robot's 0-based index (R1 is index 0), ``n_robots`` the team size K,
    ``rng`` a seeded generator for tie-breaking, or ``None`` for the canonical,
    fully deterministic tie rules each strategy documents.
    """

    #: CLI name of the strategy.
    name: ClassVar[str]
    #: After a call of :meth:`on_vertex`: the incidence angles (rad) the vertex's beacon
    #: stored before this visit, the common frame an embodied robot re-anchors its
    #: heading to; None when the robot has just dropped the beacon (its own angles).
    stored_angles: tuple[float, ...] | None = None
    #: Whether :meth:`give_up` can plan round a busy edge.
    replans: ClassVar[bool] = False

    def __init__(self, index: int, n_robots: int, rng: np.random.Generator | None = None):
        if n_robots < 1 or not 0 <= index < n_robots:
            raise ValueError(f"robot index {index} out of range for {n_robots} robots")
        self.index = index
        self.n_robots = n_robots
        self.rng = rng

    def arrive(self, beacon: Beacon, angles: Sequence[float], arrived_by: float | None) -> None:
        """Bookkeeping of an arrival that must reach the beacon before any robot arriving
        at the same time decides (Brass et al.'s model for MR-DFS). The graph world calls
        it for every robot of a simultaneous batch, then :meth:`on_vertex` for each; a
        strategy that keeps its bookkeeping and decision together leaves it empty
        (Nagavarapu et al.'s robots handle simultaneous arrivals one after another, see
        the module docstring)."""

    @abstractmethod
    def on_vertex(
        self, beacon: Beacon, angles: Sequence[float], arrived_by: float | None
    ) -> Decision:
        """Handle an arrival (or a wake-up after idling) and decide what to do next."""

    def block(self, angle: float) -> None:
        """The edge at incidence ``angle`` (rad, the beacons' frame) from the vertex of
        the latest call leads to a closed vertex (its station answered
        :class:`~algorithms.exploration.entry.EntryBlocked`): the robot did not
        leave. The world then calls :meth:`on_vertex` again at that vertex with
        ``arrived_by`` None, and that call writes the mark into the beacon and decides
        anew. Only ``incidence-dfs`` routes round closed vertices
        (:mod:`~algorithms.exploration.incidence_dfs`); every other strategy refuses here."""
        raise NotImplementedError(f"strategy {self.name} cannot explore round a closed vertex")

    def give_up(self, angle: float) -> None:
        """The robot gave up its place in a queue for the edge at incidence ``angle`` (rad,
        the beacons' frame) from the vertex of the latest call, and did not leave
        (:mod:`~algorithms.exploration.entry`, step 8). The world then calls
        :meth:`on_vertex` again at that vertex with ``arrived_by`` None, and that call plans
        without leaving by that edge. Only strategies with :attr:`replans` give up."""
        raise NotImplementedError(f"strategy {self.name} cannot plan round a busy edge")

    @abstractmethod
    def map_edges(self) -> list[tuple[str, str]]:
        """The robot's map: its known traversed edges as pairs of beacon ids."""


def normalize_angle(angle: float) -> float:
    """``angle`` (radians) mapped into (0, 2*pi], with 0 represented by 2*pi (Nagavarapu et al.)."""
    a = math.fmod(angle, TWO_PI)
    if a <= 0.0:
        a += TWO_PI
    return a


def angle_gap(a: float, b: float) -> float:
    """Smallest absolute difference between two angles (radians), in [0, pi]."""
    d = abs(a - b) % TWO_PI
    return min(d, TWO_PI - d)


def match_angle(angle: float, stored: Sequence[float], tolerance: float = ANGLE_TOLERANCE) -> float:
    """The stored angle nearest to a measured ``angle``; :class:`AngleMismatch` if none is
    within ``tolerance`` (radians)."""
    if angle in stored:
        return angle
    best = min(stored, key=lambda s: angle_gap(angle, s))
    if angle_gap(angle, best) > tolerance:
        raise AngleMismatch(
            f"measured angle {math.degrees(angle):.1f} deg matches no edge within "
            f"{math.degrees(tolerance):.0f} deg of {[round(math.degrees(s), 1) for s in stored]}"
        )
    return best


def ccw_from(reference: float, angles: Sequence[float]) -> list[float]:
    """``angles`` in counter-clockwise order starting just after ``reference``.

    An angle equal to the reference comes last (a full turn). This is the preference
    order of a robot's own new edges at a vertex (reference: the edge it arrived by; +x,
    i.e. 2*pi, at the root), which reproduces Nagavarapu et al.'s Fig. 9 run (DESIGN notes).
    """
    def turn(a: float) -> float:
        d = (a - reference) % TWO_PI
        return d if d > 1e-12 else TWO_PI

    return sorted(angles, key=turn)
