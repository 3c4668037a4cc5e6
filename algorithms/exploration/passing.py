"""Passing a body that stands on a lane for good (ours: not in the paper): the protocol,
both sides.

A robot whose lane is blocked by a body that does not move and is silent (a teammate
switched off, for instance) asks the stations to pass it on the opposite lane, which
leads from the vertex ahead ``w`` back to the vertex it left ``u``:

1. The robot watches its front IR while it stands on its lane (:class:`BodyWatch`): a
   reading held within ``PASS_STEADY_M`` for ``PASS_AFTER_S``, with no radio
   neighbour's ranging within 30 degrees of its nose nearer than the body's far side,
   is a body. It sends :class:`PassRequest` to the stations.
2. The station of ``w`` lets nobody leave along the opposite lane from then on (``w``
   to ``u`` requests wait: :meth:`PassLanes.holds`), and answers :class:`PassGranted`
   once no robot is on its way along it (granted ``u`` from ``w`` and not yet on ``u``'s
   centre).
3. The robot passes (:meth:`~algorithms.navigation.Navigator.pass_body`) and, off the
   opposite lane, sends :class:`PassDone`: the station opens the lane again. A robot
   granted a pass where it no longer stands on its lane (it stopped for good meanwhile)
   answers :class:`PassDone` at once.

The pass is held like a vertex area: one robot per lane, so nothing comes towards it.
The robot cannot tell a dead robot from any other body; it needs not to: vertex entry
(:mod:`algorithms.exploration.entry`) leaves nobody else on its lane, so a live robot
never stands on it (a speed-rule stop is its own, a queue waits on vertex centres); the
one live exception, a relay of connected exploration, beats on its radio, and tethered
robots do not pass (a walk back and a pass would share the opposite lane).

Robot side, as a state machine (:class:`Pass`)::

    WATCHING --body steady PASS_AFTER_S, silent--> ASKED          (sends PassRequest)
    ASKED    --PassGranted, still on its lane-----> PASSING       (Navigator.pass_body)
    ASKED    --PassGranted, no longer on its lane-> WATCHING      (sends PassDone)
    PASSING  --navigator: PASSED-----------------> WATCHING      (sends PassDone)
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from enum import Enum
from typing import NamedTuple

#: A body: the front IR's reading held within ``PASS_STEADY_M`` (m: five times the 2 mm
#: of the noisiest IR the noise grid runs) for ``PASS_AFTER_S`` (s) while the robot
#: stood on its lane: twice the creep's wait (:data:`~algorithms.exploration.explorer.
#: CREEP_AFTER_S`), so that a phantom stop has been crept out of first.
PASS_AFTER_S = 10.0
PASS_STEADY_M = 0.01
#: Radio neighbours ranged within this angle of the nose (rad) and nearer than the
#: body's far side speak for the body: it is no body to pass.
SILENT_CONE_RAD = math.radians(30.0)


class PassRequest(NamedTuple):
    """Robot → station: a body blocks my lane; hold the opposite lane for me to pass."""


class PassGranted(NamedTuple):
    """Station → robot: the opposite lane is empty and held for you: pass."""


class PassDone(NamedTuple):
    """Robot → station: I am off the opposite lane; open it again."""


class Pass(Enum):
    """The robot's side of the protocol (module docstring's diagram)."""

    WATCHING = "watching"
    ASKED = "asked to pass"
    PASSING = "passing a body"


class BodyWatch:
    """One robot's side: whether a body stands on its lane for good, and its pass.

    Args:
        body_radius_m: the robot's own radius (m): a body of its kind ends
            ``4 body_radius_m`` beyond the front IR's reading (its far side, with room).
    """

    def __init__(self, body_radius_m: float) -> None:
        self.body_radius_m = body_radius_m
        self.state = Pass.WATCHING
        #: the body its front IR holds steady: since when (s) and its reading (m)
        self._body: tuple[float, float] | None = None

    def watch(self, now_s: float, front_m: float, standing: bool,
              detections: Mapping) -> PassRequest | None:
        """One tick on its lane (``standing``: on its lane and held still; ``front_m``:
        the front IR's reading, m, NaN for nothing; ``detections``: its radio
        neighbours' ranges and bearings). A :class:`PassRequest` once it sees a body."""
        if self.state is not Pass.WATCHING:
            return None
        if not standing or math.isnan(front_m):
            self._body = None
            return None
        if self._body is None or abs(front_m - self._body[1]) > PASS_STEADY_M:
            self._body = (now_s, front_m)
            return None
        far_m = front_m + 4.0 * self.body_radius_m
        if now_s - self._body[0] >= PASS_AFTER_S and not any(
                d.range_m < far_m and abs(d.bearing_rad) < SILENT_CONE_RAD
                for d in detections.values()):  # no radio answers from there
            self.state, self._body = Pass.ASKED, (self._body[0], front_m)
            return PassRequest()
        return None

    def granted(self, on_lane: bool, pass_body: Callable[[float], None]) -> PassDone | None:
        """:class:`PassGranted` came: pass (``pass_body(ahead_m)``) if it still stands on
        its lane, else free the lane at once (:class:`PassDone`)."""
        if on_lane and self._body is not None:
            self.state = Pass.PASSING
            pass_body(self._body[1])
            return None
        self.state = Pass.WATCHING
        return PassDone()

    def passed(self) -> PassDone:
        """Its navigator is past the body, off the opposite lane: the lane is free."""
        self.state, self._body = Pass.WATCHING, None
        return PassDone()


class PassLanes:
    """The stations' side: lanes held for a pass. ``lanes``: robot -> ``(from, to)``, the
    opposite lane's ends in its direction of travel (from the vertex ahead of the passing
    robot back to the vertex it left); nobody is granted ``to`` from ``from`` meanwhile.
    ``waiting``: robots that asked and have not yet been told to pass."""

    def __init__(self) -> None:
        self.lanes: dict[int, tuple[str | None, str | None]] = {}
        self.waiting: set[int] = set()

    def request(self, robot: int, ahead: str | None, behind: str | None) -> None:
        """``robot`` asked to pass: hold the lane from ``ahead`` back to ``behind``."""
        self.lanes[robot] = (ahead, behind)
        self.waiting.add(robot)

    def done(self, robot: int) -> None:
        """``robot`` is off the opposite lane (or stopped for good): open it again."""
        self.lanes.pop(robot, None)
        self.waiting.discard(robot)

    def holds(self, at: str | None, to: str) -> bool:
        """Whether the lane from ``at`` to ``to`` is held for a pass."""
        return (at, to) in self.lanes.values()

    def ready(self, on_the_way: Callable[[str | None, str | None], bool]) -> list[int]:
        """The waiting robots whose lane nobody is on any more (``on_the_way(from, to)``:
        whether some robot travels that lane), in robot order; they stop waiting."""
        ready = [i for i in sorted(self.waiting) if not on_the_way(*self.lanes[i])]
        self.waiting.difference_update(ready)
        return ready
