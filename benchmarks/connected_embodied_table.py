"""The embodied table of exploration that stays connected on the MuJoCo robots.

Each case (arena, team size K, radio range R in m, speed in m/s, seed, constraint) is one
run of :func:`mjswarm.experiments.exploration.explore_embodied` (incidence-DFS,
tie-breaking randomised by the seed), two at a time; prints a markdown table: the outcome
(makespan in edges and total traversals, or the verdict with the explored share),
robot-robot contact events, ticks in which some robot had no radio route to the base, and
(``biconnected``) ticks in which the radio graph with the base was not biconnected
(ground truth, walls block links), relay trips (rule 6), robots stopped for good,
simulated and wall seconds. Cases are small so that one table takes minutes.

    python benchmarks/connected_embodied_table.py [--jobs 2]
"""

from __future__ import annotations

import argparse
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

#: (arena, K, R (m), speed (m/s), seed, constraint)
CASES = [
    ("arena1", 2, 1.5, 0.1, 0, "connected"),
    ("arena1", 3, 1.5, 0.1, 2, "connected"),
    ("arena1", 3, 2.5, 0.1, 5, "connected"),
    ("arena2", 4, 1.5, 0.1, 1, "connected"),
    ("arena2", 4, 2.0, 0.1, 0, "connected"),
    ("arena2", 6, 1.5, 0.1, 3, "connected"),
    ("fig9", 3, 1.2, 0.1, 0, "connected"),
    ("lattice:2x3:0.8", 3, 1.2, 0.1, 0, "connected"),
    ("lattice:2x3:0.8", 4, 1.5, 0.1, 1, "connected"),
    ("lattice:1x5:0.75", 3, 1.2, 0.1, 0, "connected"),
    ("arena1", 3, 3.0, 0.1, 0, "biconnected"),
    ("arena1", 4, 2.5, 0.1, 1, "biconnected"),
    ("arena2", 5, 2.5, 0.1, 2, "biconnected"),
    ("arena2", 6, 1.5, 0.1, 3, "biconnected"),
    ("fig9", 4, 2.0, 0.1, 1, "biconnected"),
    ("lattice:2x3:0.8", 4, 1.5, 0.1, 1, "biconnected"),
]


def run_case(case: tuple) -> str:
    """One table row."""
    from mjswarm.arena import load_arena
    from mjswarm.experiments.exploration import EmbodiedConfig, explore_embodied

    arena, k, range_m, speed, seed, constraint = case
    start = time.perf_counter()
    r = explore_embodied(load_arena(arena), k, seed=seed, config=EmbodiedConfig(
        speed_m_s=speed, radio_range_m=range_m, connectivity=constraint))
    wall = time.perf_counter() - start
    if r.completed:
        outcome = f"completed, {r.makespan} / {r.total_traversals}"
    elif r.reason is not None:  # rule 5's verdict: infeasible, or stalled
        outcome = r.reason.split(" with ")[0] + ": " + r.reason.split(": ")[1]
    else:
        outcome = r.ended_because
    fragile = r.fragile_ticks if constraint == "biconnected" else "-"
    return (f"| `{arena}` | {k} | {range_m:g} | {speed:g} | {seed} | {constraint} | {outcome} | "
            f"{r.collisions} | {r.cut_ticks} | {fragile} | {r.relay_trips} | "
            f"{len(r.stopped_robots)} | {r.sim_time_s:.0f} / {wall:.0f} |")


def table(cases: list[tuple], jobs: int) -> list[str]:
    head = ["| arena | K | R (m) | speed (m/s) | seed | constraint | outcome | contacts "
            "| cut ticks | not biconnected | relay trips | stopped | sim / wall (s) |",
            "|---|---:|---:|---:|---:|---|---|---:|---:|---:|---:|---:|---:|"]
    with ProcessPoolExecutor(jobs) as pool:
        return head + list(pool.map(run_case, cases))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=2, help="runs at a time (default 2)")
    args = parser.parse_args()
    print("\n".join(table(CASES, args.jobs)))
