"""Motion primitives: small closed-loop behaviours a navigator chains into plans.

Each primitive's :meth:`step` takes the robot's odometry and this tick's percept and
returns a ``(v, omega)`` command (m/s, rad/s), or ``None`` once it has finished (the
navigator then starts the next one in the same tick). Primitives read only the robot's
own sensors and odometry.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from algorithms.navigation.odometry import Odometry
from algorithms.navigation.percept import LINE_WINDOW_MAX, Percept

#: Heading gain (1/s) and the slowest turn rate worth commanding (rad/s).
HEADING_GAIN = 3.0
MIN_TURN_RATE = 0.2
#: A turn is done within this heading error (rad, 0.6 degrees).
TURN_TOLERANCE = 0.01
#: Drive slows down to ``DRIVE_GAIN * distance left`` (1/s), but not below DRIVE_MIN_SPEED
#: (m/s): the wheels' speed ramp (the motor filter of ``models/spark_v.xml``, 0.05 s) then
#: coasts the robot at most half a millimetre past its goal.
DRIVE_GAIN = 2.0
DRIVE_MIN_SPEED = 0.005
#: Line-following curvature (1/m) per unit of strip position (+1: under the left sensor).
LINE_CURVATURE = 15.0
#: A strip lost sideways counts as ended after this many metres without any sensor on it.
LINE_END_GAP_M = 0.02
#: A strip's longitudinal end (see FollowLine) must hold for this many control ticks, so
#: that one noisy reading does not end it.
END_CONFIRM_TICKS = 2
#: The scan's first spoke has come round when the odometry has read between
#: ``1 - FULL_TURN_UNDER`` and ``1 + FULL_TURN_OVER`` turns since (see :func:`_same_spoke`).
FULL_TURN_UNDER = 0.015
FULL_TURN_OVER = 0.095
#: FollowLine keeps a heading for its lane's direction at most once per this travel (m):
#: half a control tick's travel at the paper's 0.05 m/s (1 mm at 50 Hz), so a moving robot
#: keeps one per tick and a standing one none.
HEADING_SAMPLE_M = 0.0005
#: FollowSpoke holds its heading once the centre sensor alone has seen the spoke this far (m).
SPOKE_ALIGN_M = 0.015


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
        v = min(self.speed, max(DRIVE_MIN_SPEED, DRIVE_GAIN * left))
        return v, hold_heading(odo, self.heading)


@dataclass
class SeekLine:
    """Drive straight along ``heading`` until a line sensor sees a strip.

    ``failed`` is set if none is found within ``max_distance_m``. ``ours`` (optional)
    tells the strip sought from another one: it takes the odometry and the sensors that
    see a strip, and the seek ends only when it says True.
    """

    heading: float
    speed: float
    max_distance_m: float
    ours: Callable[[Odometry, tuple[bool, bool, bool]], bool] | None = None
    failed: bool = False
    _start: float | None = None

    def step(self, odo: Odometry, percept: Percept):
        if self._start is None:
            self._start = odo.distance_m
        if percept.any_line and (self.ours is None or self.ours(odo, percept.line)):
            return None
        if odo.distance_m - self._start > self.max_distance_m:
            self.failed = True
            return None
        return self.speed, hold_heading(odo, self.heading)


@dataclass
class CentreEnd:
    """Where the centre sensor left a strip lengthwise: the strip's end.

    Fed every tick while the end is watched; :meth:`update` returns the odometry
    distance (m) half-way between the last tick with the centre on and the first tick
    off, once the centre has stayed off for ``END_CONFIRM_TICKS`` ticks (one noisy
    reading does not end a strip), else None.

    A strip's end lies ahead: a tick off at an odometry distance short of where the
    centre was last on is the robot driven backwards off the strip's start (the leash's
    retrace, :meth:`~.navigator.Navigator.carried`), no end; the count starts again once
    the robot has come forward past that point with the centre still off.
    """

    _last_on_m: float = 0.0
    _off_ticks: int = 0
    _left_at_m: float = 0.0

    def update(self, centre: bool, distance_m: float) -> float | None:
        if centre:
            self._last_on_m, self._off_ticks = distance_m, 0
            return None
        if distance_m < self._last_on_m:  # backed off the strip's start: no end
            self._off_ticks = 0
            return None
        if self._off_ticks == 0:
            self._left_at_m = (self._last_on_m + distance_m) / 2.0
        self._off_ticks += 1
        return self._left_at_m if self._off_ticks >= END_CONFIRM_TICKS else None


@dataclass
class FollowLine:
    """Follow a strip with the three line sensors until it ends.

    The strip's position under the robot is read as +1 (left sensor alone), +0.5 (left
    with centre), 0 (centre alone), -0.5 (centre with right), -1 (right alone), and the
    robot steers towards it with curvature ``LINE_CURVATURE * position``. Strips are
    wider than the sensor spacing, so while the robot is near a strip some sensor sees
    it, and a robot drifting sideways off it passes through "centre with a side": the
    side sensor keeps holding the strip.

    The strip has **ended** in either of two ways; ``ended_at_m`` is then the odometry
    distance where the centre sensor (or, in the second way, any sensor) last saw it:

    * *longitudinally*: the centre sensor leaves it while no side sensor that saw it
      together with the centre still does, for ``END_CONFIRM_TICKS`` ticks in a row. A
      side sensor that turns on just then belongs to another strip: near a vertex centre
      the inner ends of the spokes of edges 45-90 degrees apart come within a side
      sensor's reach, and following that sensor would carry the robot out along a
      neighbouring spoke. Drifting sideways never looks like this (the side
      sensor holding the strip was on before the centre left it);
    * *laterally lost*: no sensor has seen it over LINE_END_GAP_M; meanwhile the follower
      keeps its last correction (the strip is beyond the outer sensor).

    ``headings`` keeps the odometry headings of the ticks where only the centre sensor
    was on (the robot aligned with the strip), at most one per ``HEADING_SAMPLE_M`` of
    travel, so callers can estimate its direction: a robot standing on its lane (the
    speed rule, vertex entry) would otherwise pull the estimate onto whatever heading
    its last swing left it at.
    """

    speed: float
    headings: list[float] = field(default_factory=list)
    ended_at_m: float | None = None
    _position: float = 0.0
    #: while the centre sensor tracks the strip: the side sensors on with it last tick
    _holding: tuple[bool, bool] | None = None
    _end: CentreEnd = field(default_factory=CentreEnd)
    _sampled_m: float = -math.inf  # the odometry distance of the last heading kept
    #: sums of the sines and cosines of all ``headings``, added in order as they are kept
    _sin_sum: float = 0.0
    _cos_sum: float = 0.0

    def step(self, odo: Odometry, percept: Percept):
        left, centre, right = percept.line
        seen_at_m = odo.distance_back(percept.lag_ticks)  # where the filter's readings were
        if centre:
            self._holding = (left, right)
            self._end.update(True, seen_at_m)
        elif self._holding is not None:
            if (left and self._holding[0]) or (right and self._holding[1]):
                self._holding = None  # drifted sideways: a side sensor holds the strip
            else:  # the centre left the strip lengthwise: its end, once confirmed
                end = self._end.update(False, seen_at_m)
                if end is not None:
                    self.ended_at_m = end
                    return None
                return self.speed, self.speed * LINE_CURVATURE * self._position
        if left or centre or right:
            self.ended_at_m = None
            side = float(left) - float(right)
            self._position = side / 2.0 if centre else side
            if self._position == 0.0 and odo.distance_m - self._sampled_m >= HEADING_SAMPLE_M:
                self.headings.append(odo.theta)
                self._sin_sum += math.sin(odo.theta)
                self._cos_sum += math.cos(odo.theta)
                self._sampled_m = odo.distance_m
        else:
            if self.ended_at_m is None:
                self.ended_at_m = seen_at_m
            if seen_at_m - self.ended_at_m > LINE_END_GAP_M:
                return None
        return self.speed, self.speed * LINE_CURVATURE * self._position

    def direction(self, fallback: float, last: int | None = 40) -> float:
        """Mean heading (rad) over the last ``last`` aligned ticks (all if None), or
        ``fallback`` when there were none. Over all of them it reads the running sums
        (the same additions in the same order as summing the list: asked every tick on a
        lane, by :meth:`~.navigator.Navigator.lane_bearings`)."""
        if not self.headings:
            return fallback
        if not last or last >= len(self.headings):
            return math.atan2(self._sin_sum, self._cos_sum)
        recent = self.headings[-last:]
        return math.atan2(sum(math.sin(h) for h in recent), sum(math.cos(h) for h in recent))


@dataclass
class FollowLineAlong:
    """Follow a strip with ``line`` (a :class:`FollowLine`) until the robot has come
    ``distance_m`` along ``heading`` (rad) from ``origin`` (x, y in m, odometry frame), or
    until the strip ends (``line.ended_at_m`` is then set)."""

    line: FollowLine
    heading: float
    origin: tuple[float, float]
    distance_m: float

    @property
    def reached(self) -> bool:
        """Whether it stopped because it came ``distance_m`` along ``heading``."""
        return self.line.ended_at_m is None

    def remaining_m(self, odo: Odometry) -> float:
        """How much of ``distance_m`` (m) is still to come along ``heading``."""
        return self.distance_m - self._along(odo)

    def step(self, odo: Odometry, percept: Percept):
        if self._along(odo) >= self.distance_m:
            return None
        return self.line.step(odo, percept)

    def _along(self, odo: Odometry) -> float:
        return ((odo.x - self.origin[0]) * math.cos(self.heading)
                + (odo.y - self.origin[1]) * math.sin(self.heading))


@dataclass
class FollowSpoke:
    """Follow a vertex spoke to its inner end, where the robot's centre sensor leaves it.

    Starts as :class:`FollowLine`; once the centre sensor alone has been on the strip
    for ``SPOKE_ALIGN_M`` (the robot is aligned with it), the robot holds the spoke's
    direction (the mean heading of those aligned ticks) and no longer steers by the side
    sensors: where edges are 45 degrees apart the inner ends of neighbouring spokes
    overlap, and a side sensor that reached one would steer the robot out along it
    (``fan:3:45``). The spoke's centre line beyond its inner end crosses no
    other spoke. It ends where the centre sensor leaves the strip (:class:`CentreEnd`);
    ``direction`` is the held heading.
    """

    speed: float
    ended_at_m: float | None = None
    _follow: FollowLine | None = None
    _aligned_since_m: float | None = None
    _heading: float | None = None
    _end: CentreEnd = field(default_factory=CentreEnd)

    def step(self, odo: Odometry, percept: Percept):
        left, centre, right = percept.line
        if self._heading is None:
            if self._follow is None:
                self._follow = FollowLine(self.speed)
            command = self._follow.step(odo, percept)
            if command is None:
                self.ended_at_m = self._follow.ended_at_m
                return None
            if centre and not (left or right):
                if self._aligned_since_m is None:
                    self._aligned_since_m = odo.distance_m
                if odo.distance_m - self._aligned_since_m >= SPOKE_ALIGN_M:
                    self._heading = self._follow.direction(odo.theta, last=None)
            else:
                self._aligned_since_m = None
            self._end.update(centre, odo.distance_back(percept.lag_ticks))
            return command
        end = self._end.update(centre, odo.distance_back(percept.lag_ticks))
        if end is not None:
            self.ended_at_m = end
            return None
        return self.speed, hold_heading(odo, self._heading)

    def direction(self, fallback: float) -> float:
        """The spoke's direction (rad, odometry frame): the held heading, else the
        follower's estimate, else ``fallback``."""
        if self._heading is not None:
            return self._heading
        return fallback if self._follow is None else self._follow.direction(fallback)


@dataclass
class Scan:
    """Rotate in place (counter-clockwise, or clockwise with ``direction=-1``) and find
    the strips around the robot.

    The centre line sensor sweeps a circle of radius ``line_ahead_m`` around the axle;
    each spoke it crosses gives a run of headings with the (filtered) sensor on the
    strip, and the spoke's direction is the run's centre. A run narrower than
    ``min_width`` (rad, odometry) is no spoke: the navigator asks for half of
    ``spoke_width``, the angle a strip spans at the sensor's radius. A transition is
    placed half-way between the two ticks that saw it (removing the half-tick sampling
    bias), ``Percept.lag_ticks`` back (the line filter's decision is about the readings
    centred then).

    A run may hold several spokes (:func:`spokes_in_run`): the gap between two
    neighbouring spokes narrows where the robot stands off the vertex centre away from
    them (45 degrees apart, 6 mm off: 5 degrees, 4 readings at 1 rad/s and 50 Hz), and
    the line filter's window (7 readings at 0.5 mm of noise) cannot open a gap that
    narrow (``wheel:4@8``, 4 robots, 0.05 m/s, line noise 0.5 mm, dynamic: taken as one,
    two spokes at ``r3`` merge into one between them, along neither of which the robot
    could set off).

    The scan keeps turning until the first spoke it measured comes round again, so the
    odometry angle between those two crossings, ``full_turn``, is exactly one true turn:
    the navigator uses it to calibrate the odometry's track (wheel sinkage and
    contact-patch scrub make odometry over-read rotation by a few per cent). Results, in
    odometry angles swept since the start (negative when turning clockwise): ``mids``
    (one per spoke), ``full_turn`` (always positive; None if no spoke came round),
    ``swept``.
    """

    rate: float
    direction: int = 1  # +1 counter-clockwise, -1 clockwise
    min_width: float = 0.0
    spoke_width: float = 0.0
    max_turns: float = 2.5
    mids: list[float] = field(default_factory=list)
    full_turn: float | None = None
    swept: float = 0.0
    start: float | None = None
    _last_theta: float = 0.0
    _on_since: float | None = None
    _was_on: bool | None = None
    #: ``swept`` after each tick, newest last (as far back as a filter's lag and one more)
    _swept: deque = field(default_factory=lambda: deque(maxlen=LINE_WINDOW_MAX + 1))

    def step(self, odo: Odometry, percept: Percept):
        if self.start is None:
            self.start = self._last_theta = odo.theta
            self._swept.append(0.0)
        self.swept += wrap(odo.theta - self._last_theta)
        self._last_theta = odo.theta
        self._swept.append(self.swept)
        on = percept.line[1]
        if self._was_on is not None and on != self._was_on:
            back = min(percept.lag_ticks, len(self._swept) - 2)
            at = (self._swept[-2 - back] + self._swept[-1 - back]) / 2.0
            if on:
                self._on_since = at
            elif self._on_since is not None:
                start, self._on_since = self._on_since, None
                if abs(at - start) >= self.min_width:
                    window = (2 * percept.lag_ticks + 1) * abs(self._swept[-1] - self._swept[-2])
                    for mid in spokes_in_run(start, at, self.spoke_width, window):
                        self.mids.append(mid)
                        if len(self.mids) > 1 and _same_spoke(abs(mid - self.mids[0])):
                            self.full_turn = abs(self.mids.pop() - self.mids[0])
                            return None
        self._was_on = on
        if abs(self.swept) >= 2.0 * math.pi * self.max_turns:
            return None
        return 0.0, self.direction * self.rate


def spokes_in_run(start: float, end: float, spoke_width: float, window: float) -> list[float]:
    """The spokes' directions (rad, odometry) in one run of the scan's centre sensor on
    strips, from ``start`` to ``end`` (either way round).

    Each spoke spans ``spoke_width`` (rad) at the sensor's radius (35 degrees for the 30 mm
    strips at 50 mm; standing 6 mm off the centre changes it by 0.3 degree), and a gap
    between two spokes stays shut only while no wider than the line filter's ``window``
    (rad: the angle its readings span, its window of readings times the angle turned per
    reading; 8 degrees for 7 readings at 1 rad/s and 50 Hz; a reading at 0 mm noise). So
    ``k`` spokes merged into one run span ``k spoke_width`` plus ``k - 1`` gaps of 0 to
    ``window``: ``k - 1`` is the run's excess over one span in units of ``spoke_width +
    window / 2`` (the middle of that range), rounded. The first and last spokes are
    ``spoke_width / 2`` inside the run's ends (exact whatever the gap), any between
    evenly spaced. One spoke (``k = 1``, every noise-free run) is the run's centre, as
    always; ``spoke_width = 0`` asks for that."""
    width = abs(end - start)
    k = 1 if spoke_width <= 0.0 else 1 + max(0, round((width - spoke_width)
                                                      / (spoke_width + window / 2.0)))
    if k == 1:
        return [(start + end) / 2.0]
    inset = math.copysign(spoke_width / 2.0, end - start)
    first, last = start + inset, end - inset
    return [first + (last - first) * j / (k - 1) for j in range(k)]


def _same_spoke(swept_between: float) -> bool:
    """Two crossings ``swept_between`` (rad, odometry) apart are one spoke seen twice: the
    odometry read between ``1 - FULL_TURN_UNDER`` and ``1 + FULL_TURN_OVER`` of a turn.

    Before its first calibration odometry over-reads a turn: the contact patches' scrub
    widens the effective track (1-2 per cent in the dynamic tier) and wheel slip makes
    the encoders read more than the wheels rolled (``|N(0, s)|`` per tick and wheel: 0.8 s
    on average, 4 per cent at ``--wheel-slip 0.05``); neither under-reads. Together they
    reach 384 degrees for one turn (dynamic tier, slip 0.05 and line noise 0.5 mm: the
    noise grid's "all noises" run, ``python -m mjswarm.experiments.stress --noise``),
    beyond a symmetric 22.5 degrees, where a robot would scan on uncalibrated and set
    off along the wrong spoke. The window is
    skewed to over-reading, as wide as edges 45 degrees apart allow: the neighbouring
    spokes come round at 405 and 315 degrees of a true turn, and a window from
    ``360 (1 - u)`` to ``360 (1 + o)`` excludes them for every over-read in it while
    ``(1 + o) < 1.125 (1 - u)``: 1.095 against 1.108.
    """
    turns = swept_between / (2.0 * math.pi)
    return 1.0 - FULL_TURN_UNDER <= turns <= 1.0 + FULL_TURN_OVER
