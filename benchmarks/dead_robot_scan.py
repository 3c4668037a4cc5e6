"""Random dead-robot runs beyond the grid: arenas, team sizes, speeds, tiers and fault
times drawn from a seeded generator, one line per run, judged as the stress grid judges
(:func:`mjswarm.experiments.stress.passed`). The grid (``stress --dead``) holds its
cells fixed; this scan looks for the cases it misses.

    python benchmarks/dead_robot_scan.py --seed 1 --runs 40 \\
        --arenas arena1,arena2,lattice:4x4,random-planar:10:3,tree4,hex:2x2,wheel:6
"""

from __future__ import annotations

import argparse
import random
import sys
import time
from pathlib import Path

if __package__ in (None, ""):
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from mjswarm.arena import load_arena  # noqa: E402
from mjswarm.experiments.embodied import EmbodiedConfig  # noqa: E402
from mjswarm.experiments.exploration import explore_embodied  # noqa: E402
from mjswarm.experiments.faults import parse_fault  # noqa: E402
from mjswarm.experiments.stress import passed  # noqa: E402

TEAMS = (2, 3, 4, 6)
SPEEDS_M_S = (0.05, 0.1, 0.15, 0.2)
TIERS = ("kinematic", "kinematic", "dynamic")  # the fast tier twice as often
LATEST_FAULT_S = 300.0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1, help="the draws' seed")
    parser.add_argument("--runs", type=int, default=40, help="how many runs")
    parser.add_argument("--arenas", default="arena1,arena2,lattice:4x4,random-planar:10:3,"
                        "tree4,hex:2x2,wheel:6", help="comma-separated arenas to draw from")
    args = parser.parse_args()
    rng = random.Random(args.seed)
    arenas = args.arenas.split(",")
    failed = 0
    for _ in range(args.runs):
        arena = rng.choice(arenas)
        k, speed, tier = rng.choice(TEAMS), rng.choice(SPEEDS_M_S), rng.choice(TIERS)
        at_s = rng.uniform(0, LATEST_FAULT_S)
        fault = f"robot:{rng.randrange(1, k + 1)}@{at_s:.0f}"
        start = time.perf_counter()
        result = explore_embodied(load_arena(arena), k, config=EmbodiedConfig(
            physics=tier, speed_m_s=speed, faults=[parse_fault(fault)]))
        ok = passed(result)
        failed += not ok
        print(f"{arena} {k} {speed} {tier} {fault}: {result.ended_because} map "
              f"{result.map_correct} contacts {result.collisions} stopped "
              f"{len(result.stopped_robots)} {'PASS' if ok else 'FAIL'} "
              f"{time.perf_counter() - start:.0f}s", flush=True)
    print(f"{args.runs - failed} of {args.runs} passed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
