"""Exploration that stays connected, in both worlds side by side under one radio model.

Each case (arena, team size K, radio range R in m) runs ``incidence-dfs`` under
``--connectivity connected`` three times: in the graph world with the open radio model
(range alone), in the graph world with walls (links need line of sight past the arena's
walls, the base's antenna on its 1 m mast: :mod:`mjswarm.worlds.wall_sight`), and on
the MuJoCo robots at 0.1 m/s, noise-free (walls block there too). Each cell gives the
outcome (completed, or the verdict and the share of edges explored), the makespan
(graph: time units; MuJoCo: edges traversed by the busiest robot, and simulated
seconds), relay trips, and the share of ticks in which every robot had a radio route to
the base (ground truth); the MuJoCo cell adds contact events and robots stopped for good.

    python benchmarks/connected_worlds.py [--jobs 2]
    python benchmarks/docs_tables.py connected     # the same table, for the docs
"""

from __future__ import annotations

import argparse
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

#: (arena, K, R (m)): the paper's arena, a tree, a lattice, a hexagonal lattice and a
#: random planar arena, each at a short and a long range.
CASES = [("arena2", 4, 1.5), ("arena2", 4, 2.5), ("tree1", 5, 1.2), ("tree1", 5, 2.0),
         ("lattice:4x4", 4, 1.5), ("lattice:4x4", 6, 2.5), ("hex:3x3", 6, 1.5),
         ("hex:3x3", 6, 3.0), ("random-planar:10:3", 4, 1.5), ("random-planar:10:3", 4, 2.5)]
#: The MuJoCo robots' cruising speed (m/s).
SPEED_M_S = 0.1


def outcome(r) -> str:
    """Completed, or the verdict (infeasible, stalled) with the share of the edges
    explored and the robots the arena needs."""
    if r.completed:
        return "completed"
    reason = getattr(r, "reason", None) or getattr(r, "ended_because", "")
    if "explored " in reason:
        explored = reason.split("explored ")[1].split(";")[0]
        return f"{reason.split(' with ')[0]}, {explored}, needs {r.robots_needed}"
    return reason or "not completed"


def graph_cell(arena: str, k: int, range_m: float, walls: bool) -> str:
    from mjswarm.arena import load_arena
    from mjswarm.experiments.runs import run_exploration

    r = run_exploration(load_arena(arena), k, world="graph", radio_range_m=range_m,
                        connectivity="connected", radio_walls=walls)
    makespan = f"{r.makespan:.1f}" if r.completed else "-"
    return (f"{outcome(r)}; {makespan}; {r.relay_trips}; "
            f"{100 * r.connected_share:.0f} %")


def embodied_cell(case: tuple) -> str:
    from mjswarm.arena import load_arena
    from mjswarm.experiments.exploration import EmbodiedConfig, explore_embodied

    arena, k, range_m = case
    r = explore_embodied(load_arena(arena), k, config=EmbodiedConfig(
        speed_m_s=SPEED_M_S, radio_range_m=range_m, connectivity="connected"))
    makespan = f"{r.makespan} ({r.sim_time_s:.0f} s)" if r.completed else "-"
    return (f"{outcome(r)}; {makespan}; {r.relay_trips}; {100 * r.connected_share:.0f} %; "
            f"{r.collisions}; {len(r.stopped_robots)}")


def rows(cases: list[tuple], jobs: int) -> list[list[str]]:
    """One row per case: arena, K, R and the three worlds' cells."""
    with ProcessPoolExecutor(jobs) as pool:
        bodies = list(pool.map(embodied_cell, cases))
    return [[f"`{arena}`", str(k), f"{range_m:g}", graph_cell(arena, k, range_m, False),
             graph_cell(arena, k, range_m, True), body]
            for (arena, k, range_m), body in zip(cases, bodies)]


HEADER = ["arena", "K", "R (m)", "graph, open radio", "graph, walls block",
          "MuJoCo robots, walls block"]
LEGEND = ("Each cell: outcome; makespan (graph: time units; MuJoCo: edges traversed by "
          "the busiest robot, and simulated seconds); relay trips; share of ticks in which "
          "every robot had a radio route to the base. MuJoCo cells add contact events and "
          f"robots stopped for good. `incidence-dfs`, `--connectivity connected`, MuJoCo "
          f"robots at {SPEED_M_S:g} m/s, fixed tie rules.")


def markdown(table_rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(HEADER) + " |", "|" + "---|" * len(HEADER)]
    lines += ["| " + " | ".join(row) + " |" for row in table_rows]
    return "\n".join(lines) + "\n\n" + LEGEND


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=2, help="MuJoCo runs at a time (default 2)")
    args = parser.parse_args()
    print(markdown(rows(CASES, args.jobs)))
