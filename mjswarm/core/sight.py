"""Line of sight between robots: cast once per world state, shared by every sensor.

Robot ``k`` sees robot ``p`` when a ray from ``k``'s centre at ``ANTENNA_HEIGHT_M``, towards
``p``'s centre, hits ``p`` first; only collision geoms (``COLLISION_GROUP``: robots, walls, the floor) block.
The bearing sensor (:mod:`mjswarm.core.bearing`) asks this for the ordered pairs in its field of
view, the radio (:func:`mjswarm.core.radio.sight_blocker`) for every pair in range
both ways in one call (a link needs both).
:class:`LineOfSight` answers each ordered pair once per world state (the simulation's
``state_version``), so the bearing sensor's rays that the radio has already cast in a tick
(all of them, when the radio's range is at least the sensor's) cost nothing.
The rays go where the simulation's rangefinders go: with ``sensing="mujoco"`` (few robots,
below ``GRID_SENSING_MIN_ROBOTS``) to MuJoCo itself, ``mj_ray`` ray by ray below
``MULTI_RAY_FROM`` rays, else one ``mj_multiRay`` per robot with that many (every ray from
one robot's centre at once; 4 robots' 6 rays in about 20 us, where the grid caster's fixed
cost is about 50 us), else to the simulation's
:class:`~mjswarm.core.raycast.RayCaster`, which answers as ``mj_ray`` does
(``tests/test_raycast.py`` and ``tests/test_sight.py`` check every ordered pair against
``mj_ray`` and the two paths against each other).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import mujoco
import numpy as np

from mjswarm.core.radio import ANTENNA_HEIGHT_M
from mjswarm.core.raycast import Rays
from mjswarm.core.world import COLLISION_GROUP

if TYPE_CHECKING:
    from mjswarm.core.simulation import Simulation

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
        #: one ray's start and direction (m) and first geom, for :meth:`_cast_each`
        self._ray = (np.array([0.0, 0.0, ANTENNA_HEIGHT_M]), np.zeros(3), np.empty(1, np.int32))

    def __call__(self, k: np.ndarray, p: np.ndarray) -> np.ndarray:
        n = self.sim.n
        key = np.asarray(k, np.int64) * n + np.asarray(p, np.int64)
        if self._version != self.sim.state_version:  # a new state: nothing known yet
            self._version = self.sim.state_version
            if len(key) < 2:  # one ray or none (the main job's common case): nothing to sort
                self._keys, self._seen = key, self._cast(key // n, key % n)
                return self._seen.copy()
            self._keys, self._seen = np.empty(0, np.int64), np.empty(0, bool)
            order = np.argsort(key, kind="stable")
            ordered = key[order]
            if (ordered[1:] > ordered[:-1]).all():  # all new, no repeats
                self._keys = ordered
                self._seen = self._cast(self._keys // n, self._keys % n)
                seen = np.empty(len(key), bool)
                seen[order] = self._seen
                return seen
        where = self._find(key)
        missing = where < 0
        if missing.any():  # cast the new pairs, each once, and merge them in key order
            new = np.sort(key[missing])
            new = new[np.concatenate([[True], new[1:] != new[:-1]])]
            at = np.searchsorted(self._keys, new)
            self._seen = np.insert(self._seen, at, self._cast(new // n, new % n))
            self._keys = np.insert(self._keys, at, new)
            where = self._find(key)
        return self._seen[where]

    def from_point(self, point: tuple[float, float], robots: np.ndarray,
                   height_m: float = ANTENNA_HEIGHT_M) -> np.ndarray:
        """Whether each robot is seen from a fixed antenna at ``point`` (m), ``height_m``
        above the floor (a base station's mast): a ray from the antenna towards the robot's
        centre at ``ANTENNA_HEIGHT_M`` must hit the robot first; nothing is excluded."""
        sim = self.sim
        robots = np.asarray(robots, np.int64)
        poses = sim.poses()
        start = np.array([point[0], point[1], height_m], float)
        vec = np.column_stack([poses[robots, :2], np.full(len(robots), ANTENNA_HEIGHT_M)]) - start
        dist = np.linalg.norm(vec, axis=1)
        unit = vec / np.where(dist > 0, dist, 1.0)[:, None]
        unit[dist == 0] = (1.0, 0.0, 0.0)
        self.rays_cast += len(robots)
        geom = self._first_geoms(np.zeros(len(robots), np.int64), np.tile(start, (len(robots), 1)),
                                 unit, dist, np.full(len(robots), -1))
        return (geom >= 0) & (sim.geom_robot[geom] == robots)

    def _find(self, key: np.ndarray) -> np.ndarray:
        """Index of each key among the answered ones, -1 where not answered yet."""
        if not len(self._keys):
            return np.full(len(key), -1)
        at = np.minimum(np.searchsorted(self._keys, key), len(self._keys) - 1)
        return np.where(self._keys[at] == key, at, -1)

    def _cast(self, k: np.ndarray, p: np.ndarray) -> np.ndarray:
        """Every geom of ``p`` lies within ``R`` of its centre, so a ray of length
        ``|p - k| + R`` finds ``p`` if ``mj_ray`` would; coincident robots do not see
        each other."""
        sim = self.sim
        x, y, _ = sim.poses().T
        dx, dy = x[p] - x[k], y[p] - y[k]
        dist = np.hypot(dx, dy)
        self.rays_cast += len(k)
        if sim.sensing == "mujoco" and len(k) < MULTI_RAY_FROM:
            return self._cast_each(k, p, x, y, dx, dy, dist)
        apart = dist > 0
        scale = np.where(apart, dist, 1.0)
        unit = np.zeros((len(k), 3))
        unit[:, 0], unit[:, 1] = dx / scale, dy / scale
        unit[~apart, 0] = 1.0
        start = np.full((len(k), 3), ANTENNA_HEIGHT_M)
        start[:, 0], start[:, 1] = x[k], y[k]
        geom = self._first_geoms(k, start, unit, dist, sim.robot_bodies[k])
        return apart & (geom >= 0) & (sim.geom_robot[geom] == p)

    def _cast_each(self, k: np.ndarray, p: np.ndarray, x: np.ndarray, y: np.ndarray,
                   dx: np.ndarray, dy: np.ndarray, dist: np.ndarray) -> np.ndarray:
        """:meth:`_cast` of fewer than ``MULTI_RAY_FROM`` rays under MuJoCo's sensing (the
        main job's 0-3 a tick): ``mj_ray`` ray by ray from Python floats, with the start and
        direction :meth:`_cast`'s arrays hold, bit for bit (the same subtractions, and the
        same ``np.hypot``), without building them (their dozen numpy calls cost about
        15 us a tick)."""
        sim = self.sim
        model, data, bodies, owner = sim.model, sim.data, sim.robot_bodies, sim.geom_robot
        start, unit, hit = self._ray
        seen = np.zeros(len(k), bool)
        for r, (kr, pr, d) in enumerate(zip(k.tolist(), p.tolist(), dist.tolist())):
            if d > 0:  # coincident robots do not see each other
                start[0], start[1] = x[kr], y[kr]
                unit[0], unit[1] = dx[r] / d, dy[r] / d
                mujoco.mj_ray(model, data, start, unit, _COLLISION, 1, int(bodies[kr]), hit)
                seen[r] = hit[0] >= 0 and owner[hit[0]] == pr
        return seen

    def _first_geoms(self, origin: np.ndarray, start: np.ndarray, unit: np.ndarray,
                     dist: np.ndarray, exclude: np.ndarray) -> np.ndarray:
        """The first collision geom each ray ``start + t unit`` hits (-1: none), a ray
        aimed at a robot ``dist`` away; rays with equal ``origin`` share their start and
        excluded body. Every geom of the target lies within ``R`` of its centre, so the
        grid caster looks ``dist + R`` far (a farther hit is not the target either)."""
        sim = self.sim
        if sim.sensing != "mujoco":
            _, geom = sim.rays.cast(Rays(start, unit, dist + sim.rays.robot_radius_m, exclude), _COLLISION)
            return geom
        return _multi_ray(sim.model, sim.data, origin, start, unit, exclude)


#: From this many rays from one origin, one ``mj_multiRay`` (about 8.5 us in arena2, whatever
#: the count) costs less than as many ``mj_ray`` calls (about 1.2 us each).
MULTI_RAY_FROM = 8


def _multi_ray(model: mujoco.MjModel, data: mujoco.MjData, origin: np.ndarray, start: np.ndarray,
               unit: np.ndarray, exclude: np.ndarray) -> np.ndarray:
    """``mj_ray``'s first geom for every ray (no cutoff, static geoms tested, collision
    group only, as :meth:`LineOfSight._first_geoms`): ``mj_ray`` ray by ray, or one
    ``mj_multiRay`` for an origin with ``MULTI_RAY_FROM`` rays or more."""
    n = len(origin)
    geom = np.full(n, -1, np.int64)
    if not n:
        return geom
    order = np.argsort(origin, kind="stable")
    origin = origin[order]
    cuts = (np.flatnonzero(origin[1:] != origin[:-1]) + 1).tolist()
    start, unit = np.ascontiguousarray(start[order], float), np.ascontiguousarray(unit[order], float)
    exclude = exclude[order].tolist()
    hit = np.empty(n, np.int32)
    one = np.empty(1, np.int32)
    for a, b in zip([0, *cuts], [*cuts, n]):
        if b - a >= MULTI_RAY_FROM:
            mujoco.mj_multiRay(model, data, start[a], unit[a:b].ravel(), _COLLISION, 1, exclude[a],
                               hit[a:b], np.empty(b - a), None, b - a, mujoco.mjMAXVAL)
            continue
        for r in range(a, b):
            mujoco.mj_ray(model, data, start[r], unit[r], _COLLISION, 1, exclude[r], one)
            hit[r] = one[0]
    geom[order] = hit
    return geom
