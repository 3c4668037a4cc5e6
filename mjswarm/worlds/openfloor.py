"""Open-floor worlds for the connectivity-maintenance experiments 
(Kobayashi et al.; Ahmadi & Stone).

Two :class:`~mjswarm.worlds.loop.World` s with one implementation, :class:`MotionWorld`, so the
same controllers run on MuJoCo robots (:class:`EmbodiedFloor`) and on kinematic points
(:class:`PointWorld`):

* robots command **planar velocities** (m/s, world frame; ``Command.velocity_m_s``) that
  the unicycle tracker of :mod:`algorithms.motion` follows within the Spark V's limits
  (the robot model's top speed, ``omega_max``), or ``(v, omega)`` directly;
* robots **sense their own position and heading** through a positioning sensor (the
  papers assume robots know their positions; think UWB or motion capture) with optional
  Gaussian noise (``Observation.pose``);
* with ``detection_range_m``, a **range-and-bearing sensor** reports every present robot
  within that range (Kobayashi et al.: "the robots can identify other robots in range d_s"):
  exact range (m) and bearing (rad, in the observer's frame) from the true poses, and the
  signal that robot last showed (``Command.signal``; Kobayashi et al.'s robots tell roles apart,
  our choice is that each shows its role, as an LED colour would);
* robots can be **added and removed** (Ahmadi & Stone's episodes): an absent robot waits in a
  depot outside the floor (embodied) and is invisible to the radio and the sensors.

Ground truth (:meth:`MotionWorld.true_positions`) is for loop functions, metrics and tests.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Sequence

import numpy as np

from algorithms.motion import track_velocity
from algorithms.robot import Command, Detection, Observation
from mjswarm.errors import MjswarmError
from mjswarm.worlds.loop import World

#: The turn rate we allow the tracker (rad/s); the top speed is the robot model's.
OMEGA_MAX_RAD_S = 2.0
#: Longest integration step of the point world, and longest sensing period of the
#: MuJoCo floor (s): the Spark V's 50 Hz control rate.
MAX_SUBSTEP_S = 0.02


def whole_steps(period_s: float, step_s: float, what: str) -> int:
    """How many ``step_s`` make ``period_s``; :class:`MjswarmError` unless a whole number
    (a world integrates exactly its control period, never a rounded one)."""
    ratio = period_s / step_s
    steps = round(ratio)
    if steps < 1 or abs(ratio - steps) > 1e-6:
        raise MjswarmError(f"control period {period_s:g} s is not a whole number of the "
                           f"{what} step {step_s:g} s")
    return steps


def substeps(period_s: float, step_s: float, what: str) -> tuple[int, int]:
    """``period_s`` as ``(ticks, steps)``: ``ticks`` sub-periods of ``steps`` steps of
    ``step_s`` each, the sub-period the longest not over :data:`MAX_SUBSTEP_S`."""
    n = whole_steps(period_s, step_s, what)
    k = max(d for d in range(1, n + 1) if n % d == 0 and d * step_s <= MAX_SUBSTEP_S + 1e-12) \
        if step_s <= MAX_SUBSTEP_S else n
    return n // k, k


class MotionWorld(World, ABC):
    """N robots on an open floor (module docstring).

    Args:
        positions: start positions (m), one per robot; ``present`` says which are on the
            floor (the rest wait in the depot).
        seed: seeds the position-sensor noise.
        position_noise_m: standard deviation of the positioning sensor's position (m).
        heading_noise_rad: standard deviation of its heading (rad).
        omega_max_rad_s: turn-rate cap of the velocity tracker (a paper may set its own).
        control_dt_s: the control period (s) of :meth:`step`.
        detection_range_m: range of the range-and-bearing sensor (m); None: no sensor.
    """

    def __init__(self, positions: Sequence[tuple[float, float]], present: Sequence[bool] | None,
                 seed: int, position_noise_m: float, heading_noise_rad: float,
                 omega_max_rad_s: float = OMEGA_MAX_RAD_S, control_dt_s: float = 0.1,
                 detection_range_m: float | None = None) -> None:
        if len(positions) < 1:
            raise MjswarmError("an open-floor world needs at least one robot")
        if position_noise_m < 0 or heading_noise_rad < 0:
            raise MjswarmError("sensor noise standard deviations must be >= 0")
        self.n = len(positions)
        self.present = np.ones(self.n, bool) if present is None else np.array(present, bool)
        self.rng = np.random.default_rng(seed)
        self.position_noise_m, self.heading_noise_rad = position_noise_m, heading_noise_rad
        if omega_max_rad_s <= 0:
            raise MjswarmError(f"turn-rate cap must be positive, got {omega_max_rad_s} rad/s")
        self.omega_max_rad_s = omega_max_rad_s
        if not control_dt_s > 0:
            raise MjswarmError(f"control period must be positive, got {control_dt_s} s")
        self.control_dt_s = control_dt_s
        self.detection_range_m = detection_range_m
        self._time_s = 0.0
        self._commands: list[Command] = [Command()] * self.n
        self.signals: list = [None] * self.n
        self.uplinks = {}
        self._speeds = np.zeros(self.n)
        self._sensed: np.ndarray | None = None  # this tick's positioning-sensor readings
        self._detections: list[dict] | None = None

    @property
    def time_s(self) -> float:
        return self._time_s

    @abstractmethod
    def _advance(self, v: np.ndarray, omega: np.ndarray) -> None:
        """Drive every present robot with ``(v, omega)`` for one control period."""

    def place(self, i: int, xy: tuple[float, float] | None, yaw: float = 0.0) -> None:
        """Put robot ``i`` on the floor at ``xy`` (m) heading ``yaw`` (rad), or take it off
        (``None``): the experimenter's hand. It is on the air exactly while on the floor."""
        self.departures += bool(self.present[i]) and xy is None
        self.present[i] = xy is not None
        self._put(i, xy, yaw)
        self._sensed = self._detections = None
        self.set_on_air(i, xy is not None)
        self.relink()

    @abstractmethod
    def _put(self, i: int, xy: tuple[float, float] | None, yaw: float) -> None:
        """Move robot ``i``'s body to ``xy`` (or to the depot for ``None``)."""

    def true_positions(self) -> np.ndarray:
        return self.true_poses()[:, :2]

    def sense(self) -> np.ndarray:
        """Each robot's positioning-sensor reading, shape (N, 3): x, y (m), yaw (rad)."""
        poses = self.true_poses().copy()
        if self.position_noise_m:
            poses[:, :2] += self.rng.normal(0.0, self.position_noise_m, (self.n, 2))
        if self.heading_noise_rad:
            poses[:, 2] += self.rng.normal(0.0, self.heading_noise_rad, self.n)
        return poses

    # -- the World surface ---------------------------------------------------------------
    def observe(self, i: int) -> Observation:
        """Robot ``i``'s positioning sensor, range-and-bearing sensor and radio."""
        if self._sensed is None:  # one reading of every sensor per tick
            self._sensed = self.sense()
        inbox, neighbors = self._inbox(i)
        return Observation(i, self._time_s, pose=tuple(self._sensed[i].tolist()),
                           detections=self._detected(i), inbox=inbox, neighbors=neighbors)

    def act(self, i: int, command: Command) -> None:
        self._commands[i] = command
        if command.signal is not None:
            self.signals[i] = command.signal
        self._send(i, command.messages)

    def step(self) -> None:
        """Follow every present robot's command for one control period, then the radio.
        The velocity tracker (the robot's own motion control) steers by the positioning
        reading the robot observed this tick: one reading per tick."""
        from mjswarm.core.robot import spark_v_geometry  # loads MuJoCo

        if self._sensed is None:
            self._sensed = self.sense()
        sensed = self._sensed
        v_max = spark_v_geometry().max_speed_m_s
        v, omega = np.zeros(self.n), np.zeros(self.n)
        for i, c in enumerate(self._commands):
            if not self.present[i]:
                continue
            if c.velocity_m_s is not None:
                v[i], omega[i] = track_velocity(sensed[i, 2], np.asarray(c.velocity_m_s, float),
                                                v_max, self.omega_max_rad_s)
            else:
                v[i], omega[i] = c.v_m_s, c.omega_rad_s
        self._advance(v, omega)
        self._speeds = v
        self._time_s += self.control_dt_s
        self._sensed = self._detections = None
        self._radio_step()

    def commanded_speeds(self) -> np.ndarray:
        return self._speeds.copy()

    def show(self, i: int, signal) -> None:
        """The experimenter sets what robot ``i`` shows (e.g. its initial role)."""
        self.signals[i] = signal

    def _detected(self, i: int) -> dict[int, Detection]:
        if self.detection_range_m is None:
            return {}
        if self._detections is None:
            poses = self.true_poses()
            here = np.flatnonzero(self.present)
            d = poses[here, None, :2] - poses[None, here, :2]  # d[a, b] = x_a - x_b
            dist = np.hypot(d[..., 0], d[..., 1])
            self._detections = [{} for _ in range(self.n)]
            for a, b in zip(*np.nonzero(dist <= self.detection_range_m)):
                if a == b:
                    continue
                i_, k = int(here[a]), int(here[b])
                bearing = math.remainder(math.atan2(-d[a, b, 1], -d[a, b, 0]) - poses[i_, 2],
                                         2 * math.pi)
                self._detections[i_][k] = Detection(float(dist[a, b]), bearing, self.signals[k])
        return self._detections[i]


class PointWorld(MotionWorld):
    """Kinematic unicycles: Euler integration of ``(v, omega)`` in steps of ``dt_s``
    (default: the longest step up to :data:`MAX_SUBSTEP_S` that divides the control
    period), no bodies, no contacts. A ``dt_s`` that does not divide the control period
    is refused."""

    def __init__(self, positions, present=None, seed=0, position_noise_m=0.0,
                 heading_noise_rad=0.0, dt_s: float | None = None,
                 omega_max_rad_s: float = OMEGA_MAX_RAD_S, control_dt_s: float = 0.1,
                 detection_range_m: float | None = None) -> None:
        super().__init__(positions, present, seed, position_noise_m, heading_noise_rad,
                         omega_max_rad_s, control_dt_s, detection_range_m)
        if dt_s is None:
            dt_s = control_dt_s / math.ceil(control_dt_s / MAX_SUBSTEP_S - 1e-9)
        elif not dt_s > 0:
            raise MjswarmError(f"integration step must be positive, got {dt_s} s")
        self._steps = whole_steps(control_dt_s, dt_s, "integration")
        self.dt_s = dt_s
        self._poses = np.zeros((self.n, 3))
        self._poses[:, :2] = np.asarray(positions, float)

    def true_poses(self) -> np.ndarray:
        return self._poses

    def _put(self, i, xy, yaw) -> None:
        if xy is not None:
            self._poses[i] = (xy[0], xy[1], yaw)

    def _advance(self, v, omega) -> None:
        for _ in range(self._steps):
            yaw = self._poses[:, 2]
            self._poses[:, 0] += v * np.cos(yaw) * self.dt_s
            self._poses[:, 1] += v * np.sin(yaw) * self.dt_s
            self._poses[:, 2] = yaw + omega * self.dt_s


class EmbodiedFloor(MotionWorld):
    """Spark V robots in MuJoCo on a bare floor; absent robots wait in a depot row.

    ``floor_half_size_m`` sizes the floor around the origin; the depot lies beyond it.
    Robot-robot contacts are counted in ``self.sim.collisions``. The control period must
    be a whole number of physics steps; the simulation senses (and counts contacts)
    every sub-period of at most :data:`MAX_SUBSTEP_S` that divides it (0.1 s: five
    0.02 s periods; 0.15 s: fifteen of 0.01 s).
    """

    def __init__(self, positions, present=None, seed=0, position_noise_m=0.0,
                 heading_noise_rad=0.0, floor_half_size_m: float = 10.0,
                 omega_max_rad_s: float = OMEGA_MAX_RAD_S, control_dt_s: float = 0.1,
                 detection_range_m: float | None = None) -> None:
        from mjswarm.core.simulation import Simulation
        from mjswarm.core.world import PHYSICS_TIMESTEP_S, Pose2D, world_spec

        super().__init__(positions, present, seed, position_noise_m, heading_noise_rad,
                         omega_max_rad_s, control_dt_s, detection_range_m)
        self._ticks, steps = substeps(control_dt_s, PHYSICS_TIMESTEP_S, "physics")
        self._depot = [(-floor_half_size_m + 0.4 * i, -floor_half_size_m - 1.0)
                       for i in range(self.n)]
        poses = [Pose2D(*(positions[i] if self.present[i] else self._depot[i]), 0.0)
                 for i in range(self.n)]
        corners = [(-floor_half_size_m, -floor_half_size_m),
                   (floor_half_size_m, floor_half_size_m)]
        spec = world_spec(poses, margin_m=1.5, floor_points=corners)
        self._pose_type = Pose2D
        self.sim = Simulation(spec, seed=seed, control_hz=1.0 / (steps * PHYSICS_TIMESTEP_S))

    def true_poses(self) -> np.ndarray:
        return self.sim.poses()

    def _put(self, i, xy, yaw) -> None:
        where = xy if xy is not None else self._depot[i]
        self.sim.place_robot(i, self._pose_type(where[0], where[1], yaw))

    def contact_events(self) -> list[tuple[float, int, int]]:
        return self.sim.collisions.events

    def _advance(self, v, omega) -> None:
        self.sim.set_velocity(v, omega)
        self.sim.step(self._ticks)


def spread(n: int, radius_m: float, seed: int) -> list[tuple[float, float]]:
    """``n`` random positions in a disc of ``radius_m`` at least 0.2 m apart (a helper for
    tests and experiments; raises :class:`MjswarmError` if they do not fit)."""
    rng = np.random.default_rng(seed)
    points: list[tuple[float, float]] = []
    for _ in range(1000 * n):
        if len(points) == n:
            return points
        r, a = radius_m * math.sqrt(rng.uniform()), rng.uniform(0, 2 * math.pi)
        p = (r * math.cos(a), r * math.sin(a))
        if all(math.dist(p, q) >= 0.2 for q in points):
            points.append(p)
    raise MjswarmError(f"cannot place {n} robots 0.2 m apart in a {radius_m} m disc")
