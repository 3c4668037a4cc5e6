"""Seeded embodied exploration scenarios shared by the embodied tests.

Twenty runs across ``arena1``, ``arena2``, ``fig9`` and ``lattice:4x4`` with 2 to 6
robots, launch orders shuffled per scenario and launch intervals from 2 to 12 s
(staggered departures from the root), at the paper's 5 cm/s and at 10 cm/s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mjswarm.arena import load_arena
from mjswarm.experiments.exploration import EmbodiedConfig, EmbodiedResult, explore_embodied

ARENAS = {"arena1": (2, 3), "arena2": (3, 5), "fig9": (2, 4), "lattice:4x4": (2, 6)}


@dataclass(frozen=True)
class Scenario:
    arena: str
    robots: int
    seed: int
    launch_order: tuple[int, ...]
    launch_interval_s: float
    speed_m_s: float

    def run(self, collision_avoidance: bool = True, max_sim_time_s: float = 1800.0
            ) -> EmbodiedResult:
        config = EmbodiedConfig(
            speed_m_s=self.speed_m_s, collision_avoidance=collision_avoidance,
            launch_order=list(self.launch_order), launch_interval_s=self.launch_interval_s,
            max_sim_time_s=max_sim_time_s)
        return explore_embodied(load_arena(self.arena), self.robots, config=config,
                                seed=self.seed)


def scenarios(n: int = 20, seed: int = 2026) -> list[Scenario]:
    """``n`` scenarios cycling through the arenas, drawn from ``seed``."""
    rng = np.random.default_rng(seed)
    names = list(ARENAS)
    out = []
    for i in range(n):
        arena = names[i % len(names)]
        low, high = ARENAS[arena]
        k = int(rng.integers(low, high + 1))
        out.append(Scenario(
            arena=arena, robots=k, seed=i,
            launch_order=tuple(int(x) for x in rng.permutation(k)),
            launch_interval_s=float(rng.choice([2.0, 5.0, 12.0])),
            speed_m_s=float(rng.choice([0.05, 0.1])),
        ))
    return out
