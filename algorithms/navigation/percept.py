"""What one robot senses in one control tick, already in its own calibrated units."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

#: A line sensor sees a strip when its reading is this much (m) below the bare-floor
#: reading: half the 2 mm strip thickness.
LINE_THRESHOLD_M = 0.001


@dataclass(frozen=True)
class Percept:
    """One control tick of a robot's own sensor readings.

    Attributes:
        line: line sensors (left, centre, right): True where a floor strip is underneath.
        ir: IR distances (left, front, right) in metres, ``math.nan`` for "nothing".
        encoders: wheel angles (left, right) in radians.
    """

    line: tuple[bool, bool, bool]
    ir: tuple[float, float, float]
    encoders: tuple[float, float]

    @property
    def any_line(self) -> bool:
        return any(self.line)


def percept(line_m: Sequence[float], ir_m: Sequence[float], encoder_rad: Sequence[float],
            line_floor_m: float) -> Percept:
    """A robot's raw readings (m, m, rad) as a :class:`Percept`: a line sensor sees a
    strip when it reads at least ``LINE_THRESHOLD_M`` less than over the bare floor
    (``line_floor_m``); a NaN reading (nothing within range) compares false: no strip."""
    line = tuple(line_floor_m - d > LINE_THRESHOLD_M for d in line_m)
    return Percept(line, tuple(float(d) for d in ir_m), tuple(float(e) for e in encoder_rad))
