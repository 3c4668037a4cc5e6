"""The stepping loop: physics at ~2 ms, sensing and control at a lower rate.

:class:`Simulation` owns one compiled world of N robots (built by
:func:`mjswarm.core.world.world_spec`). Each control tick it

1. writes the wheel-speed commands (rad/s) into ``data.ctrl``,
2. advances physics ``substeps`` steps with ``mj_step(..., nstep=k)``; sensors are read
   once per tick, on the state at the start of the last physics step (at most one
   physics step, 2 ms, old), as MuJoCo's own sensors in that step see it,
3. reads every robot's sensors into one structured array (:meth:`readings`),
4. updates the battery model and the robot-robot collision counter.

Sensing comes in two interchangeable implementations (``sensing=``; the default
``"auto"`` takes ``"mujoco"`` below ``GRID_SENSING_MIN_ROBOTS`` robots, where its O(N^2)
costs less than the grid's fixed per-tick cost, and ``"grid"`` from there on):

* ``"grid"``, O(N): MuJoCo's sensor stage stays disabled; the rangefinders
  declared in the robot model (site, direction = site z axis, ``cutoff``) are cast by
  :class:`mjswarm.core.raycast.RayCaster` against nearby geoms only, and encoders and wheel
  speeds are the wheel joints' ``qpos`` / ``qvel``, which is what MuJoCo's ``jointpos`` /
  ``jointvel`` sensors return. A rangefinder without a cutoff is probed over
  ``UNBOUNDED_PROBE_M`` and, if nothing is there (a tipped robot), re-cast with ``mj_ray``.
* ``"mujoco"``: MuJoCo's sensors, evaluated in the last substep (every rangefinder tests
  every geom: O(N^2)). The reference ``tests/test_raycast.py`` compares against: readings
  are equal within 1e-9 on random states.

Commands are wheel speeds or unicycle ``(v, omega)``; both are vectorised over robots.
Ground-truth accessors (:meth:`poses`) exist for metrics, tests and recordings, never
for controllers. A run is a pure function of the world and the command sequence, plus
``seed`` for the optional sensor noise: bit-identical on one machine.
"""

from __future__ import annotations

import mujoco
import numpy as np

from mjswarm.core.battery import Battery
from mjswarm.core.contacts import CollisionCounter
from mjswarm.core import PHYSICS
from mjswarm.core.kinematic import KinematicDrive
from mjswarm.errors import MjswarmError, one_line
from mjswarm.core.raycast import RayCaster, Rays
from mjswarm.core.robot import (
    ACTUATORS,
    ENCODERS,
    IR_SENSORS,
    LINE_SENSORS,
    ROOT_BODY,
    WHEEL_SPEED_SENSORS,
    measure_geometry,
)
from mjswarm.core.neighbours import Neighbours
from mjswarm.core.sight import LineOfSight
from mjswarm.core.world import Pose2D, quiet_empty_prefix, yaw_quat

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

#: MuJoCo's flag that switches its sensor stage off (as an int: ``opt.disableflags``)
SENSOR_OFF = int(mujoco.mjtDisableBit.mjDSBL_SENSOR)

SENSING = ("auto", "grid", "mujoco")
#: Robot count from which ``sensing="auto"`` casts rays on the grid (``mjswarm bench
#: --sensing grid`` and ``--sensing mujoco`` measure the two; ``docs/performance.md``).
GRID_SENSING_MIN_ROBOTS = 32
#: How far (m) grid sensing looks along a rangefinder that has no cutoff before it asks
#: ``mj_ray``: beyond any line-sensor reading of an upright robot (0.02 m).
UNBOUNDED_PROBE_M = 0.1


def _robot_count(spec: mujoco.MjSpec) -> int:
    """Robots in an uncompiled world: bodies named ``.../ROOT_BODY``."""
    return sum(1 for b in spec.bodies if b.name.endswith(f"/{ROOT_BODY}"))


def _check_options(control_hz: float, line_noise_m: float, ir_noise_m: float,
                   wheel_slip: float, sensing: str, physics: str) -> None:
    """Refuse, in one line, options a :class:`Simulation` cannot run with."""
    if control_hz <= 0:
        raise MjswarmError(f"control rate must be positive, got {control_hz} Hz")
    if line_noise_m < 0 or ir_noise_m < 0:
        raise MjswarmError("sensor noise standard deviations must be >= 0")
    if not 0.0 <= wheel_slip < 1.0:
        raise MjswarmError(f"wheel slip must be in [0, 1), got {wheel_slip}")
    if sensing not in SENSING:
        raise MjswarmError(f"sensing must be one of {', '.join(SENSING)}, got '{sensing}'")
    if physics not in PHYSICS:
        raise MjswarmError(f"physics must be one of {', '.join(PHYSICS)}, got '{physics}'")
    if physics == "kinematic" and sensing == "mujoco":
        raise MjswarmError("the kinematic tier senses with the ray caster: use sensing "
                           "'grid' or 'auto' with physics 'kinematic'")


def _compile(spec: mujoco.MjSpec, physics: str, sensing: str) -> mujoco.MjModel:
    """Compile the world, with MuJoCo's sensors off when the ray caster will sense."""
    flags = spec.option.disableflags
    if physics == "kinematic" or sensing == "grid" or (
            sensing == "auto" and _robot_count(spec) >= GRID_SENSING_MIN_ROBOTS):
        # compiling evaluates every sensor once (mj_setConst steps through mj_forward):
        # for grid sensing, N robots' rangefinders against every geom, O(N^2), that
        # nobody reads (20 s of a 10,000-robot build); the flag is set below anyway
        spec.option.disableflags = flags | SENSOR_OFF
    try:
        with quiet_empty_prefix():  # robots attached in groups (world.attach_robots)
            return spec.compile()
    except ValueError as exc:
        raise MjswarmError(f"world does not compile: {one_line(exc)}") from None
    finally:
        spec.option.disableflags = flags  # the caller's spec as it was


class Simulation:
    """N robots stepping together.

    Args:
        spec: an uncompiled world from :func:`mjswarm.core.world.world_spec` (robots ``r0``...).
        control_hz: control / sensing rate (Hz); must divide the physics rate.
        seed: seeds the sensor noise generator.
        line_noise_m: standard deviation of Gaussian noise added to the line
            rangefinder readings (m) that saw something; 0 by default.
        ir_noise_m: the same for the IR rangefinders (m); 0 by default.
        sensing: ``"grid"`` (O(N) ray casting), ``"mujoco"`` (MuJoCo's sensors) or
            ``"auto"``; see the module docstring.
        wheel_slip: wheel slip seen by the encoders: each control tick, each wheel's
            encoder advances by its true rotation times ``1 + |n|``, ``n ~ N(0,
            wheel_slip)`` (the wheel spun that much more than it rolled); 0 by default.
        physics: ``"dynamic"`` (MuJoCo's contact physics, the default) or ``"kinematic"``
            (robots move by their wheel kinematics and stop at contacts, no constraint
            solve: :mod:`mjswarm.core.kinematic`); the kinematic tier always senses with
            the ray caster (``sensing`` ``"auto"`` or ``"grid"``).
    """

    def __init__(
        self,
        spec: mujoco.MjSpec,
        control_hz: float = 50.0,
        seed: int = 0,
        line_noise_m: float = 0.0,
        ir_noise_m: float = 0.0,
        sensing: str = "auto",
        wheel_slip: float = 0.0,
        physics: str = "dynamic",
    ) -> None:
        _check_options(control_hz, line_noise_m, ir_noise_m, wheel_slip, sensing, physics)
        self.model = _compile(spec, physics, sensing)
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
        self.wheel_slip = wheel_slip
        self._index_robots()
        geom_robot = self._body_robot()[m.geom_bodyid]
        self.geom_robot = geom_robot
        if self.n == 0:
            raise MjswarmError("a simulation needs at least one robot")
        if sensing == "auto":
            kinematic = physics == "kinematic"
            sensing = "grid" if kinematic or self.n >= GRID_SENSING_MIN_ROBOTS else "mujoco"
        self.physics = physics
        self.sensing = sensing
        self.geometry = measure_geometry(m, "r0/")
        self.collisions = CollisionCounter(geom_robot)
        self.battery = Battery(self.n)
        self._slip_rad = np.zeros((self.n, 2))  # encoder over-reading from wheel slip
        self.step_count = 0
        #: changes whenever the world's state does (a step, or the experimenter's hand
        #: through :meth:`set_state` or :meth:`place_robot`; writing ``data.qpos``
        #: directly bypasses it)
        self.state_version = 0
        self._poses_version = -1
        self._sight: LineOfSight | None = None
        #: pairs of robots within a range, one k-d tree per set of positions, shared by the
        #: bearing sensor and the radio (:mod:`mjswarm.core.neighbours`)
        self.neighbours = Neighbours()
        if sensing == "grid":
            m.opt.disableflags |= SENSOR_OFF
            mujoco.mj_kinematics(m, self.data)
        # a world grid sensing cannot cast fails here, in one line
        self._rays = RayCaster(m, self.data, self.robot_bodies, geom_robot) if sensing == "grid" else None
        self._drive = KinematicDrive(self) if physics == "kinematic" else None
        self._no_torque = np.zeros((self.n, 2))
        self._wheel_cmd = np.zeros((self.n, 2))  # set_velocity's buffer
        self._sense_now()

    def _index_robots(self) -> None:
        """Where each robot's actuators, sensors, wheel joints and free joint live in
        the compiled model and its data (robots are attached with prefixes r0/, r1/, ...)."""
        m = self.model

        def ids(obj, names):
            return np.array(
                [[mujoco.mj_name2id(m, obj, f"r{i}/{n}") for n in names] for i in range(self.n)],
                dtype=np.int64,
            ).reshape(self.n, len(names))

        sens = mujoco.mjtObj.mjOBJ_SENSOR
        self._actuators = ids(mujoco.mjtObj.mjOBJ_ACTUATOR, ACTUATORS)
        self._range_ids = ids(sens, LINE_SENSORS + IR_SENSORS)  # (N, 6): line, then IR
        self._range_adr = m.sensor_adr[self._range_ids]
        self._range_cutoff = m.sensor_cutoff[self._range_ids]
        self._range_site = m.sensor_objid[self._range_ids].ravel()
        self._range_length = np.where(self._range_cutoff > 0, self._range_cutoff,
                                      UNBOUNDED_PROBE_M).ravel()
        self._enc_adr = m.sensor_adr[ids(sens, ENCODERS)]
        self._vel_adr = m.sensor_adr[ids(sens, WHEEL_SPEED_SENSORS)]
        wheel_joints = m.sensor_objid[ids(sens, ENCODERS)]
        self._wheel_qpos_adr = m.jnt_qposadr[wheel_joints]
        self._wheel_dof_adr = m.jnt_dofadr[wheel_joints]
        self.robot_bodies = ids(mujoco.mjtObj.mjOBJ_BODY, (ROOT_BODY,))[:, 0]
        joints = m.body_jntadr[self.robot_bodies]
        self._qpos_adr = m.jnt_qposadr[joints]
        self._pose_qpos = self._qpos_adr[:, None] + np.arange(7)  # free joints: xyz, quat

    @property
    def rays(self) -> RayCaster:
        """The O(N) ray caster for this world (rangefinders, bearing line of sight); with
        ``sensing="mujoco"`` built on first use."""
        if self._rays is None:
            self._rays = RayCaster(self.model, self.data, self.robot_bodies, self.geom_robot)
        return self._rays

    @property
    def sight(self) -> LineOfSight:
        """Robot-to-robot line of sight, cast once per state (:mod:`mjswarm.core.sight`)."""
        if self._sight is None:
            self._sight = LineOfSight(self)
        return self._sight

    def _body_robot(self) -> np.ndarray:
        """The robot whose subtree holds each body, -1 for none (bodies come in
        depth-first order, so a parent precedes its children): O(nbody)."""
        m = self.model
        owner = np.full(m.nbody, -1, np.int64)
        owner[self.robot_bodies] = np.arange(self.n)
        own, parent = owner.tolist(), m.body_parentid.tolist()
        for b in range(1, m.nbody):
            if own[b] < 0:
                own[b] = own[parent[b]]
        return np.array(own, np.int64)

    # ------------------------------------------------------------------ commands
    def set_velocity(self, v_m_s: np.ndarray, omega_rad_s: np.ndarray) -> None:
        """Command unicycle velocities: forward ``v`` (m/s) and turn rate ``omega`` (rad/s).

        Differential-drive kinematics: ``w_l = (v - omega b / 2) / r``,
        ``w_r = (v + omega b / 2) / r`` (b track, r wheel radius). A command beyond the
        wheel limit is scaled down as a whole, keeping the path's curvature ``omega / v``.
        """
        g = self.geometry
        v = np.asarray(v_m_s, float)
        w = np.asarray(omega_rad_s, float)
        if v.shape != (self.n,):
            v = np.broadcast_to(v, (self.n,))
        if w.shape != (self.n,):
            w = np.broadcast_to(w, (self.n,))
        # into a buffer kept for it, in the operations (and so the roundings) of
        # wheels = [v - w b / 2, v + w b / 2] / r, scaled down by max / peak where over
        turn = w * g.track_m
        turn /= 2.0
        wheels = self._wheel_cmd
        np.subtract(v, turn, out=wheels[:, 0])
        np.add(v, turn, out=wheels[:, 1])
        wheels /= g.wheel_radius_m
        peak = np.abs(wheels).max(axis=1)
        over = peak > g.max_wheel_speed_rad_s
        if over.any():
            wheels[over] *= (g.max_wheel_speed_rad_s / np.maximum(peak[over], 1e-12))[:, None]
        if not np.isfinite(peak).all():
            raise MjswarmError("wheel speed commands must be finite")
        self.data.ctrl[self._actuators] = wheels

    def place_robot(self, i: int, pose: Pose2D) -> None:
        """Put robot ``i`` down at ``pose``, at rest (the experimenter's hand, not physics)."""
        adr = self._qpos_adr[i]
        dof = self.model.jnt_dofadr[self.model.body_jntadr[self.robot_bodies[i]]]
        q = self.data.qpos
        q[adr:adr + 2] = pose.x, pose.y
        q[adr + 3:adr + 7] = yaw_quat(pose.yaw)
        self.data.qvel[dof:dof + 6] = 0.0
        self.data.ctrl[self._actuators[i]] = 0.0
        self.data.act[self.model.actuator_actadr[self._actuators[i]]] = 0.0  # motor ramp
        self._sense_now()

    def set_state(self, qpos: np.ndarray, qvel: np.ndarray) -> None:
        """Put the whole world in a given state (the experimenter's hand) and sense it."""
        m = self.model
        qpos, qvel = np.asarray(qpos, float), np.asarray(qvel, float)
        if qpos.shape != (m.nq,) or qvel.shape != (m.nv,):
            raise MjswarmError(f"state needs qpos of shape ({m.nq},) and qvel of shape ({m.nv},), "
                               f"got {qpos.shape} and {qvel.shape}")
        self.data.qpos[:], self.data.qvel[:] = qpos, qvel
        self._sense_now()

    def _sense_now(self) -> None:
        """Recompute kinematics (and MuJoCo's sensors, if on) and read every sensor."""
        if self._drive is not None:  # nothing to solve: positions are all there is
            mujoco.mj_kinematics(self.model, self.data)
        else:
            mujoco.mj_forward(self.model, self.data)
        self.state_version += 1
        self._wheels = self._wheel_state()
        self._readings = self._read_sensors()

    # ------------------------------------------------------------------ stepping
    def step(self, ticks: int = 1) -> None:
        """Advance ``ticks`` control periods (each ``substeps`` physics steps, or one
        kinematic tick of as long in the kinematic tier)."""
        m, d = self.model, self.data
        for _ in range(ticks):
            if self._drive is not None:
                touching = self._drive.step(self.substeps)
                self._wheels = self._wheel_state()
                torque = self._no_torque
            else:
                if self.substeps > 1:
                    m.opt.disableflags |= SENSOR_OFF
                    mujoco.mj_step(m, d, nstep=self.substeps - 1)
                    if self.sensing == "mujoco":
                        m.opt.disableflags &= ~SENSOR_OFF
                if self.sensing == "grid":
                    self._wheels = self._wheel_state()  # the state the last step's sensors see
                mujoco.mj_step(m, d)
                touching = self.collisions.touching_pairs(d)
                torque = d.actuator_force[self._actuators]
            self.step_count += 1
            self.state_version += 1
            self.battery.update(torque, self.control_dt_s)
            self.collisions.record(float(d.time), touching)
            previous = self._readings["encoder"] if self.wheel_slip else None
            self._readings = self._read_sensors()
            if self.wheel_slip:
                turned = self._readings["encoder"] - previous
                slip = np.abs(self.rng.normal(0.0, self.wheel_slip, turned.shape)) * turned
                self._slip_rad += slip
                self._readings["encoder"] += slip

    def _wheel_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Wheel angles (rad) and speeds (rad/s) now: the encoders' ``qpos`` / ``qvel``."""
        return self.data.qpos[self._wheel_qpos_adr], self.data.qvel[self._wheel_dof_adr]

    def _rangefinders(self) -> np.ndarray:
        """Every rangefinder's distance (m), shape (N, 6) line then IR; NaN = nothing.

        A hit at or beyond a sensor's cutoff is nothing, as is MuJoCo's miss (-1, or
        -cutoff after its clamp).
        """
        m, d = self.model, self.data
        cutoff = self._range_cutoff
        if self.sensing == "mujoco":
            raw = d.sensordata[self._range_adr]
        else:
            site = self._range_site
            rays = Rays(d.site_xpos[site], d.site_xmat[site][:, 2::3], self._range_length, m.site_bodyid[site])
            dist, _ = self.rays.cast(rays)
            for k in np.flatnonzero((dist < 0) & (cutoff.ravel() <= 0)):
                dist[k] = mujoco.mj_ray(m, d, rays.origin[k], rays.direction[k], None, 1,
                                        int(rays.exclude_body[k]), np.zeros(1, np.int32))
            raw = dist.reshape(self._range_ids.shape)
        return np.where((raw >= 0) & ((cutoff <= 0) | (raw < cutoff)), raw, np.nan)

    def _read_sensors(self) -> np.ndarray:
        out = np.empty(self.n, dtype=READING_DTYPE)
        ranges = self._rangefinders()
        line, ir = ranges[:, :3], ranges[:, 3:]
        if self.line_noise_m:
            line = line + self.rng.normal(0.0, self.line_noise_m, line.shape)
        if self.ir_noise_m:
            ir = ir + self.rng.normal(0.0, self.ir_noise_m, ir.shape)
        out["line"] = line
        out["ir"] = ir
        if self.sensing == "mujoco":
            sd = self.data.sensordata
            out["encoder"], out["wheel_speed"] = sd[self._enc_adr], sd[self._vel_adr]
        else:
            out["encoder"], out["wheel_speed"] = self._wheels
        if self.wheel_slip:
            out["encoder"] += self._slip_rad
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
        """Ground-truth planar poses, shape (N, 3): x (m), y (m), yaw (rad). Not for controllers.

        Computed once per state (``state_version``); each call returns a fresh copy."""
        if self._poses_version != self.state_version:
            q = self.data.qpos[self._pose_qpos]
            w, x, y, z = q[:, 3], q[:, 4], q[:, 5], q[:, 6]
            poses = np.empty((self.n, 3))
            poses[:, :2] = q[:, :2]
            poses[:, 2] = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
            self._poses = poses
            self._poses_version = self.state_version
        return self._poses.copy()

    def warnings(self) -> dict[str, int]:
        """MuJoCo warnings raised so far, by name (empty when none)."""
        return {
            mujoco.mjtWarning(i).name: int(w.number)
            for i, w in enumerate(self.data.warning)
            if w.number > 0
        }

