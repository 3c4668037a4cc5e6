"""What one robot senses in one control tick, already in its own calibrated units.

Line detection filters the raw line readings (:class:`LineFilter`), as a real line
follower must: its reflectance (here range) sensors are noisy, and one reading against
one threshold flickers. The robot calibrates itself as it drives, from its own readings
only: the level its sensors read over the bare floor, and their noise.
"""

from __future__ import annotations

import bisect
import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass

#: A line sensor sees a strip when its reading is this much (m) below the bare-floor
#: reading: half the 2 mm strip thickness (``mjswarm.core.world.FloorStrip``), the
#: threshold that leaves equal margins to the floor and to the strip.
LINE_THRESHOLD_M = 0.001
#: The filtered decision keeps this many noise standard deviations between the mean of
#: the window and the threshold (a Gaussian tail of 3e-7 per reading: at 3 sensors and
#: 50 Hz, one wrong flip per robot in about six hours of driving).
LINE_SIGMAS = 5.0
#: The longest window (control ticks, odd): 9 readings (0.18 s at 50 Hz) keep
#: ``LINE_SIGMAS`` for a noise of ``LINE_THRESHOLD_M * 3 / LINE_SIGMAS`` = 0.6 mm, above
#: the 0.5 mm the noise grid asks for. Also the window while the noise is not yet known.
LINE_WINDOW_MAX = 9
#: How many consecutive-reading differences (pooled over the three sensors) estimate the
#: noise: three seconds at 50 Hz (the median of 450 errs by about 5 per cent); and how
#: many the estimate needs before it is used.
NOISE_SAMPLES = 450
NOISE_MIN_SAMPLES = 30
#: How far (a fraction) the noise estimate must fall below the largest noise a shorter
#: window holds before the filter takes that window (ours): two standard errors of the
#: median of ``NOISE_SAMPLES`` differences (about 5 per cent each). A noise near a
#: window's limit (0.53 mm for 7 readings) otherwise moves its estimate across the limit
#: tick after tick, and a window that changes between two ticks changes its mean and its
#: lag at once: a robot leaving a vertex at 0.1 m/s with 0.5 mm of line noise saw its
#: centre sensor turn on and off again as the window went 7, 9, 7, 9, and took its new
#: lane for ended (``random-planar:8:1``, 4 robots, every noise, kinematic, seed 0).
WINDOW_HYSTERESIS = 0.1
#: Rate (per reading) of the floor level's exponential average: a time constant of 50
#: readings, a third of a second of the three sensors at 50 Hz. The floor level moves
#: with the robot's sinkage and pitch (0.4-0.5 mm in the dynamic tier), not tick by tick.
FLOOR_RATE = 1.0 / 50.0
#: The median of ``|a - b|`` for two independent ``N(0, sigma^2)`` readings, in sigmas.
_MEDIAN_ABS_DIFF = 0.6744897501960817 * math.sqrt(2.0)


class RunningMedian:
    """The median of the last ``size`` values (m), kept sorted as they come and go: a
    control tick costs a binary search and a short memory move, not a sort of them all
    (the noise estimates below ask every tick). The same number as
    :func:`statistics.median` of the values."""

    def __init__(self, size: int) -> None:
        self._recent: deque[float] = deque(maxlen=size)
        self._sorted: list[float] = []

    def __len__(self) -> int:
        return len(self._recent)

    def append(self, value: float) -> None:
        if len(self._recent) == self._recent.maxlen:
            del self._sorted[bisect.bisect_left(self._sorted, self._recent[0])]
        self._recent.append(value)
        bisect.insort(self._sorted, value)

    def median(self) -> float:
        values, n = self._sorted, len(self._sorted)
        return values[n // 2] if n % 2 else (values[n // 2 - 1] + values[n // 2]) / 2


def noise_estimate(diffs: RunningMedian, least: int) -> float | None:
    """A noise standard deviation (m) from the median of ``|reading - previous
    reading|`` of a sensor; None while fewer than ``least`` differences are in."""
    return None if len(diffs) < least else diffs.median() / _MEDIAN_ABS_DIFF


@dataclass(frozen=True)
class Percept:
    """One control tick of a robot's own sensor readings.

    Attributes:
        line: line sensors (left, centre, right): True where a floor strip is underneath,
            as filtered by :class:`LineFilter`.
        ir: IR distances (left, front, right) in metres, ``math.nan`` for "nothing".
        encoders: wheel angles (left, right) in radians.
        lag_ticks: how many control ticks ``line`` lags the robot's motion: the filter's
            decision now is about the readings centred that many ticks ago, so a motion
            that places a strip's edge takes the odometry of then
            (:meth:`~.odometry.Odometry.distance_back`).
    """

    line: tuple[bool, bool, bool]
    ir: tuple[float, float, float]
    encoders: tuple[float, float]
    lag_ticks: int = 0

    @property
    def any_line(self) -> bool:
        return any(self.line)


def window_for(sigma_m: float) -> int:
    """The smallest odd window (readings) whose mean keeps ``LINE_SIGMAS`` standard
    deviations of a noise ``sigma_m`` (m) within ``LINE_THRESHOLD_M``, at most
    ``LINE_WINDOW_MAX``."""
    needed = (LINE_SIGMAS * sigma_m / LINE_THRESHOLD_M) ** 2
    return min(LINE_WINDOW_MAX, 2 * math.ceil((needed - 1.0) / 2.0) + 1)


class LineFilter:
    """Strip detection from noisy line readings, one robot's three sensors.

    Each sensor sees a strip when the mean of its last ``n`` readings is more than
    ``LINE_THRESHOLD_M`` below the floor level; ``n`` is the smallest odd window that
    keeps ``LINE_SIGMAS`` noise deviations of that mean within the threshold (1 with
    noise-free sensors: the filter is then the single threshold, and runs keep their
    results), at most ``LINE_WINDOW_MAX``: a longer window as soon as the noise estimate
    asks for it, a shorter one only once the estimate is ``WINDOW_HYSTERESIS`` below that
    window's limit (ours: an estimate hovering at a limit would switch windows tick by
    tick). The mean of a centred window lags by
    ``(n - 1) / 2`` ticks, reported as :attr:`Percept.lag_ticks`.

    Self-calibration, from the robot's own readings:

    * the noise ``sigma`` from the median of ``|reading - previous reading|`` over the
      last ``NOISE_SAMPLES`` (the median ignores the few differences where a sensor
      crossed a strip's edge); ``LINE_WINDOW_MAX`` until ``NOISE_MIN_SAMPLES`` are in;
    * the floor level (starting from the calibration's ``line_floor_m``) by an
      exponential average at ``FLOOR_RATE`` of the windows that read floor: in the
      dynamic tier the body sinks 0.46 mm into the floor, which left only 0.54 mm
      between the floor and a fixed threshold, where 0.25 mm of noise stops robots
      within seconds.

    A NaN reading (nothing within range) counts as the floor level.
    """

    def __init__(self, line_floor_m: float) -> None:
        self.floor_m = line_floor_m
        self.window = LINE_WINDOW_MAX
        self._readings = tuple(deque(maxlen=LINE_WINDOW_MAX) for _ in range(3))
        self._diffs = RunningMedian(NOISE_SAMPLES)
        self._on = [False, False, False]

    @property
    def noise_m(self) -> float | None:
        """The estimated noise standard deviation (m), None while too few readings."""
        return noise_estimate(self._diffs, NOISE_MIN_SAMPLES)

    def __call__(self, line_m: Sequence[float]) -> tuple[tuple[bool, bool, bool], int]:
        """Take this tick's readings (m); return whether each sensor sees a strip and
        the lag (ticks) of that decision."""
        for readings, d in zip(self._readings, line_m):
            d = self.floor_m if math.isnan(d) else float(d)
            if readings:
                self._diffs.append(abs(d - readings[-1]))
            readings.append(d)
        sigma = self.noise_m
        if sigma is not None:  # a longer window at once, a shorter one with margin
            if (longer := window_for(sigma)) > self.window:
                self.window = longer
            else:
                self.window = min(self.window, window_for(sigma * (1.0 + WINDOW_HYSTERESIS)))
        n = min(self.window, len(self._readings[0]))
        for i, readings in enumerate(self._readings):
            mean = readings[-1] if n == 1 else math.fsum(list(readings)[-n:]) / n
            self._on[i] = self.floor_m - mean > LINE_THRESHOLD_M
            if not self._on[i] and abs(mean - self.floor_m) < LINE_THRESHOLD_M / 2.0:
                self.floor_m += FLOOR_RATE * (mean - self.floor_m)
        return (self._on[0], self._on[1], self._on[2]), (n - 1) // 2


#: How far (m) the left IR's wall readings stray from the nominal wall distance while a
#: robot follows its lane (the follower's swings and the corridor's ends: 0.018-0.031 m
#: around 0.024 m measured noise-free at 0.2 m/s, dynamic tier): what is left of the
#: navigator's wall tolerance beyond it is the margin a noisy reading must cross to miss
#: the wall.
WALL_SPREAD_M = 0.007
#: A wall that is there is missed for ``confirm_ticks`` readings in a row with at most this
#: probability: 3e-7, the line filter's rate (:data:`LINE_SIGMAS`, a Gaussian 5-sigma tail).
WALL_MISS_RATE = 3e-7
#: The longest confirmation (control ticks): also the one used while the noise is unknown.
WALL_CONFIRM_MAX = 5
#: Consecutive wall readings the IR noise estimate needs: fewer than a robot takes over
#: the navigator's ``min_wall_run_m`` (5 cm) at the 0.2 m/s top speed (12 at 50 Hz), so
#: the estimate is in before the first wall can end (the median of 10 errs by a third).
WALL_NOISE_MIN_SAMPLES = 10


class WallWatch:
    """Vertex detection by the left IR sensor, debounced: is the corridor wall beside?

    A reading sees the wall when it is within ``tolerance_m`` of ``wall_distance_m`` (NaN,
    nothing in range, never does). One reading out of tolerance is no vertex under IR
    noise: readings stray up to ``WALL_SPREAD_M`` from the wall distance in motion, which
    leaves a margin ``m = tolerance_m - WALL_SPREAD_M`` (5 mm for the 12 mm tolerance); at
    2 mm of noise one reading misses the wall with probability ``p = Phi(-m / sigma)``
    (0.6 %), several times per edge at 50 Hz. So the wall counts as gone only after
    ``confirm_ticks`` misses in a row, the smallest ``k`` with ``p^k <= WALL_MISS_RATE``
    (1 without noise, so noise-free runs keep their results; 3 at 2 mm), at most
    ``WALL_CONFIRM_MAX``; a shorter gap does not interrupt the wall. The detection comes
    ``k - 1`` ticks late (8 mm at 0.2 m/s and 50 Hz for k = 3; walls are at least 8 cm).

    The noise ``sigma`` is the robot's own estimate, as :class:`LineFilter`'s: the median of
    ``|reading - previous reading|`` over consecutive wall readings, the last
    ``NOISE_SAMPLES`` (``WALL_CONFIRM_MAX`` while fewer than ``WALL_NOISE_MIN_SAMPLES``).
    """

    def __init__(self, wall_distance_m: float, tolerance_m: float) -> None:
        self.wall_distance_m, self.tolerance_m = wall_distance_m, tolerance_m
        self._diffs = RunningMedian(NOISE_SAMPLES)
        self._last_wall: float | None = None  # the previous reading, if it saw the wall
        self._missed = WALL_CONFIRM_MAX  # readings in a row without the wall

    @property
    def noise_m(self) -> float | None:
        """The estimated noise standard deviation (m), None while too few readings."""
        return noise_estimate(self._diffs, WALL_NOISE_MIN_SAMPLES)

    @property
    def confirm_ticks(self) -> int:
        """How many readings in a row must miss the wall for it to be gone."""
        sigma = self.noise_m
        if sigma is None:
            return WALL_CONFIRM_MAX
        margin = self.tolerance_m - WALL_SPREAD_M
        p = 0.5 * math.erfc(margin / sigma / math.sqrt(2.0)) if sigma > 0.0 else 0.0
        if p <= WALL_MISS_RATE:
            return 1
        return min(WALL_CONFIRM_MAX, math.ceil(math.log(WALL_MISS_RATE) / math.log(p)))

    def __call__(self, left_ir_m: float) -> bool:
        """Take this tick's left IR reading (m, NaN for nothing); return whether the wall
        is beside the robot (seen now, or missed for fewer than ``confirm_ticks``)."""
        wall = abs(left_ir_m - self.wall_distance_m) <= self.tolerance_m
        if wall:
            if self._last_wall is not None:
                self._diffs.append(abs(left_ir_m - self._last_wall))
            self._last_wall, self._missed = left_ir_m, 0
            return True
        self._last_wall = None
        self._missed += 1
        return self._missed < self.confirm_ticks


def percept(line_m: Sequence[float], ir_m: Sequence[float], encoder_rad: Sequence[float],
            line_filter: LineFilter) -> Percept:
    """A robot's raw readings (m, m, rad) as a :class:`Percept`, its line readings
    through its ``line_filter``."""
    line, lag = line_filter(line_m)
    return Percept(line, tuple(float(d) for d in ir_m), tuple(float(e) for e in encoder_rad),
                   lag)
