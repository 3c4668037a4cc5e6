"""Robot-robot collision events, counted from ``data.contact``.

Ground truth for metrics and tests only; controllers never see it. A collision *event*
is a pair of robots that starts touching: a pair that stays in contact over several
checks is one event, and it counts again only after it has separated.
"""

from __future__ import annotations

import re

import mujoco
import numpy as np


#: How a contact event reads in a recording's event log (``mjswarm plot`` parses it back).
CONTACT_EVENT = "contact {a}-{b} at ({x:.3f}, {y:.3f}) m"
CONTACT_PATTERN = re.compile(r"contact (R\d+)-(R\d+) at \((-?[\d.]+), (-?[\d.]+)\) m")


def contact_event(i: int, j: int, poses: np.ndarray) -> str:
    """The event text of a contact between robots ``i`` and ``j`` (0-based), placed at the
    midpoint of their positions (``poses``: (N, 3) in m)."""
    x, y = (poses[i, :2] + poses[j, :2]) / 2.0
    return CONTACT_EVENT.format(a=robot_name(i), b=robot_name(j), x=x, y=y)


def robot_name(i: int) -> str:
    """The name users see for 0-based robot index ``i``: R1, R2, ..."""
    return f"R{i + 1}"


class CollisionCounter:
    """Counts new touching robot pairs each time :meth:`record` is called.

    Args:
        geom_robot: for every geom of the model, the index of the robot it belongs
            to, or -1 (floor, strips, walls).
    """

    def __init__(self, geom_robot: np.ndarray) -> None:
        self._geom_robot = np.asarray(geom_robot, dtype=np.int64)
        self._touching: set[tuple[int, int]] = set()
        self.events: list[tuple[float, int, int]] = []

    def touching_pairs(self, data: mujoco.MjData) -> set[tuple[int, int]]:
        """Robot pairs ``(i, j)`` with ``i < j`` in contact in ``data`` right now."""
        if data.ncon == 0:
            return set()
        robots = self._geom_robot[data.contact.geom[: data.ncon]]
        both = robots.min(axis=1) >= 0  # both geoms on robots (most contacts are the floor's)
        if not both.any():
            return set()
        mask = both & (robots[:, 0] != robots[:, 1])
        pairs = np.sort(robots[mask], axis=1)
        return {(int(a), int(b)) for a, b in pairs}

    def record(self, time_s: float, now: set[tuple[int, int]]) -> list[tuple[int, int]]:
        """Record which pairs ``(i, j)``, i < j, touch at ``time_s`` (s); return the new ones
        (the kinematic tier reports its pairs here, :mod:`mjswarm.core.kinematic`)."""
        new = sorted(now - self._touching)
        self._touching = now
        self.events.extend((time_s, i, j) for i, j in new)
        return new

    @property
    def count(self) -> int:
        """Number of collision events so far."""
        return len(self.events)
