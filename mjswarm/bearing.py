"""The bearing sensor: which other robots a robot sees, and at what bearing.

Modelled on an omnidirectional IR beacon receiver with robot identification (each
robot's beacon is modulated with its id): robot ``k`` sees robot ``p`` when ``p`` is within
``range_m`` and inside the field of view ``|beta| <= fov_rad`` around ``k``'s heading, and
nothing blocks the line of sight (an ``mj_ray`` from ``k``'s centre, at ``RAY_HEIGHT_M``,
towards ``p`` hits ``p`` first; only collision geoms, group 0, block: walls and robots).
The reading is ``beta_kp``: the angle from ``k``'s heading to ``p`` (rad, CCW positive),
plus optional Gaussian noise. Defaults: +-60 degrees, 1 m.

Sampled at the control rate from the simulated world; controllers receive only
``{p: beta_kp}``.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from mjswarm.simulation import Simulation

RAY_HEIGHT_M = 0.06  # above the wheels (0.05 m), inside the chassis (0.012..0.07 m)
DEFAULT_FOV_RAD = math.radians(60.0)
DEFAULT_RANGE_M = 1.0


class BearingSensor:
    """Bearings of visible robots for every robot of a simulation."""

    def __init__(self, sim: Simulation, fov_rad: float = DEFAULT_FOV_RAD,
                 range_m: float = DEFAULT_RANGE_M, noise_rad: float = 0.0,
                 seed: int = 0) -> None:
        if not 0.0 < fov_rad <= math.pi or range_m <= 0.0 or noise_rad < 0.0:
            raise ValueError("bearing sensor needs 0 < fov <= pi, range > 0, noise >= 0")
        self.sim = sim
        self.fov_rad, self.range_m, self.noise_rad = fov_rad, range_m, noise_rad
        self.rng = np.random.default_rng(seed)

    def read(self, poses: np.ndarray | None = None) -> list[dict[int, float]]:
        """For every robot ``k``: ``{p: beta_kp}`` (rad) of the robots it sees now."""
        sim = self.sim
        poses = sim.poses() if poses is None else poses
        n = len(poses)
        diff = poses[None, :, :2] - poses[:, None, :2]  # [k, p] = p - k
        dist = np.hypot(diff[..., 0], diff[..., 1])
        beta = np.arctan2(diff[..., 1], diff[..., 0]) - poses[:, None, 2]
        beta = np.arctan2(np.sin(beta), np.cos(beta))
        candidates = (dist <= self.range_m) & (np.abs(beta) <= self.fov_rad)
        np.fill_diagonal(candidates, False)
        out: list[dict[int, float]] = [{} for _ in range(n)]
        for k, p in zip(*np.nonzero(candidates)):
            if line_of_sight(sim, k, p, poses):
                noise = self.rng.normal(0.0, self.noise_rad) if self.noise_rad else 0.0
                out[k][int(p)] = float(beta[k, p] + noise)
        return out


_GROUP0 = np.array([1, 0, 0, 0, 0, 0], dtype=np.uint8)


def line_of_sight(sim: Simulation, k: int, p: int, poses: np.ndarray | None = None) -> bool:
    """Whether robot ``p`` is the first thing a ray from robot ``k``'s centre towards it
    hits (collision geoms only, at RAY_HEIGHT_M): walls and other robots block."""
    poses = sim.poses() if poses is None else poses
    start = np.array([poses[k, 0], poses[k, 1], RAY_HEIGHT_M])
    vec = np.array([poses[p, 0] - poses[k, 0], poses[p, 1] - poses[k, 1], 0.0])
    geomid = np.zeros(1, dtype=np.int32)
    mujoco.mj_ray(sim.model, sim.data, start, vec, _GROUP0, 1, int(sim.robot_bodies[k]), geomid)
    return geomid[0] >= 0 and sim.geom_robot[geomid[0]] == p
