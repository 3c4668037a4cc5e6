"""The bearing sensor: which other robots a robot sees, and at what bearing.

Modelled on an omnidirectional IR beacon receiver with robot identification (each
robot's beacon is modulated with its id): robot ``k`` sees robot ``p`` when ``p`` is within
``range_m`` and inside the field of view ``|beta| <= fov_rad`` around ``k``'s heading, and
nothing blocks the line of sight (:mod:`mjswarm.core.sight`: a ray from ``k``'s centre towards
``p`` hits ``p`` first; only collision geoms block: robots, walls, the floor).
The reading is ``beta_kp``: the angle from ``k``'s heading to ``p`` (rad, CCW positive),
plus optional Gaussian noise. Defaults: +-60 degrees, 1 m.

Sampled at the control rate from the simulated world; controllers receive only
``{p: beta_kp}``. O(N) for bounded density: the pairs in range are the simulation's
:attr:`~mjswarm.core.simulation.Simulation.neighbours` (one k-d tree per state, shared with
the radio; ``|p - k|^2 <= range_m^2`` exactly), and line of sight is the simulation's
:attr:`~mjswarm.core.simulation.Simulation.sight`, cast once per state and shared with the radio.
From ``QUICK_WRAP_FROM`` pairs on, the field of view is tested in two steps: a cheap wrap
of the bearing (``round``, a multiple of 2 pi) keeps the pairs within ``fov_rad +
FOV_MARGIN_RAD``, and the reading's own wrap (``atan2(sin, cos)``, the one the controllers
receive) decides on those alone, so the sine and cosine of pairs far outside the field of
view are never taken.
"""

from __future__ import annotations

import math

import numpy as np

from mjswarm.core.simulation import Simulation

DEFAULT_FOV_RAD = math.radians(60.0)
DEFAULT_RANGE_M = 1.0
#: how far (rad) outside the field of view the cheap wrap keeps pairs: the two wraps differ
#: by rounding (about 1e-15 rad), so none inside is lost
FOV_MARGIN_RAD = 1e-9
#: ordered pairs in range from which the cheap wrap runs first: below, its own half a dozen
#: numpy calls (about 6 us) cost more than the sines and cosines it spares
QUICK_WRAP_FROM = 64


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

    def read(self) -> list[dict[int, float]]:
        """For every robot ``k``: ``{p: beta_kp}`` (rad) of the robots it sees now."""
        return self.as_dicts(*self.read_pairs())

    def as_dicts(self, k: np.ndarray, p: np.ndarray, beta: np.ndarray) -> list[dict[int, float]]:
        """:meth:`read_pairs`' pairs as one ``{p: beta_kp}`` per robot ``k``."""
        out: list[dict[int, float]] = [{} for _ in range(self.sim.n)]
        for ki, pi, b in zip(k.tolist(), p.tolist(), beta.tolist()):
            out[ki][pi] = b
        return out

    def read_pairs(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every pair ``(k, p)`` with ``k`` seeing ``p`` now, and ``beta_kp`` (rad), as
        three arrays sorted by ``k``, then ``p`` (one noise draw per pair, in that order)."""
        sim = self.sim
        if sim.n < 2:  # nobody to see
            return (np.empty(0, np.int64),) * 2 + (np.empty(0),)
        poses = sim.poses()
        pairs = sim.neighbours.pairs(poses[:, :2], self.range_m)
        if not len(pairs):  # nobody within range of anybody
            return (np.empty(0, np.int64),) * 2 + (np.empty(0),)
        k = np.concatenate([pairs[:, 0], pairs[:, 1]])
        p = np.concatenate([pairs[:, 1], pairs[:, 0]])
        x, y, yaw = poses.T
        beta = np.arctan2(y[p] - y[k], x[p] - x[k]) - yaw[k]
        if len(beta) >= QUICK_WRAP_FROM:
            near = np.flatnonzero(np.abs(beta - 2 * np.pi * np.round(beta / (2 * np.pi)))
                                  <= self.fov_rad + FOV_MARGIN_RAD)
            k, p, beta = k[near], p[near], beta[near]
        beta = np.arctan2(np.sin(beta), np.cos(beta))
        ahead = np.abs(beta) <= self.fov_rad
        k, p, beta = k[ahead], p[ahead], beta[ahead]
        seen = sim.sight(k, p)
        k, p, beta = k[seen], p[seen], beta[seen]
        order = np.lexsort((p, k))
        k, p, beta = k[order], p[order], beta[order]
        if self.noise_rad:
            beta = beta + self.rng.normal(0.0, self.noise_rad, len(beta))
        return k, p, beta
