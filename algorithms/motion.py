"""Velocity tracking and go-to-point for a differential-drive (unicycle) robot.

Pure functions: pose in, ``(v, omega)`` out. They turn the planar velocity commands of the
connectivity papers (seed 001's ``u_i``, seed 002's "drive towards") into what a
differential-drive robot can do: turn towards the commanded direction and drive forward
at the commanded speed scaled by ``cos`` of the heading error (never backwards), within
its speed and turn-rate limits.
"""

from __future__ import annotations

import math


def track_velocity(yaw: float, velocity: tuple[float, float], v_max: float,
                   omega_max: float, heading_gain: float = 3.0) -> tuple[float, float]:
    """``(v, omega)`` (m/s, rad/s) following the planar velocity ``velocity`` (m/s).

    ``omega = clip(heading_gain * e)``, ``v = clip(|u| cos e, 0, v_max)`` with ``e`` the
    angle from the heading ``yaw`` (rad) to ``velocity``.
    """
    speed = math.hypot(*velocity)
    if speed < 1e-9:
        return 0.0, 0.0
    error = math.remainder(math.atan2(velocity[1], velocity[0]) - yaw, 2.0 * math.pi)
    omega = max(-omega_max, min(omega_max, heading_gain * error))
    v = max(0.0, min(v_max, speed * math.cos(error)))
    return v, omega


def go_to(position: tuple[float, float], yaw: float, target: tuple[float, float],
          v_max: float, omega_max: float, gain: float = 1.0,
          tolerance_m: float = 0.02) -> tuple[float, float]:
    """``(v, omega)`` driving to ``target`` (m): a proportional velocity ``gain (target -
    position)`` capped at ``v_max``; zero within ``tolerance_m``."""
    dx, dy = target[0] - position[0], target[1] - position[1]
    distance = math.hypot(dx, dy)
    if distance < tolerance_m:
        return 0.0, 0.0
    speed = min(v_max, gain * distance)
    return track_velocity(yaw, (dx / distance * speed, dy / distance * speed), v_max, omega_max)
