"""Graph-world speed: exploration runs per second on one core (target >= 1000 runs/s
for ``lattice:10x10`` with 10 robots and the proposed strategy).

Run ``python benchmarks/graphworld_bench.py`` from the repository root, or call
:func:`bench` from code. The world is built once; each timed run creates fresh minds and
explores to completion. Reported: median and best runs/s over ``repeats`` batches.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mjswarm.arena import load_arena
from mjswarm.experiments.graph_exploration import explore_world
from mjswarm.worlds.graphworld import GraphWorld


def bench(
    arena: str = "lattice:10x10",
    robots: int = 10,
    strategy: str = "incidence-dfs",
    runs: int = 50,
    repeats: int = 5,
    clock=time.perf_counter,
) -> dict:
    """Time ``repeats`` batches of ``runs`` explorations; runs per second of ``clock``
    (wall clock, or ``time.process_time`` for this process's CPU time, which other jobs
    on a shared machine disturb less)."""
    spec = load_arena(arena)
    world = GraphWorld(spec.graph(), spec.root)
    result = explore_world(world, robots, strategy)  # warm-up, and a sanity check
    if not (result.completed and result.map_correct):
        raise RuntimeError(f"{strategy} did not complete {arena} correctly")
    rates = []
    for _ in range(repeats):
        start = clock()
        for _ in range(runs):
            explore_world(world, robots, strategy)
        rates.append(runs / (clock() - start))
    return {
        "arena": spec.name,
        "robots": robots,
        "strategy": strategy,
        "makespan": result.makespan,
        "runs_per_batch": runs,
        "runs_per_s_median": round(statistics.median(rates), 1),
        "runs_per_s_best": round(max(rates), 1),
        "python": platform.python_version(),
        "machine": platform.processor() or platform.machine(),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arena", default="lattice:10x10")
    parser.add_argument("--robots", type=int, default=10)
    parser.add_argument("--strategy", default="incidence-dfs")
    parser.add_argument("--runs", type=int, default=50, help="runs per timed batch")
    parser.add_argument("--repeats", type=int, default=5, help="timed batches")
    parser.add_argument("--cpu", action="store_true",
                        help="runs per CPU second of this process instead of per wall second")
    parser.add_argument("--json", action="store_true", help="print JSON")
    args = parser.parse_args(argv)
    r = bench(args.arena, args.robots, args.strategy, args.runs, args.repeats,
              time.process_time if args.cpu else time.perf_counter)
    if args.json:
        print(json.dumps(r, indent=2))
    else:
        print(f"{r['arena']}, {r['robots']} robots, {r['strategy']} (makespan {r['makespan']}): "
              f"{r['runs_per_s_median']} runs/s median, {r['runs_per_s_best']} best "
              f"({'CPU' if args.cpu else 'wall'} seconds) "
              f"over {args.repeats} x {r['runs_per_batch']} runs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
