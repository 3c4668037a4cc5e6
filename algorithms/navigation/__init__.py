"""Sensor-only navigation on line-marked arenas (Nagavarapu et al., Sec. 5).

Pure Python: the embodied adapter (:mod:`mjswarm.experiments.exploration`) feeds each robot's own
readings (line sensors, IR, wheel encoders) in, and applies the ``(v, omega)`` that comes
out. Nothing here knows the arena graph or any ground truth.
"""

from algorithms.navigation.navigator import (
    ArenaConventions,
    NavEvent,
    Navigator,
    NavigatorEvent,
    NavigatorState,
)
from algorithms.navigation.odometry import Odometry, RobotCalibration
from algorithms.navigation.percept import Percept

__all__ = [
    "ArenaConventions",
    "NavEvent",
    "Navigator",
    "NavigatorEvent",
    "NavigatorState",
    "Odometry",
    "Percept",
    "RobotCalibration",
]
