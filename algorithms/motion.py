"""Velocity tracking for a differential-drive (unicycle) robot.

A pure function: pose in, ``(v, omega)`` out. It turns the planar velocity commands of the
connectivity papers (Kobayashi et al.'s ``u_i``, Ahmadi & Stone's "drive towards") into what a
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
