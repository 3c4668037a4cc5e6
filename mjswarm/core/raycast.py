"""Ray casting in O(N): MuJoCo's ``mj_ray``, tested only against geoms a ray can reach.

``mj_ray`` (and so every MuJoCo rangefinder) tests a ray against every geom of the model,
about 6.7 ns per ray x geom pair, so N robots casting a few rays each cost O(N^2). A
:class:`RayCaster` returns what ``mj_ray`` returns for rays of bounded length ``L`` (the
nearest hit within ``L`` and its geom), testing each ray only against

* geoms welded to the world, binned once into a uniform 2-D grid of ``cell_m`` cells by
  their world bounding boxes (planes, unbounded, are always tested); a geom spanning
  several cells of a ray's box is tested once, and only if the segment meets its world
  bounding box (grown by 1 um);
* the geoms of robots binned, at every cast, by their centres into the same grid: robot
  j's geoms lie within ``R`` of its centre, so only robots in the cells of the ray's
  segment box grown by ``R`` can be hit, and of those only robots whose centre is within
  ``R`` of the segment;
* any other moving geom (none in mjswarm's worlds), always.

Each surviving geom first passes a segment / bounding-sphere test (a geom whose bounding
sphere misses the segment cannot be hit within ``L``), then the exact intersection: a
line-by-line transcription of MuJoCo's ``mju_rayGeom`` (``engine_ray.c``: ``ray_plane``,
``ray_sphere``, ``ray_box``, ``ray_cylinder`` with their bounding-sphere tests and the
``mjMINVAL`` guards), with ``mj_ray``'s elimination rules (the excluded body, invisible
geoms by ``rgba`` or material alpha, geom groups). Ties go to the lower geom id, as in
``mj_ray``. The per-ray loop is compiled with numba as a parallel loop over rays, its
helpers inlined, and runs on ``threads`` threads (default 1: a second thread only pays on
an otherwise idle core, and ``mjswarm sweep`` already fills the cores with processes; the
parallel kernel is kept because numba compiles it to faster code than a plain loop, also
on one thread: the same loop compiled without ``parallel`` took 35 / 1383 / 4479 us against
27 / 210 / 696 us for the rangefinders of 4 / 300 / 1000 robots). A cast sets numba's thread
count to ``threads`` only when it differs (and leaves it there), so a process with one
caster sets it once rather than twice per call.
``tests/test_raycast.py`` checks distances within 1e-9 and geom ids against ``mj_ray`` on
random states.

Supported geom types are plane, sphere, box and cylinder (every geom of mjswarm's robots
and arenas); a model with another ray-visible type raises :class:`MjswarmError` naming it,
and :class:`~mjswarm.core.simulation.Simulation` then needs ``sensing="mujoco"``.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numba
import numpy as np
from numba import njit, prange

from mjswarm.errors import MjswarmError

MJMINVAL = mujoco.mjMINVAL
PLANE, SPHERE, CYLINDER, BOX = (int(mujoco.mjtGeom.mjGEOM_PLANE), int(mujoco.mjtGeom.mjGEOM_SPHERE),
                                    int(mujoco.mjtGeom.mjGEOM_CYLINDER), int(mujoco.mjtGeom.mjGEOM_BOX))
SUPPORTED_TYPES = (PLANE, SPHERE, CYLINDER, BOX)
DEFAULT_CELL_M = 0.5


@dataclass(frozen=True)
class Rays:
    """A batch of rays ``origin + t * direction``, ``0 <= t <= length``.

    Attributes:
        origin: (M, 3) start points (m).
        direction: (M, 3) directions; distances are in units of their length (unit vectors
            give metres).
        length: (M,) how far along each ray a hit matters (units of ``direction``).
        exclude_body: (M,) body id whose geoms the ray ignores (``mj_ray``'s ``bodyexclude``).
    """

    origin: np.ndarray
    direction: np.ndarray
    length: np.ndarray
    exclude_body: np.ndarray


class RayCaster:
    """Nearest-hit queries on one compiled world with N robots.

    Args:
        model: the world's model.
        data: the world's data; it must hold current kinematics (geom and body poses,
            e.g. after ``mj_kinematics``) when the caster is built and when it casts.
        robot_bodies: (N,) root body id of each robot.
        geom_robot: (ngeom,) robot index owning each geom, -1 for others.
        cell_m: grid cell size (m) for the world's static geoms.
        threads: numba threads a cast runs on (1 .. ``numba.config.NUMBA_NUM_THREADS``).
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, robot_bodies: np.ndarray,
                 geom_robot: np.ndarray, cell_m: float = DEFAULT_CELL_M, threads: int = 1) -> None:
        if cell_m <= 0:
            raise MjswarmError(f"ray grid cell size must be positive, got {cell_m} m")
        if not 1 <= threads <= numba.config.NUMBA_NUM_THREADS:
            raise MjswarmError(f"ray casting threads must be 1..{numba.config.NUMBA_NUM_THREADS}, got {threads}")
        self.threads = threads
        m = model
        self.model, self.data, self.robot_bodies = m, data, np.asarray(robot_bodies)
        mat_alpha = np.append(m.mat_rgba[:, 3], 1.0)  # index -1: no material
        rgba_alpha = np.where(m.geom_matid < 0, m.geom_rgba[:, 3], mat_alpha[m.geom_matid])
        self.visible = rgba_alpha != 0
        unsupported = self.visible & ~np.isin(m.geom_type, SUPPORTED_TYPES)
        if unsupported.any():
            g = int(np.flatnonzero(unsupported)[0])
            raise MjswarmError(
                f"geom '{m.geom(g).name or g}' has type {mujoco.mjtGeom(m.geom_type[g]).name}, "
                "which grid ray casting does not support; use sensing='mujoco'")
        self.group = np.clip(m.geom_group, 0, mujoco.mjNGROUP - 1)
        static = m.body_weldid[m.geom_bodyid] == 0
        robot_geoms = geom_robot >= 0
        self.always = np.flatnonzero(self.visible & ((static & (m.geom_type == PLANE))
                                                     | (~static & ~robot_geoms))).astype(np.int64)
        self._build_grid(np.flatnonzero(self.visible & static & (m.geom_type != PLANE)), cell_m)
        order = np.argsort(geom_robot[robot_geoms], kind="stable")
        self._robot_geoms = np.flatnonzero(robot_geoms)[order].astype(np.int64)
        self._robot_geom_start = np.searchsorted(geom_robot[self._robot_geoms], np.arange(len(robot_bodies) + 1))
        root_xpos = data.xpos[robot_bodies]
        centre = np.repeat(root_xpos, np.diff(self._robot_geom_start), axis=0)
        #: R: every robot geom lies within this distance of its robot's root (m)
        self.robot_radius_m = float(np.max(np.linalg.norm(data.geom_xpos[self._robot_geoms] - centre, axis=1)
                                           + m.geom_rbound[self._robot_geoms], initial=0.0))

    def _build_grid(self, geoms: np.ndarray, cell_m: float) -> None:
        """The grid covers the static geoms and the robots' starting places (robots that
        leave it are binned into its border cells, which stays correct); static geoms are
        binned into the cells their world AABBs overlap (CSR: cell -> geoms)."""
        m, d = self.model, self.data
        self.cell_m = cell_m
        mat = d.geom_xmat[geoms].reshape(-1, 3, 3)
        aabb = m.geom_aabb[geoms]
        centre = d.geom_xpos[geoms] + np.einsum("gij,gj->gi", mat, aabb[:, :3])
        half = np.einsum("gij,gj->gi", np.abs(mat), aabb[:, 3:])
        lo, hi = (centre - half)[:, :2], (centre + half)[:, :2]
        robots = d.xpos[self.robot_bodies][:, :2]
        self._origin = np.minimum(lo.min(axis=0, initial=np.inf), robots.min(axis=0))
        top = np.maximum(hi.max(axis=0, initial=-np.inf), robots.max(axis=0))
        self._shape = tuple(int(k) for k in np.floor((top - self._origin) / cell_m) + 1)
        self._shape_array = np.array(self._shape, np.int64)
        lo_cell = self._cells(lo)
        cells, owner = self._expand(lo_cell, self._cells(hi))
        # per static geom: its first cell, and its world AABB grown by 1 um (a hit lies on
        # the geom, so inside the box up to rounding; growing keeps the box test safe)
        self._static_corner = np.zeros((m.ngeom, 2), np.int64)
        self._static_corner[geoms] = lo_cell
        grow = 1e-6 + 1e-9 * np.abs(centre) + 1e-9 * half
        self._static_box = np.zeros((m.ngeom, 6))
        self._static_box[geoms] = np.hstack([centre - half - grow, centre + half + grow])
        order = np.argsort(cells, kind="stable")
        self._cell_geoms = geoms[owner[order]].astype(np.int64)
        self._cell_ids = np.arange(self._shape[0] * self._shape[1] + 1)
        self._cell_start = np.searchsorted(cells[order], self._cell_ids)
        self._candidates: dict[bytes | None, np.ndarray] = {}  # geomgroup -> geoms it may hit
        self._binned: tuple[np.ndarray, ...] = (np.empty((0, 3)),)  # :meth:`_binned_robots`

    def _cells(self, xy: np.ndarray) -> np.ndarray:
        """Grid (ix, iy) of points, clipped to the grid."""
        idx = np.floor((xy - self._origin) / self.cell_m).astype(np.int64)
        return np.clip(idx, 0, self._shape_array - 1)

    def _expand(self, c0: np.ndarray, c1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All cells of the boxes ``c0..c1`` (inclusive): (flat cell ids, box index)."""
        nx = c1[:, 0] - c0[:, 0] + 1
        count = nx * (c1[:, 1] - c0[:, 1] + 1)
        owner = np.repeat(np.arange(len(c0)), count)
        local = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
        cx = c0[owner, 0] + local % nx[owner]
        cy = c0[owner, 1] + local // nx[owner]
        return self._flat(np.column_stack([cx, cy])), owner

    # ------------------------------------------------------------------ queries
    def cast(self, rays: Rays, geomgroup: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Nearest hit of every ray within its length: (distance, geom id), -1 where none.

        ``geomgroup`` is ``mj_ray``'s: None tests every group, else a 0/1 flag per group.
        Static geoms are always tested (``mj_ray``'s ``flg_static = 1``).
        """
        n = len(rays.length)
        dist, geom = np.full(n, -1.0), np.full(n, -1, np.int64)
        if n == 0:
            return dist, geom
        m, d = self.model, self.data
        key = None if geomgroup is None else bytes(np.asarray(geomgroup, bool))
        candidate = self._candidates.get(key)
        if candidate is None:
            groups = np.ones(mujoco.mjNGROUP, bool) if key is None else np.asarray(geomgroup, bool)
            candidate = self._candidates[key] = self.visible & groups[self.group]
        centres, order, robot_start = self._binned_robots()
        if numba.get_num_threads() != self.threads:  # set once, not per call (see above)
            numba.set_num_threads(self.threads)
        _cast(np.ascontiguousarray(rays.origin, float), np.ascontiguousarray(rays.direction, float),
              np.asarray(rays.length, float), np.asarray(rays.exclude_body, np.int64), candidate,
              m.geom_type, m.geom_bodyid, d.geom_xpos, d.geom_xmat, m.geom_size, m.geom_rbound,
              self.always, self._origin, self.cell_m, self._shape_array,
              self._cell_start, self._cell_geoms, self._static_box, self._static_corner,
              robot_start, order, centres,
              self._robot_geom_start, self._robot_geoms, self.robot_radius_m, dist, geom)
        return dist, geom

    def _binned_robots(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The robots' centres now (m), the robots sorted by grid cell and each cell's
        start in that order; binned again only when a centre moved (the rangefinders and
        the line of sight of one state, about 45 us a binning at 1000 robots, share one)."""
        centres = self.data.xpos[self.robot_bodies]
        if not np.array_equal(centres, self._binned[0]):
            cells = self._flat(self._cells(centres[:, :2]))
            order = np.argsort(cells, kind="stable")
            self._binned = (centres, order, np.searchsorted(cells[order], self._cell_ids))
        return self._binned

    def _flat(self, cells: np.ndarray) -> np.ndarray:
        return cells[:, 0] * self._shape[1] + cells[:, 1]


# ----------------------------------------------------------------- the compiled ray loop
@njit(cache=True, error_model="numpy", parallel=True)
def _cast(origin, direction, length, exclude_body, candidate, geom_type, geom_bodyid, geom_xpos,
          geom_xmat, geom_size, geom_rbound, always, grid_origin, cell_m, shape, cell_start,
          cell_geoms, static_box, static_corner, robot_start, robots, centres, robot_geom_start,
          robot_geoms, robot_radius, out_dist, out_geom):  # pragma: no cover (compiled)
    """Every ray's nearest hit (``out_dist``, ``out_geom``).

    A static geom spanning several cells of the ray's box is tested once, in the first of
    them (its ``static_corner`` clipped to the box), and only if the segment meets its
    world AABB (``static_box``)."""
    for r in prange(len(length)):
        # scalars and tuples, not array views: a view costs a reference count per use
        pnt = (origin[r, 0], origin[r, 1], origin[r, 2])
        vec = (direction[r, 0], direction[r, 1], direction[r, 2])
        top, skip = length[r], exclude_body[r]
        best, best_geom = -1.0, -1
        end0, end1 = pnt[0] + top * vec[0], pnt[1] + top * vec[1]
        lo0, hi0 = min(pnt[0], end0), max(pnt[0], end0)
        lo1, hi1 = min(pnt[1], end1), max(pnt[1], end1)
        for g in always:
            best, best_geom = _try(g, best, best_geom, pnt, vec, top, skip, candidate, geom_type,
                                   geom_bodyid, geom_xpos, geom_xmat, geom_size, geom_rbound)
        cx0, cy0 = _cell(lo0, lo1, grid_origin, cell_m, shape)
        cx1, cy1 = _cell(hi0, hi1, grid_origin, cell_m, shape)
        for cx in range(cx0, cx1 + 1):
            for cy in range(cy0, cy1 + 1):
                c = cx * shape[1] + cy
                for k in range(cell_start[c], cell_start[c + 1]):
                    g = cell_geoms[k]
                    if (not candidate[g] or max(static_corner[g, 0], cx0) != cx
                            or max(static_corner[g, 1], cy0) != cy
                            or not _meets_box(static_box, g, pnt, vec, _reach(top, best))):
                        continue
                    best, best_geom = _try(g, best, best_geom, pnt, vec, top, skip, candidate,
                                           geom_type, geom_bodyid, geom_xpos, geom_xmat,
                                           geom_size, geom_rbound)
        cx0, cy0 = _cell(lo0 - robot_radius, lo1 - robot_radius, grid_origin, cell_m, shape)
        cx1, cy1 = _cell(hi0 + robot_radius, hi1 + robot_radius, grid_origin, cell_m, shape)
        for cx in range(cx0, cx1 + 1):
            for cy in range(cy0, cy1 + 1):
                c = cx * shape[1] + cy
                for k in range(robot_start[c], robot_start[c + 1]):
                    i = robots[k]
                    centre = (centres[i, 0], centres[i, 1], centres[i, 2])
                    if _gap_sq(centre, pnt, vec, _reach(top, best)) > robot_radius * robot_radius * (1 + 1e-9):
                        continue
                    for j in range(robot_geom_start[i], robot_geom_start[i + 1]):
                        best, best_geom = _try(robot_geoms[j], best, best_geom, pnt, vec, top,
                                               skip, candidate, geom_type, geom_bodyid,
                                               geom_xpos, geom_xmat, geom_size, geom_rbound)
        out_dist[r], out_geom[r] = best, best_geom


@njit(cache=True, error_model="numpy", inline="always")
def _cell(x, y, grid_origin, cell_m, shape):  # pragma: no cover (compiled)
    cx = min(max(int(np.floor((x - grid_origin[0]) / cell_m)), 0), shape[0] - 1)
    cy = min(max(int(np.floor((y - grid_origin[1]) / cell_m)), 0), shape[1] - 1)
    return cx, cy


@njit(cache=True, error_model="numpy", inline="always")
def _gap_sq(point, pnt, vec, top):  # pragma: no cover (compiled)
    """Squared distance from ``point`` to the segment ``pnt + t vec``, ``0 <= t <= top``."""
    d0, d1, d2 = point[0] - pnt[0], point[1] - pnt[1], point[2] - pnt[2]
    t = (d0 * vec[0] + d1 * vec[1] + d2 * vec[2]) / (vec[0] * vec[0] + vec[1] * vec[1] + vec[2] * vec[2])
    t = min(max(t, 0.0), top)
    g0, g1, g2 = d0 - t * vec[0], d1 - t * vec[1], d2 - t * vec[2]
    return g0 * g0 + g1 * g1 + g2 * g2


@njit(cache=True, error_model="numpy", inline="always")
def _reach(top, best):  # pragma: no cover (compiled)
    """How far along the ray a hit can still win: its length, or the best hit so far (a
    geom whose bounding sphere lies beyond it can neither beat nor tie it)."""
    return top if best < 0 else min(top, best)


@njit(cache=True, error_model="numpy", inline="always")
def _meets_box(box, g, pnt, vec, top):  # pragma: no cover (compiled)
    """Whether the segment ``pnt + t vec``, ``0 <= t <= top``, meets geom ``g``'s box
    ``box[g, :3] <= x <= box[g, 3:]`` (slab test)."""
    t0, t1 = 0.0, top
    for a in range(3):
        if vec[a] == 0.0:
            if pnt[a] < box[g, a] or pnt[a] > box[g, a + 3]:
                return False
            continue
        s0, s1 = (box[g, a] - pnt[a]) / vec[a], (box[g, a + 3] - pnt[a]) / vec[a]
        t0, t1 = max(t0, min(s0, s1)), min(t1, max(s0, s1))
        if t0 > t1:
            return False
    return True


@njit(cache=True, error_model="numpy", inline="always")
def _try(g, best, best_geom, pnt, vec, top, skip, candidate, geom_type, geom_bodyid, geom_xpos,
         geom_xmat, geom_size, geom_rbound):  # pragma: no cover (compiled)
    """mj_ray's elimination, the segment test, mju_rayGeom, and the nearest-hit update."""
    if not candidate[g] or geom_bodyid[g] == skip:
        return best, best_geom
    kind = geom_type[g]
    pos = (geom_xpos[g, 0], geom_xpos[g, 1], geom_xpos[g, 2])
    if kind != PLANE and _gap_sq(pos, pnt, vec, _reach(top, best)) > geom_rbound[g] * geom_rbound[g] * (1 + 1e-9):
        return best, best_geom
    mat = (geom_xmat[g, 0], geom_xmat[g, 1], geom_xmat[g, 2], geom_xmat[g, 3], geom_xmat[g, 4],
           geom_xmat[g, 5], geom_xmat[g, 6], geom_xmat[g, 7], geom_xmat[g, 8])
    x = _ray_geom(kind, pos, mat, (geom_size[g, 0], geom_size[g, 1], geom_size[g, 2]), pnt, vec)
    if x >= 0 and x <= top and (best < 0 or x < best or (x == best and g < best_geom)):
        return x, g
    return best, best_geom


# ------------------------------------------------- engine_ray.c, transcribed for numba
@njit(cache=True, error_model="numpy")
def _ray_quad(a, b, c):  # pragma: no cover (compiled)
    """``ray_quad``: smallest non-negative root of ``a x^2 + 2 b x + c = 0``, or -1."""
    det = b * b - a * c
    if det < MJMINVAL:
        return -1.0, -1.0, -1.0
    det = np.sqrt(det)
    x0, x1 = (-b - det) / a, (-b + det) / a
    if x0 >= 0:
        return x0, x0, x1
    if x1 >= 0:
        return x1, x0, x1
    return -1.0, x0, x1


@njit(cache=True, error_model="numpy")
def _ray_sphere(pos, dist_sqr, pnt, vec):  # pragma: no cover (compiled)
    d0, d1, d2 = pnt[0] - pos[0], pnt[1] - pos[1], pnt[2] - pos[2]
    a = vec[0] * vec[0] + vec[1] * vec[1] + vec[2] * vec[2]
    b = vec[0] * d0 + vec[1] * d1 + vec[2] * d2
    c = d0 * d0 + d1 * d1 + d2 * d2 - dist_sqr
    return _ray_quad(a, b, c)[0]


@njit(cache=True, error_model="numpy")
def _ray_map(pos, mat, pnt, vec):  # pragma: no cover (compiled)
    """``ray_map``: the ray in the geom's frame, ``lpnt = mat' (pnt - pos)``, ``lvec = mat' vec``."""
    d0, d1, d2 = pnt[0] - pos[0], pnt[1] - pos[1], pnt[2] - pos[2]
    return ((mat[0] * d0 + mat[3] * d1 + mat[6] * d2,
             mat[1] * d0 + mat[4] * d1 + mat[7] * d2,
             mat[2] * d0 + mat[5] * d1 + mat[8] * d2),
            (mat[0] * vec[0] + mat[3] * vec[1] + mat[6] * vec[2],
             mat[1] * vec[0] + mat[4] * vec[1] + mat[7] * vec[2],
             mat[2] * vec[0] + mat[5] * vec[1] + mat[8] * vec[2]))


@njit(cache=True, error_model="numpy")
def _ray_geom(kind, pos, mat, size, pnt, vec):  # pragma: no cover (compiled)
    """``mju_rayGeom`` for planes, spheres, boxes and cylinders: distance or -1."""
    if kind == SPHERE:
        return _ray_sphere(pos, size[0] * size[0], pnt, vec)
    if kind == BOX:
        if _ray_sphere(pos, size[0] * size[0] + size[1] * size[1] + size[2] * size[2], pnt, vec) < 0:
            return -1.0
        lpnt, lvec = _ray_map(pos, mat, pnt, vec)
        x = -1.0
        for i in range(3):
            if abs(lvec[i]) > MJMINVAL:
                j, k = (1, 2) if i == 0 else ((0, 2) if i == 1 else (0, 1))
                for side in (-1.0, 1.0):
                    sol = (side * size[i] - lpnt[i]) / lvec[i]
                    if sol >= 0:
                        p0, p1 = lpnt[j] + sol * lvec[j], lpnt[k] + sol * lvec[k]
                        if abs(p0) <= size[j] and abs(p1) <= size[k] and (x < 0 or sol < x):
                            x = sol
        return x
    if kind == CYLINDER:
        if _ray_sphere(pos, size[0] * size[0] + size[1] * size[1], pnt, vec) < 0:
            return -1.0
        lpnt, lvec = _ray_map(pos, mat, pnt, vec)
        x = -1.0
        if abs(lvec[2]) > MJMINVAL:
            for side in (-1.0, 1.0):
                sol = (side * size[1] - lpnt[2]) / lvec[2]
                if sol >= 0:
                    p0, p1 = lpnt[0] + sol * lvec[0], lpnt[1] + sol * lvec[1]
                    if p0 * p0 + p1 * p1 <= size[0] * size[0] and (x < 0 or sol < x):
                        x = sol
        a = lvec[0] * lvec[0] + lvec[1] * lvec[1]
        b = lvec[0] * lpnt[0] + lvec[1] * lpnt[1]
        c = lpnt[0] * lpnt[0] + lpnt[1] * lpnt[1] - size[0] * size[0]
        sol = _ray_quad(a, b, c)[0]
        if sol >= 0 and abs(lpnt[2] + sol * lvec[2]) <= size[1] and (x < 0 or sol < x):
            x = sol
        return x
    # plane
    lpnt, lvec = _ray_map(pos, mat, pnt, vec)
    if lvec[2] > -MJMINVAL:
        return -1.0
    x = -lpnt[2] / lvec[2]
    if x < 0:
        return -1.0
    p0, p1 = lpnt[0] + x * lvec[0], lpnt[1] + x * lvec[1]
    if (size[0] <= 0 or abs(p0) <= size[0]) and (size[1] <= 0 or abs(p1) <= size[1]):
        return x
    return -1.0
