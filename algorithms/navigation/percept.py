"""What one robot senses in one control tick, already in its own calibrated units.

Line detection filters the raw line readings (:class:`LineFilter`), as a real line
follower must: its reflectance (here range) sensors are noisy, and one reading against
one threshold flickers. The robot calibrates itself as it drives, from its own readings
only: the level its sensors read over the bare floor, and their noise.
"""

from __future__ import annotations

import math
import statistics
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
#: Rate (per reading) of the floor level's exponential average: a time constant of 50
#: readings, a third of a second of the three sensors at 50 Hz. The floor level moves
#: with the robot's sinkage and pitch (0.4-0.5 mm in the dynamic tier), not tick by tick.
FLOOR_RATE = 1.0 / 50.0
#: The median of ``|a - b|`` for two independent ``N(0, sigma^2)`` readings, in sigmas.
_MEDIAN_ABS_DIFF = 0.6744897501960817 * math.sqrt(2.0)


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


class LineFilter:
    """Strip detection from noisy line readings, one robot's three sensors.

    Each sensor sees a strip when the mean of its last ``n`` readings is more than
    ``LINE_THRESHOLD_M`` below the floor level; ``n`` is the smallest odd window that
    keeps ``LINE_SIGMAS`` noise deviations of that mean within the threshold (1 with
    noise-free sensors: the filter is then the single threshold, and runs keep their
    results), at most ``LINE_WINDOW_MAX``. The mean of a centred window lags by
    ``(n - 1) / 2`` ticks, reported as :attr:`Percept.lag_ticks`.

    Self-calibration, from the robot's own readings:

    * the noise ``sigma`` from the median of ``|reading - previous reading|`` over the
      last ``NOISE_SAMPLES`` (the median ignores the few differences where a sensor
      crossed a strip's edge); ``LINE_WINDOW_MAX`` until ``NOISE_MIN_SAMPLES`` are in;
    * the floor level (starting from the calibration's ``line_floor_m``) by an
      exponential average at ``FLOOR_RATE`` of the windows that read floor: in the
      dynamic tier the body sinks 0.46 mm into the floor, which left only 0.54 mm
      between the floor and the fixed threshold (issue 27: 0.25 mm of noise stopped
      robots within seconds).

    A NaN reading (nothing within range) counts as the floor level.
    """

    def __init__(self, line_floor_m: float) -> None:
        self.floor_m = line_floor_m
        self.window = LINE_WINDOW_MAX
        self._readings = tuple(deque(maxlen=LINE_WINDOW_MAX) for _ in range(3))
        self._diffs: deque[float] = deque(maxlen=NOISE_SAMPLES)
        self._on = [False, False, False]

    @property
    def noise_m(self) -> float | None:
        """The estimated noise standard deviation (m), None while too few readings."""
        if len(self._diffs) < NOISE_MIN_SAMPLES:
            return None
        return statistics.median(self._diffs) / _MEDIAN_ABS_DIFF

    def __call__(self, line_m: Sequence[float]) -> tuple[tuple[bool, bool, bool], int]:
        """Take this tick's readings (m); return whether each sensor sees a strip and
        the lag (ticks) of that decision."""
        for readings, d in zip(self._readings, line_m):
            d = self.floor_m if math.isnan(d) else float(d)
            if readings:
                self._diffs.append(abs(d - readings[-1]))
            readings.append(d)
        sigma = self.noise_m
        if sigma is not None:
            needed = (LINE_SIGMAS * sigma / LINE_THRESHOLD_M) ** 2
            self.window = min(LINE_WINDOW_MAX, 2 * math.ceil((needed - 1.0) / 2.0) + 1)
        n = min(self.window, len(self._readings[0]))
        for i, readings in enumerate(self._readings):
            recent = list(readings)[-n:]
            mean = math.fsum(recent) / len(recent)
            self._on[i] = self.floor_m - mean > LINE_THRESHOLD_M
            if not self._on[i] and abs(mean - self.floor_m) < LINE_THRESHOLD_M / 2.0:
                self.floor_m += FLOOR_RATE * (mean - self.floor_m)
        return (self._on[0], self._on[1], self._on[2]), (n - 1) // 2


def percept(line_m: Sequence[float], ir_m: Sequence[float], encoder_rad: Sequence[float],
            line_filter: LineFilter) -> Percept:
    """A robot's raw readings (m, m, rad) as a :class:`Percept`, its line readings
    through its ``line_filter``."""
    line, lag = line_filter(line_m)
    return Percept(line, tuple(float(d) for d in ir_m), tuple(float(e) for e in encoder_rad),
                   lag)
