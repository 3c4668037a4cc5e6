"""The kinematic tier: robots move by their wheels' kinematics; MuJoCo keeps the scene.

``Simulation(physics="kinematic")`` keeps the same compiled scene, arena and sensors as the
dynamic tier, but no constraint is solved: each control tick :class:`KinematicDrive`

1. runs the wheels' motor filter exactly as the model declares it (``filterexact`` with the
   actuator's time constant ``tau``: ``a <- a + (u - a)(1 - exp(-h / tau))`` per physics step
   ``h``, ``u`` the commanded wheel speed clamped to the ctrl range) and takes each wheel's
   speed equal to its filtered set-point (the velocity servo is ideal: no lag, no slip);
2. integrates differential-drive kinematics per physics step, ``v = r (w_l + w_r) / 2``,
   ``omega = r (w_r - w_l) / b`` (``r`` wheel radius, ``b`` track, both from the model), the
   heading at the step's midpoint (second order; the error over a 2 ms step is below 1e-9 m);
3. applies the contact rule below, writes the poses, wheel angles (the encoders) and
   velocities into ``data`` and recomputes kinematics (``mj_kinematics``), so the ray
   caster, the bearing sensor, the radio and the viewer see the new state.

**Contact rule.** In plan every robot is its chassis disc (radius and offset from the
model's ``chassis`` geom; every other collision geom of the robot lies inside it, which
``tests/test_kinematic.py`` checks) and every wall is its box's rectangle. A robot whose
move this tick would make it overlap another robot or a wall more than it did before the
tick (by more than ``OVERLAP_TOL_M``) stops: it keeps its pose from the start of the tick,
its wheels stand (the encoders do not advance), its motor filter runs on. The test repeats
on the new poses until no robot is stopped anew (a stopped robot may block one that moved
into the place it kept); it ends because the start-of-tick poses pass it. Two robots that
drive into each other both stop. A robot-robot pair that would have overlapped, or still
overlaps, is a touching pair: :class:`~mjswarm.core.contacts.CollisionCounter` counts a
contact event when a pair starts touching, as in the dynamic tier. Bodies never pass
through each other; robots never push each other or tip.

What this tier leaves out: wheel slip on the floor (the encoders' slip model,
``Simulation(wheel_slip=...)``, applies in both tiers), the servo's lag behind its
set-point (about 6 ms at this model's gains), pitching and sinking into the floor, and the
battery's load current (the wheels need no torque: the battery draws its idle current).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from numba import njit

from mjswarm.errors import MjswarmError

if TYPE_CHECKING:
    from mjswarm.core.simulation import Simulation

#: Overlap (m) a move may add before the contact rule stops the robot (float rounding).
OVERLAP_TOL_M = 1e-9
#: Side (m) of the cells of the grid that lists, per cell, the walls a footprint disc
#: centred in it may reach (:class:`WallGrid`).
WALL_CELL_M = 0.25
#: The chassis geom whose disc is a robot's footprint in plan.
FOOTPRINT_GEOM = "chassis"


class KinematicDrive:
    """Moves a simulation's robots by their wheel kinematics (module docstring)."""

    def __init__(self, sim: Simulation) -> None:
        m, d = sim.model, sim.data
        self.sim = sim
        g = sim.geometry
        self.wheel_radius_m, self.track_m = g.wheel_radius_m, g.track_m
        act = sim._actuators
        if not np.all(m.actuator_dyntype[act] == mujoco.mjtDyn.mjDYN_FILTEREXACT):
            raise MjswarmError("the kinematic tier needs the wheels' motors to be "
                               "first-order filters (dyntype filterexact)")
        self._act_adr = m.actuator_actadr[act]
        self._ctrl_lo = m.actuator_ctrlrange[act][..., 0]
        self._ctrl_hi = m.actuator_ctrlrange[act][..., 1]
        h = m.opt.timestep
        self._blend = 1.0 - np.exp(-h / m.actuator_dynprm[act][..., 0])
        self.timestep_s = h
        chassis = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, f"r0/{FOOTPRINT_GEOM}")
        if chassis < 0:
            raise MjswarmError(f"the kinematic tier needs a '{FOOTPRINT_GEOM}' geom on every robot")
        self.footprint_radius_m = float(m.geom_size[chassis, 0])
        self._footprint_offset = m.geom_pos[chassis, :2].copy()  # in the robot's frame (m)
        walls = _wall_rectangles(m, d, sim.geom_robot)
        self._walls = None if walls is None else WallGrid(*walls, self.footprint_radius_m)
        qpos_adr = sim._qpos_adr
        self._xy_adr = qpos_adr[:, None] + np.arange(2)
        self._quat_adr = qpos_adr[:, None] + np.arange(3, 7)
        dof = m.jnt_dofadr[m.body_jntadr[sim.robot_bodies]]
        self._lin_dof = dof[:, None] + np.arange(2)
        self._yaw_dof = dof + 5

    # ------------------------------------------------------------------ one tick
    def step(self, substeps: int) -> set[tuple[int, int]]:
        """Advance one control tick of ``substeps`` physics steps; the touching pairs."""
        sim, d = self.sim, self.sim.data
        start = sim.poses()
        ctrl = np.clip(d.ctrl[sim._actuators], self._ctrl_lo, self._ctrl_hi)
        act = d.act[self._act_adr]
        end, turned, wheel, act = _integrate(start, act, ctrl, self._blend, substeps,
                                             self.timestep_s, self.wheel_radius_m, self.track_m)
        stopped, touching = self._contact_rule(start, end)
        end[stopped] = start[stopped]
        turned[stopped] = 0.0
        wheel = np.where(stopped[:, None], 0.0, wheel)
        self._write(end, turned, wheel, act)
        d.time += substeps * self.timestep_s
        mujoco.mj_kinematics(sim.model, d)
        return touching

    def _write(self, pose: np.ndarray, turned: np.ndarray, wheel: np.ndarray,
               act: np.ndarray) -> None:
        sim, d = self.sim, self.sim.data
        q, qv = d.qpos, d.qvel
        q[self._xy_adr] = pose[:, :2]
        half = pose[:, 2] / 2.0
        quat = np.zeros((len(pose), 4))
        quat[:, 0], quat[:, 3] = np.cos(half), np.sin(half)
        q[self._quat_adr] = quat
        q[sim._wheel_qpos_adr] += turned
        qv[sim._wheel_dof_adr] = wheel
        r = self.wheel_radius_m
        v = r * (wheel[:, 0] + wheel[:, 1]) / 2.0
        qv[self._lin_dof] = np.column_stack([v * np.cos(pose[:, 2]), v * np.sin(pose[:, 2])])
        qv[self._yaw_dof] = r * (wheel[:, 1] - wheel[:, 0]) / self.track_m
        d.act[self._act_adr] = act

    # ------------------------------------------------------------------ contacts
    def footprints(self, pose: np.ndarray) -> np.ndarray:
        """Centres (m) of the robots' footprint discs at planar poses ``pose`` (N, 3)."""
        c, s = np.cos(pose[:, 2]), np.sin(pose[:, 2])
        ox, oy = self._footprint_offset
        return np.column_stack([pose[:, 0] + c * ox - s * oy, pose[:, 1] + s * ox + c * oy])

    def _contact_rule(self, start: np.ndarray, end: np.ndarray) -> tuple[np.ndarray, set]:
        """Which robots stop, and the robot pairs that touch (module docstring)."""
        before = self.footprints(start)
        after = self.footprints(end)
        stopped = np.zeros(len(start), bool)
        touching: set[tuple[int, int]] = set()
        centres = after
        while True:
            pairs, deeper = self._robot_overlaps(before, centres)
            touching.update(map(tuple, pairs[deeper].tolist()))
            anew = np.zeros(len(start), bool)
            anew[pairs[deeper].ravel()] = True
            if self._walls is not None:
                anew |= self._walls.deeper(before, centres)
            anew &= ~stopped
            if not anew.any():
                break
            stopped |= anew
            centres = np.where(stopped[:, None], before, after)
        touching.update(map(tuple, pairs.tolist()))  # what still overlaps at the final poses
        return stopped, touching

    def _robot_overlaps(self, before: np.ndarray, now: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Robot pairs ``(i, j)``, i < j, sorted, whose discs (centres ``now``, m) overlap,
        and whether each overlaps more than at ``before``: one compiled pass over the robots
        binned into cells of a disc's diameter or more (a k-d tree's ``query_pairs`` and
        the same test in numpy took about 180 us a tick at 1000 robots)."""
        i, j, deeper = _overlapping_pairs(np.ascontiguousarray(before, float),
                                          np.ascontiguousarray(now, float),
                                          2.0 * self.footprint_radius_m, OVERLAP_TOL_M)
        order = np.lexsort((j, i))
        return np.column_stack([i[order], j[order]]), deeper[order]


@njit(cache=True)
def _overlapping_pairs(before, now, reach, tol):  # pragma: no cover (compiled)
    """Every pair ``i < j`` of discs whose centres ``now`` lie less than ``reach`` apart
    (``reach - |c_i - c_j| > 0``), found among the discs of the 3 x 3 cells around each
    (square cells of side ``reach`` or more, at most ``16 N`` of them, binned by a counting
    sort); and whether ``reach - gap`` grew by more than ``tol`` over its value at
    ``before`` (or over none). Gaps as ``numpy.linalg.norm`` takes them."""
    n = now.shape[0]
    found_i, found_j, found_deeper = [0][:0], [0][:0], [False][:0]  # empty, typed for numba
    if n < 2:
        return np.array(found_i, np.int64), np.array(found_j, np.int64), np.array(found_deeper)
    lo0, lo1 = now[:, 0].min(), now[:, 1].min()
    span0, span1 = now[:, 0].max() - lo0, now[:, 1].max() - lo1
    side = reach
    while (span0 / side + 3.0) * (span1 / side + 3.0) > 16.0 * n + 1024.0:
        side *= 2.0
    nx, ny = int(span0 / side) + 3, int(span1 / side) + 3
    cell = np.empty(n, np.int64)
    start = np.zeros(nx * ny + 1, np.int64)
    for i in range(n):  # the border cells stay empty
        cell[i] = (int((now[i, 0] - lo0) / side) + 1) * ny + int((now[i, 1] - lo1) / side) + 1
        start[cell[i] + 1] += 1
    for c in range(nx * ny):
        start[c + 1] += start[c]
    members = np.empty(n, np.int64)
    fill = start[:-1].copy()
    for i in range(n):
        members[fill[cell[i]]] = i
        fill[cell[i]] += 1
    for i in range(n):
        for ox in range(-1, 2):
            for oy in range(-1, 2):
                c = cell[i] + ox * ny + oy
                for t in range(start[c], start[c + 1]):
                    j = members[t]
                    if j <= i:
                        continue
                    d0, d1 = now[i, 0] - now[j, 0], now[i, 1] - now[j, 1]
                    depth = reach - math.sqrt(d0 * d0 + d1 * d1)
                    if depth <= 0.0:
                        continue
                    b0, b1 = before[i, 0] - before[j, 0], before[i, 1] - before[j, 1]
                    was = reach - math.sqrt(b0 * b0 + b1 * b1)
                    found_i.append(i)
                    found_j.append(j)
                    found_deeper.append(depth > max(was, 0.0) + tol)
    return (np.array(found_i, np.int64), np.array(found_j, np.int64),
            np.array(found_deeper, np.bool_))


class WallGrid:
    """Which footprint discs (radius ``radius_m``) overlap a wall more at their new centres
    than at their old ones: :meth:`deeper`, one compiled pass over the robots.

    Walls are plan rectangles (centres (W, 2), unit axes as rows (W, 2, 2), half sizes
    (W, 2), metres). A uniform grid of ``WALL_CELL_M`` cells over the walls lists in each
    cell every wall whose bounding box, grown by the radius, meets the cell: a disc that
    reaches a wall has its centre in such a cell, and a centre outside the grid reaches
    none. The depth is computed as the reference ``wall_depth`` of ``tests/test_kinematic.py``
    computes it over arrays, the same operations in the same order (the test checks the
    two against each other, and against every wall, on random poses).
    """

    def __init__(self, centre: np.ndarray, axes: np.ndarray, half: np.ndarray,
                 radius_m: float) -> None:
        self.centre, self.axes, self.half, self.radius_m = centre, axes, half, radius_m
        reach = np.abs(axes).transpose(0, 2, 1) @ half[:, :, None]  # AABB half sizes
        lo = centre - reach[:, :, 0] - radius_m
        hi = centre + reach[:, :, 0] + radius_m
        self.origin = lo.min(axis=0)
        self.shape = (np.floor((hi.max(axis=0) - self.origin) / WALL_CELL_M) + 1).astype(np.int64)
        c0 = np.floor((lo - self.origin) / WALL_CELL_M).astype(np.int64)
        c1 = np.floor((hi - self.origin) / WALL_CELL_M).astype(np.int64)
        cells, owners = [], []
        for w in range(len(centre)):
            xs, ys = np.meshgrid(np.arange(c0[w, 0], c1[w, 0] + 1), np.arange(c0[w, 1], c1[w, 1] + 1))
            cells.append(xs.ravel() * self.shape[1] + ys.ravel())
            owners.append(np.full(xs.size, w))
        cells, owners = np.concatenate(cells), np.concatenate(owners)
        order = np.lexsort((owners, cells))
        self.cell_walls = owners[order].astype(np.int64)
        self.cell_start = np.searchsorted(cells[order], np.arange(self.shape.prod() + 1))

    def deeper(self, before: np.ndarray, now: np.ndarray) -> np.ndarray:
        """Whether each disc (centres ``now`` (N, 2), m) overlaps some wall more than it
        did at ``before`` by over ``OVERLAP_TOL_M``."""
        return _deeper(np.ascontiguousarray(before, float), np.ascontiguousarray(now, float),
                       self.origin, WALL_CELL_M, self.shape, self.cell_start, self.cell_walls,
                       self.centre, self.axes, self.half, self.radius_m, OVERLAP_TOL_M)


@njit(cache=True)
def _depth(x, y, centre, axes, half, w, radius):  # pragma: no cover (compiled)
    """How far (m) the disc centred at ``(x, y)`` reaches into wall ``w`` (negative: the
    gap)."""
    dx, dy = x - centre[w, 0], y - centre[w, 1]
    l0 = abs(axes[w, 0, 0] * dx + axes[w, 0, 1] * dy) - half[w, 0]
    l1 = abs(axes[w, 1, 0] * dx + axes[w, 1, 1] * dy) - half[w, 1]
    outside = math.hypot(max(l0, 0.0), max(l1, 0.0))
    inside = min(max(l0, l1), 0.0)
    return radius - (outside + inside)


@njit(cache=True)
def _deeper(before, now, origin, cell_m, shape, cell_start, cell_walls, centre, axes, half,
            radius, tol):  # pragma: no cover (compiled)
    n = now.shape[0]
    hit = np.zeros(n, np.bool_)
    for i in range(n):
        cx = math.floor((now[i, 0] - origin[0]) / cell_m)
        cy = math.floor((now[i, 1] - origin[1]) / cell_m)
        if cx < 0 or cy < 0 or cx >= shape[0] or cy >= shape[1]:
            continue
        cell = cx * shape[1] + cy
        for k in range(cell_start[cell], cell_start[cell + 1]):
            w = cell_walls[k]
            deep = _depth(now[i, 0], now[i, 1], centre, axes, half, w, radius)
            if deep <= tol:
                continue
            was = _depth(before[i, 0], before[i, 1], centre, axes, half, w, radius)
            if deep > max(was, 0.0) + tol:
                hit[i] = True
                break
    return hit


def _wall_rectangles(m: mujoco.MjModel, d: mujoco.MjData,
                     geom_robot: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The plan rectangles of the static colliding boxes (walls): centres (W, 2), unit
    axes (W, 2, 2) and half sizes (W, 2), all in metres; None without walls. Planes (the
    floor) bound nothing in plan; any other static colliding geom, or a tilted box, is
    not supported and raises :class:`MjswarmError` naming it."""
    static = np.flatnonzero((geom_robot < 0) & ((m.geom_contype != 0) | (m.geom_conaffinity != 0)))
    boxes = []
    for g in static:
        kind = int(m.geom_type[g])
        if kind == mujoco.mjtGeom.mjGEOM_PLANE:
            continue
        name = m.geom(g).name or f"geom {g}"
        if kind != mujoco.mjtGeom.mjGEOM_BOX:
            raise MjswarmError(f"the kinematic tier supports walls that are boxes; "
                               f"'{name}' is a {mujoco.mjtGeom(kind).name}")
        mat = d.geom_xmat[g].reshape(3, 3)
        if not math.isclose(abs(mat[2, 2]), 1.0, abs_tol=1e-9):
            raise MjswarmError(f"the kinematic tier needs upright walls; '{name}' is tilted")
        boxes.append(g)
    if not boxes:
        return None
    mats = d.geom_xmat[boxes].reshape(-1, 3, 3)
    axes = mats[:, :2, :2].transpose(0, 2, 1)  # rows: the box's x and y axes in the world
    return d.geom_xpos[boxes, :2].copy(), axes.copy(), m.geom_size[boxes, :2].copy()


@njit(cache=True)
def _integrate(start, act, ctrl, blend, substeps, h, r, b):  # pragma: no cover (compiled)
    """Steps 1-2 of the module docstring for every robot: the end poses (N, 3), each
    wheel's turn (rad) and speed in the last step (rad/s), and the motor filter states."""
    n = start.shape[0]
    end = start.copy()
    turned = np.zeros((n, 2))
    wheel = act.copy()
    act = act.copy()
    for i in range(n):
        x, y, yaw = start[i, 0], start[i, 1], start[i, 2]
        for _ in range(substeps):
            left, right = act[i, 0], act[i, 1]
            v = r * (left + right) / 2.0
            omega = r * (right - left) / b
            mid = yaw + omega * (h / 2.0)
            x += v * h * math.cos(mid)
            y += v * h * math.sin(mid)
            yaw += omega * h
            turned[i, 0] += left * h
            turned[i, 1] += right * h
            wheel[i, 0], wheel[i, 1] = left, right
            act[i, 0] += (ctrl[i, 0] - left) * blend[i, 0]
            act[i, 1] += (ctrl[i, 1] - right) * blend[i, 1]
        end[i, 0], end[i, 1], end[i, 2] = x, y, yaw
    return end, turned, wheel, act
