"""The stepping loop: physics at ~2 ms, sensing and control at a lower rate.

:class:`Simulation` owns one compiled world of N robots (built by
:func:`mjswarm.world.world_spec`). Each control tick it

1. writes the wheel-speed commands (rad/s) into ``data.ctrl``,
2. advances physics ``substeps`` steps with ``mj_step(..., nstep=k)``; sensors are
   disabled for all but the last physics step, so rangefinders (the expensive sensors)
   are evaluated once per tick, on the state at the start of that last step (at most one
   physics step, 2 ms, old),
3. reads every robot's sensors into one structured array (:meth:`readings`),
4. updates the battery model and the robot-robot collision counter.

Commands are wheel speeds or unicycle ``(v, omega)``; both are vectorised over robots.
Ground-truth accessors (:meth:`poses`) exist for metrics, tests and recordings, never
for controllers. A run is a pure function of the world and the command sequence, plus
``seed`` for the optional sensor noise: bit-identical on one machine.
"""

from __future__ import annotations

import mujoco
import numpy as np

from mjswarm.battery import Battery
from mjswarm.contacts import CollisionCounter
from mjswarm.errors import MjswarmError, one_line
from mjswarm.robot import (
    ACTUATORS,
    ENCODERS,
    IR_SENSORS,
    LINE_SENSORS,
    ROOT_BODY,
    WHEEL_SPEED_SENSORS,
    measure_geometry,
)
from mjswarm.world import Pose2D, yaw_quat

#: One robot's sensor record: line rangefinders (m), IR distances (m, NaN = nothing
#: within range), wheel encoders (rad), wheel speeds (rad/s), battery voltage (V).
READING_DTYPE = np.dtype(
    [
        ("line", np.float64, (3,)),
        ("ir", np.float64, (3,)),
        ("encoder", np.float64, (2,)),
        ("wheel_speed", np.float64, (2,)),
        ("battery", np.float64),
    ]
)


class Simulation:
    """N robots stepping together.

    Args:
        spec: an uncompiled world from :func:`mjswarm.world.world_spec` (robots ``r0``...).
        control_hz: control / sensing rate (Hz); must divide the physics rate.
        seed: seeds the sensor noise generator.
        line_noise_m, ir_noise_m: standard deviation of Gaussian noise added to the line
            and IR rangefinder readings (m); 0 by default.
    """

    def __init__(
        self,
        spec: mujoco.MjSpec,
        control_hz: float = 50.0,
        seed: int = 0,
        line_noise_m: float = 0.0,
        ir_noise_m: float = 0.0,
    ) -> None:
        if control_hz <= 0:
            raise MjswarmError(f"control rate must be positive, got {control_hz} Hz")
        if line_noise_m < 0 or ir_noise_m < 0:
            raise MjswarmError("sensor noise standard deviations must be >= 0")
        try:
            self.model = spec.compile()
        except ValueError as exc:
            raise MjswarmError(f"world does not compile: {one_line(exc)}") from None
        self.data = mujoco.MjData(self.model)
        m = self.model
        self.n = sum(1 for b in range(m.nbody) if m.body(b).name.endswith(f"/{ROOT_BODY}"))
        ratio = 1.0 / (control_hz * m.opt.timestep)
        self.substeps = round(ratio)
        if self.substeps < 1 or abs(ratio - self.substeps) > 1e-6:
            raise MjswarmError(
                f"control rate {control_hz} Hz must divide the physics rate "
                f"{1.0 / m.opt.timestep:g} Hz"
            )
        self.control_dt_s = self.substeps * m.opt.timestep
        self.rng = np.random.default_rng(seed)
        self.line_noise_m, self.ir_noise_m = line_noise_m, ir_noise_m

        def ids(obj, names):
            return np.array(
                [[mujoco.mj_name2id(m, obj, f"r{i}/{n}") for n in names] for i in range(self.n)],
                dtype=np.int64,
            ).reshape(self.n, len(names))

        sens = mujoco.mjtObj.mjOBJ_SENSOR
        self._actuators = ids(mujoco.mjtObj.mjOBJ_ACTUATOR, ACTUATORS)
        self._line_adr = m.sensor_adr[ids(sens, LINE_SENSORS)]
        self._ir_adr = m.sensor_adr[ids(sens, IR_SENSORS)]
        self._enc_adr = m.sensor_adr[ids(sens, ENCODERS)]
        self._vel_adr = m.sensor_adr[ids(sens, WHEEL_SPEED_SENSORS)]
        self._ir_cutoff = m.sensor_cutoff[ids(sens, IR_SENSORS)]
        self.robot_bodies = ids(mujoco.mjtObj.mjOBJ_BODY, (ROOT_BODY,))[:, 0]
        joints = m.body_jntadr[self.robot_bodies]
        self._qpos_adr = m.jnt_qposadr[joints]
        geom_robot = np.full(m.ngeom, -1, dtype=np.int64)
        for i, root in enumerate(self.robot_bodies):
            geom_robot[np.isin(m.geom_bodyid, self._subtree(root))] = i
        self.geom_robot = geom_robot
        if self.n == 0:
            raise MjswarmError("a simulation needs at least one robot")
        self.geometry = measure_geometry(m, "r0/")
        self.collisions = CollisionCounter(geom_robot)
        self.battery = Battery(self.n)
        self.step_count = 0
        mujoco.mj_forward(m, self.data)
        self._readings = self._read_sensors()

    def _subtree(self, root: int) -> np.ndarray:
        """Body ids of ``root`` and all its descendants."""
        m = self.model
        inside = np.zeros(m.nbody, bool)
        inside[root] = True
        for b in range(root + 1, m.nbody):
            inside[b] = inside[m.body_parentid[b]]
        return np.flatnonzero(inside)

    # ------------------------------------------------------------------ commands
    def set_wheel_speeds(self, omega_rad_s: np.ndarray) -> None:
        """Command wheel angular speeds (rad/s), shape (N, 2) as (left, right).

        The velocity actuators clamp each wheel to +-``max_wheel_speed_rad_s``, so no
        robot exceeds its top speed (20 cm/s).
        """
        omega = np.asarray(omega_rad_s, dtype=np.float64).reshape(self.n, 2)
        if not np.all(np.isfinite(omega)):
            raise MjswarmError("wheel speed commands must be finite")
        self.data.ctrl[self._actuators] = omega

    def set_velocity(self, v_m_s: np.ndarray, omega_rad_s: np.ndarray) -> None:
        """Command unicycle velocities: forward ``v`` (m/s) and turn rate ``omega`` (rad/s).

        Differential-drive kinematics: ``w_l = (v - omega b / 2) / r``,
        ``w_r = (v + omega b / 2) / r`` (b track, r wheel radius). A command beyond the
        wheel limit is scaled down as a whole, keeping the path's curvature ``omega / v``.
        """
        g = self.geometry
        v = np.broadcast_to(np.asarray(v_m_s, float), (self.n,))
        w = np.broadcast_to(np.asarray(omega_rad_s, float), (self.n,))
        wheels = np.stack([v - w * g.track_m / 2.0, v + w * g.track_m / 2.0], axis=1)
        wheels /= g.wheel_radius_m
        peak = np.abs(wheels).max(axis=1, keepdims=True)
        scale = np.where(peak > g.max_wheel_speed_rad_s, g.max_wheel_speed_rad_s / np.maximum(peak, 1e-12), 1.0)
        self.set_wheel_speeds(wheels * scale)

    def place_robot(self, i: int, pose: Pose2D) -> None:
        """Put robot ``i`` down at ``pose``, at rest (the experimenter's hand, not physics)."""
        adr = self._qpos_adr[i]
        dof = self.model.jnt_dofadr[self.model.body_jntadr[self.robot_bodies[i]]]
        q = self.data.qpos
        q[adr:adr + 2] = pose.x, pose.y
        q[adr + 3:adr + 7] = yaw_quat(pose.yaw)
        self.data.qvel[dof:dof + 6] = 0.0
        self.data.ctrl[self._actuators[i]] = 0.0
        mujoco.mj_forward(self.model, self.data)  # sensors see the robot where it now is
        self._readings = self._read_sensors()

    # ------------------------------------------------------------------ stepping
    def step(self, ticks: int = 1) -> None:
        """Advance ``ticks`` control periods (each ``substeps`` physics steps)."""
        m, d = self.model, self.data
        sensor_bit = int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
        for _ in range(ticks):
            if self.substeps > 1:
                m.opt.disableflags |= sensor_bit
                mujoco.mj_step(m, d, nstep=self.substeps - 1)
                m.opt.disableflags &= ~sensor_bit
            mujoco.mj_step(m, d)
            self.step_count += 1
            self.battery.update(d.actuator_force[self._actuators], self.control_dt_s)
            self.collisions.update(d)
            self._readings = self._read_sensors()

    def _read_sensors(self) -> np.ndarray:
        sd = self.data.sensordata
        out = np.empty(self.n, dtype=READING_DTYPE)
        line = sd[self._line_adr]
        ir = sd[self._ir_adr]
        if self.line_noise_m:
            line = line + self.rng.normal(0.0, self.line_noise_m, line.shape)
        if self.ir_noise_m:
            ir = ir + self.rng.normal(0.0, self.ir_noise_m, ir.shape)
        # MuJoCo reads -cutoff on a miss and +cutoff for a hit beyond range: both "nothing".
        out["line"] = line
        out["ir"] = np.where((ir >= 0.0) & (ir < self._ir_cutoff), ir, np.nan)
        out["encoder"] = sd[self._enc_adr]
        out["wheel_speed"] = sd[self._vel_adr]
        out["battery"] = self.battery.voltage_v
        return out

    def readings(self) -> np.ndarray:
        """Every robot's latest sensor record, shape (N,), dtype :data:`READING_DTYPE`."""
        return self._readings

    # ------------------------------------------------------------------ ground truth
    @property
    def time_s(self) -> float:
        """Simulated time (s)."""
        return float(self.data.time)

    def poses(self) -> np.ndarray:
        """Ground-truth planar poses, shape (N, 3): x (m), y (m), yaw (rad). Not for controllers."""
        q = self.data.qpos
        adr = self._qpos_adr
        xy = np.stack([q[adr], q[adr + 1]], axis=1)
        w, x, y, z = (q[adr + k] for k in range(3, 7))
        yaw = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
        return np.column_stack([xy, yaw])

    def heights(self) -> np.ndarray:
        """Ground-truth axle heights (m), shape (N,)."""
        return self.data.qpos[self._qpos_adr + 2].copy()

    def uprightness(self) -> np.ndarray:
        """Cosine of each chassis's tilt from vertical, shape (N,) (1 = upright)."""
        return self.data.xmat[self.robot_bodies][:, 8].copy()

    def warnings(self) -> dict[str, int]:
        """MuJoCo warnings raised so far, by name (empty when none)."""
        return {
            mujoco.mjtWarning(i).name: int(w.number)
            for i, w in enumerate(self.data.warning)
            if w.number > 0
        }

