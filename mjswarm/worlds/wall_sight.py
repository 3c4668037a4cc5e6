"""Radio line of sight against an arena's walls, for point robots (the radio graph world).

The MuJoCo world's radio links two robots only when each sees the other past every
collision geom (:func:`~mjswarm.core.radio.sight_blocker`), and the base, whose antenna
stands on a mast above the root, only when it sees the robot. :func:`wall_blocker` asks
the same question of the same walls for points: the corridor walls of
:func:`~mjswarm.arena.geometry.corridor_walls` as the MJCF builder makes them (boxes
``WALL_THICKNESS_M`` thick and ``WALL_HEIGHT_M`` high on the floor), and antennas at
:data:`~mjswarm.core.radio.ANTENNA_HEIGHT_M` on a robot and at the mast's height on a
fixed node. A link is blocked when the straight line between its two antennas passes
through a wall's box, in three dimensions: between two robots (antennas below the walls'
tops) any wall crossed in plan blocks; the line from a mast comes down towards the robot
and clears a wall unless it crosses it where it is lower than the wall's top (near the
robot). Two fixed nodes always link.

What points do not model: robots' bodies, which block rays in the MuJoCo world (a robot
standing between two others), and the robots' offset onto their lanes (points travel the
edges' centre lines).
"""

from __future__ import annotations

from collections.abc import Hashable, Mapping, Sequence

import numpy as np

from mjswarm.arena.geometry import WALL_HEIGHT_M, WALL_THICKNESS_M, Wall
from mjswarm.core.radio import ANTENNA_HEIGHT_M, Blocker


def wall_boxes(walls: Sequence[Wall], grow_m: float = 0.0) -> np.ndarray:
    """Each wall's footprint as its four sides, ``(walls * 4, 2 ends, 2)`` (m), grown by
    ``grow_m`` on every side."""
    sides = []
    for wall in walls:
        a, b = np.asarray(wall.start, float), np.asarray(wall.end, float)
        along = (b - a) / np.hypot(*(b - a))
        a, b = a - grow_m * along, b + grow_m * along
        normal = np.array([-along[1], along[0]]) * (WALL_THICKNESS_M / 2.0 + grow_m)
        corners = [a + normal, b + normal, b - normal, a - normal]
        sides += [(corners[k], corners[(k + 1) % 4]) for k in range(4)]
    return np.array(sides, float).reshape(-1, 2, 2)


def _crossings(a: np.ndarray, b: np.ndarray, sides: np.ndarray) -> np.ndarray:
    """For segments ``a -> b`` ``(pairs, 2)`` against ``sides`` ``(S, 2, 2)``: where along
    each segment (0 at ``a``, 1 at ``b``) it meets each side, NaN where it does not;
    ``(pairs, S)``."""
    c, d = sides[None, :, 0], sides[None, :, 1]
    r, s = (b - a)[:, None], d - c
    denom = r[..., 0] * s[..., 1] - r[..., 1] * s[..., 0]
    q = c - a[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (q[..., 0] * s[..., 1] - q[..., 1] * s[..., 0]) / denom
        u = (q[..., 0] * r[..., 1] - q[..., 1] * r[..., 0]) / denom
    hit = (denom != 0) & (t >= 0) & (t <= 1) & (u >= 0) & (u <= 1)
    return np.where(hit, t, np.nan)


def wall_blocker(walls: Sequence[Wall], positions: Mapping[Hashable, Sequence[float]],
                 masts: Mapping[Hashable, float], grow_m: float = 0.0,
                 grow_top_m: float | None = None) -> Blocker:
    """The radio's :data:`~mjswarm.core.radio.Blocker` for points among ``walls``: for each
    pair, whether the line between the antennas passes through a wall (module
    docstring). ``positions`` (m, read at call time) by node; ``masts``: the antenna
    height (m) of each fixed node (every other node is a robot). With ``grow_m`` (m), the
    walls are grown by that much on every side, and by ``grow_top_m`` (default
    ``grow_m``) in height: the links that pass within about ``grow_m`` of a wall (a fading
    link, :data:`~mjswarm.core.radio.FADE_MARGIN_M`)."""
    sides = wall_boxes(walls, grow_m)
    top_m = WALL_HEIGHT_M + (grow_m if grow_top_m is None else grow_top_m)

    def blocked(pairs: np.ndarray) -> np.ndarray:
        pairs = np.asarray(pairs, object).reshape(-1, 2)
        if not len(sides) or not len(pairs):
            return np.zeros(len(pairs), bool)
        a = np.array([positions[i][:2] for i, _ in pairs], float)
        b = np.array([positions[j][:2] for _, j in pairs], float)
        high_a = np.array([masts.get(i, ANTENNA_HEIGHT_M) for i, _ in pairs])
        high_b = np.array([masts.get(j, ANTENNA_HEIGHT_M) for _, j in pairs])
        t = _crossings(a, b, sides)  # (pairs, sides)
        height = high_a[:, None] + t * (high_b - high_a)[:, None]  # the line over each crossing
        cut = np.any(height <= top_m, axis=1)  # NaN (no crossing) compares False
        both_fixed = np.array([i in masts and j in masts for i, j in pairs], bool)
        return cut & ~both_fixed

    return blocked
