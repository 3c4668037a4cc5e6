"""What one robot senses in one control tick, already in its own calibrated units."""

from __future__ import annotations

from dataclasses import dataclass


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
