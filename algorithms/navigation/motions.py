"""Motion primitives: small closed-loop behaviours a navigator chains into plans.

Each primitive's :meth:`step` takes the robot's odometry and this tick's percept and
returns a ``(v, omega)`` command (m/s, rad/s), or ``None`` once it has finished (the
navigator then starts the next one in the same tick). Primitives read only the robot's
own sensors and odometry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from algorithms.navigation.odometry import Odometry
from algorithms.navigation.percept import Percept

#: Heading gain (1/s) and the slowest turn rate worth commanding (rad/s).
HEADING_GAIN = 3.0
MIN_TURN_RATE = 0.2
#: A turn is done within this heading error (rad, 0.6 degrees).
TURN_TOLERANCE = 0.01
#: Line-following curvature (1/m) per unit of strip position (+1: under the left sensor).
LINE_CURVATURE = 15.0
#: The line counts as ended after this many metres without any sensor on it.
LINE_END_GAP_M = 0.02


def wrap(angle: float) -> float:
    """Wrap to (-pi, pi]."""
    return math.atan2(math.sin(angle), math.cos(angle))


def hold_heading(odo: Odometry, heading: float) -> float:
    """Turn-rate command (rad/s) steering ``odo`` back to ``heading``."""
    return HEADING_GAIN * wrap(heading - odo.theta)


@dataclass
class Turn:
    """Rotate in place to an absolute odometry heading (rad)."""

    heading: float
    max_rate: float = 1.0

    def step(self, odo: Odometry, percept: Percept):
        err = wrap(self.heading - odo.theta)
        if abs(err) < TURN_TOLERANCE:
            return None
        rate = min(self.max_rate, max(MIN_TURN_RATE, HEADING_GAIN * abs(err)))
        return 0.0, math.copysign(rate, err)


@dataclass
class Drive:
    """Drive ``distance_m`` straight ahead along ``heading`` (rad), by odometry."""

    distance_m: float
    heading: float
    speed: float
    _start: float | None = None

    def step(self, odo: Odometry, percept: Percept):
        if self._start is None:
            self._start = odo.distance_m
        left = self.distance_m - (odo.distance_m - self._start)
        if left <= 0.0:
            return None
        v = min(self.speed, max(0.02, 2.0 * left))
        return v, hold_heading(odo, self.heading)


@dataclass
class SeekLine:
    """Drive straight along ``heading`` until a line sensor sees a strip.

    ``failed`` is set if none is found within ``max_distance_m``.
    """

    heading: float
    speed: float
    max_distance_m: float
    failed: bool = False
    _start: float | None = None

    def step(self, odo: Odometry, percept: Percept):
        if self._start is None:
            self._start = odo.distance_m
        if percept.any_line:
            return None
        if odo.distance_m - self._start > self.max_distance_m:
            self.failed = True
            return None
        return self.speed, hold_heading(odo, self.heading)


@dataclass
class FollowLine:
    """Follow a strip with the three line sensors until it ends.

    The strip's position under the robot is read as +1 (left sensor alone), +0.5 (left
    with centre), 0 (centre alone), -0.5 (centre with right), -1 (right alone), and the
    robot steers towards it with curvature ``LINE_CURVATURE * position``. Strips are
    wider than the sensor spacing, so while the robot is near a strip some sensor sees
    it; when none does the follower keeps its last correction (the strip is beyond the
    outer sensor, or has ended). It has ended when no sensor has seen it over
    LINE_END_GAP_M; ``ended_at_m`` is then the odometry distance where it was last seen.
    ``headings`` keeps the odometry headings of the ticks where only the centre sensor
    was on (the robot aligned with the strip), so callers can estimate its direction.
    """

    speed: float
    headings: list[float] = field(default_factory=list)
    ended_at_m: float | None = None
    _position: float = 0.0

    def step(self, odo: Odometry, percept: Percept):
        left, centre, right = percept.line
        if left or centre or right:
            self.ended_at_m = None
            side = float(left) - float(right)
            self._position = side / 2.0 if centre else side
            if self._position == 0.0:
                self.headings.append(odo.theta)
        else:
            if self.ended_at_m is None:
                self.ended_at_m = odo.distance_m
            if odo.distance_m - self.ended_at_m > LINE_END_GAP_M:
                return None
        return self.speed, self.speed * LINE_CURVATURE * self._position

    def direction(self, fallback: float, last: int | None = 40) -> float:
        """Mean heading (rad) over the last ``last`` aligned ticks (all if None), or
        ``fallback`` when there were none."""
        recent = self.headings[-last:] if last else self.headings
        if not recent:
            return fallback
        return math.atan2(sum(math.sin(h) for h in recent), sum(math.cos(h) for h in recent))


@dataclass
class Scan:
    """Rotate in place (counter-clockwise) and find the strips around the robot.

    The centre line sensor sweeps a circle of radius ``line_ahead_m`` around the axle;
    each spoke it crosses gives an interval of headings with the sensor on the strip, and
    the spoke's direction is the interval's middle. A transition is placed half-way
    between the two ticks that saw it (removing the half-tick sampling bias).

    The scan keeps turning until the first spoke it measured comes round again, so the
    odometry angle between those two crossings, ``full_turn``, is exactly one true turn:
    the navigator uses it to calibrate the odometry's track (wheel sinkage and
    contact-patch scrub make odometry over-read rotation by a few per cent). Results, in
    odometry angles swept since the start: ``mids`` (one per spoke), ``full_turn`` (None
    if no spoke came round), ``swept``.
    """

    rate: float
    max_turns: float = 2.5
    mids: list[float] = field(default_factory=list)
    full_turn: float | None = None
    swept: float = 0.0
    start: float | None = None
    _last_theta: float = 0.0
    _on_since: float | None = None
    _was_on: bool | None = None

    def step(self, odo: Odometry, percept: Percept):
        if self.start is None:
            self.start = self._last_theta = odo.theta
        previous = self.swept
        self.swept += wrap(odo.theta - self._last_theta)
        self._last_theta = odo.theta
        on = percept.line[1]
        if self._was_on is not None and on != self._was_on:
            at = (previous + self.swept) / 2.0
            if on:
                self._on_since = at
            elif self._on_since is not None:
                self.mids.append((self._on_since + at) / 2.0)
                self._on_since = None
        self._was_on = on
        if len(self.mids) > 1 and _same_spoke(self.mids[-1] - self.mids[0]):
            self.full_turn = self.mids.pop() - self.mids[0]
            return None
        if self.swept >= 2.0 * math.pi * self.max_turns:
            return None
        return 0.0, self.rate


def _same_spoke(swept_between: float) -> bool:
    """Two crossings ``swept_between`` (rad, odometry) apart are one spoke seen twice.

    Odometry errs by a few per cent per turn, far less than the 45 degrees between spokes.
    """
    return abs(swept_between - 2.0 * math.pi) < math.radians(20.0)
