"""Line of sight between robots: cast once per world state, shared by every sensor.

Robot ``k`` sees robot ``p`` when a ray from ``k``'s centre at ``RAY_HEIGHT_M``, towards
``p``'s centre, hits ``p`` first; only collision geoms (``COLLISION_GROUP``: robots, walls, the floor) block.
The bearing sensor (:mod:`mjswarm.core.bearing`) asks this for the ordered pairs in its field of
view, the radio (:func:`mjswarm.experiments.awareness.sight_blocker`) for every pair in range
one way, and the way back only where the way there is clear (a link needs both).
:class:`LineOfSight` answers each ordered pair once per world state (the simulation's
``state_version``), so the bearing sensor's rays that the radio has already cast in a tick
(all of them between robots that see each other, when both have the same range) cost
nothing.
The rays are cast by the simulation's :class:`~mjswarm.core.raycast.RayCaster`, which answers as
``mj_ray`` does (``tests/test_raycast.py`` checks every ordered pair against ``mj_ray``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import mujoco
import numpy as np

from mjswarm.core.raycast import Rays
from mjswarm.core.world import COLLISION_GROUP

if TYPE_CHECKING:
    from mjswarm.core.simulation import Simulation

RAY_HEIGHT_M = 0.06  # above the wheels (0.05 m), inside the chassis (0.012..0.07 m)
#: ``mj_ray``'s group filter: only collision geoms block line of sight.
_COLLISION = (np.arange(mujoco.mjNGROUP) == COLLISION_GROUP).astype(np.uint8)


class LineOfSight:
    """``sight(k, p)``: for every ordered pair ``(k[i], p[i])``, whether ``k`` sees ``p``.

    Answers are kept, keyed ``k * N + p``, until the simulation's state changes.
    """

    def __init__(self, sim: Simulation) -> None:
        self.sim = sim
        self._version = -1
        self._keys = np.empty(0, np.int64)
        self._seen = np.empty(0, bool)
        self.rays_cast = 0  #: rays cast so far (each ordered pair once per state)

    def __call__(self, k: np.ndarray, p: np.ndarray) -> np.ndarray:
        n = self.sim.n
        k, p = np.asarray(k, np.int64), np.asarray(p, np.int64)
        key = k * n + p
        if self._version != self.sim.state_version:  # a new state: nothing known yet
            self._version = self.sim.state_version
            self._keys, self._seen = np.empty(0, np.int64), np.empty(0, bool)
            order = np.argsort(key, kind="stable")
            if len(key) < 2 or (np.diff(key[order]) > 0).all():  # all new, no repeats
                self._keys = key[order]
                self._seen = self._cast(self._keys // n, self._keys % n)
                seen = np.empty(len(key), bool)
                seen[order] = self._seen
                return seen
        where = self._find(key)
        missing = where < 0
        if missing.any():
            new = np.unique(key[missing])
            keys = np.concatenate([self._keys, new])
            seen = np.concatenate([self._seen, self._cast(new // n, new % n)])
            order = np.argsort(keys, kind="stable")
            self._keys, self._seen = keys[order], seen[order]
            where = self._find(key)
        return self._seen[where]

    def from_point(self, point: tuple[float, float], robots: np.ndarray,
                   height_m: float = RAY_HEIGHT_M) -> np.ndarray:
        """Whether each robot is seen from a fixed antenna at ``point`` (m), ``height_m``
        above the floor (a base station's mast): a ray from the antenna towards the robot's
        centre at ``RAY_HEIGHT_M`` must hit the robot first; nothing is excluded."""
        sim = self.sim
        robots = np.asarray(robots, np.int64)
        poses = sim.poses()
        start = np.array([point[0], point[1], height_m], float)
        vec = np.column_stack([poses[robots, :2], np.full(len(robots), RAY_HEIGHT_M)]) - start
        dist = np.linalg.norm(vec, axis=1)
        unit = vec / np.where(dist > 0, dist, 1.0)[:, None]
        unit[dist == 0] = (1.0, 0.0, 0.0)
        self.rays_cast += len(robots)
        _, geom = sim.rays.cast(Rays(np.tile(start, (len(robots), 1)), unit,
                                     dist + sim.rays.robot_radius_m, np.full(len(robots), -1)),
                                _COLLISION)
        return (geom >= 0) & (sim.geom_robot[geom] == robots)

    def _find(self, key: np.ndarray) -> np.ndarray:
        """Index of each key among the answered ones, -1 where not answered yet."""
        if not len(self._keys):
            return np.full(len(key), -1)
        at = np.searchsorted(self._keys, key).clip(max=len(self._keys) - 1)
        return np.where(self._keys[at] == key, at, -1)

    def _cast(self, k: np.ndarray, p: np.ndarray) -> np.ndarray:
        """Every geom of ``p`` lies within ``R`` of its centre, so a ray of length
        ``|p - k| + R`` finds ``p`` if ``mj_ray`` would; coincident robots do not see
        each other."""
        sim = self.sim
        poses = sim.poses()
        vec = poses[p, :2] - poses[k, :2]
        dist = np.hypot(vec[:, 0], vec[:, 1])
        apart = dist > 0
        unit = np.column_stack([vec / np.where(apart, dist, 1.0)[:, None], np.zeros(len(k))])
        unit[~apart, 0] = 1.0
        start = np.column_stack([poses[k, :2], np.full(len(k), RAY_HEIGHT_M)])
        self.rays_cast += len(k)
        _, geom = sim.rays.cast(Rays(start, unit, dist + sim.rays.robot_radius_m, sim.robot_bodies[k]), _COLLISION)
        return apart & (geom >= 0) & (sim.geom_robot[geom] == p)
