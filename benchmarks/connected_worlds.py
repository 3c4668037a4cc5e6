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
    python benchmarks/connected_worlds.py --grid   # 40 cases: arenas, K, R, seeds, speeds

``--grid`` runs ``GRID`` (ten arenas, two teams each, each with tie-breaking seed 1 at
0.1 m/s and seed 2 at 0.15 m/s) in the graph world with walls and on the MuJoCo robots, one row per case, then
counts: where each world completes, where the bodies complete as the points do, and
contacts, cut ticks and robots stopped on the bodies.
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
#: (arena, K, R (m), seed, speed (m/s)): ten arenas (the paper's, a tree, lattices,
#: hexagonal and triangular lattices, a wheel, a random planar arena and a random tree),
#: two teams each, each with seed 1 at 0.1 m/s and seed 2 at 0.15 m/s.
GRID = [(arena, k, range_m, seed, speed)
        for arena, teams in [
            ("arena1", [(2, 1.5), (3, 2.5)]), ("arena2", [(3, 1.5), (4, 2.5)]),
            ("tree1", [(4, 1.5), (5, 2.0)]), ("fig9", [(3, 1.5), (5, 2.5)]),
            ("lattice:3x3", [(3, 1.2), (4, 2.0)]), ("hex:2x2", [(4, 1.5), (5, 2.5)]),
            ("tri:2x3", [(3, 1.2), (4, 2.0)]), ("wheel:6", [(3, 1.2), (4, 2.0)]),
            ("random-planar:12:5", [(4, 1.5), (5, 2.5)]),
            ("random-tree:10:2", [(3, 1.5), (5, 2.5)])]
        for (k, range_m), (seed, speed) in (
            (t, s) for t in teams for s in ((1, SPEED_M_S), (2, 0.15)))]


def outcome(r) -> str:
    """Completed, or the verdict (infeasible, stalled) with the share of the edges
    explored and the robots the arena needs; a run that reached its time limit with the
    share of the edges its robots had traversed."""
    from mjswarm.arena import load_arena
    from mjswarm.experiments.results import traversed_edges

    if r.completed:
        return "completed"
    reason = getattr(r, "reason", None) or getattr(r, "ended_because", "")
    if "explored " in reason:
        explored = reason.split("explored ")[1].split(";")[0]
        return f"{reason.split(' with ')[0]}, {explored}, needs {r.robots_needed}"
    return (f"{reason or 'not completed'}, {len(traversed_edges(r.paths))} of "
            f"{len(load_arena(r.arena).edges)} edges")


def graph_run(arena: str, k: int, range_m: float, walls: bool, seed: int | None = None):
    from mjswarm.arena import load_arena
    from mjswarm.experiments.runs import run_exploration

    return run_exploration(load_arena(arena), k, world="graph", radio_range_m=range_m,
                           connectivity="connected", radio_walls=walls, seed=seed)


def graph_cell(arena: str, k: int, range_m: float, walls: bool) -> str:
    r = graph_run(arena, k, range_m, walls)
    makespan = f"{r.makespan:.1f}" if r.completed else "-"
    return (f"{outcome(r)}; {makespan}; {r.relay_trips}; "
            f"{100 * r.connected_share:.0f} %")


def embodied_run(case: tuple):
    """One MuJoCo run: ``(arena, K, R)`` at ``SPEED_M_S`` with the fixed tie rules, or
    ``(arena, K, R, seed, speed)``."""
    from mjswarm.arena import load_arena
    from mjswarm.experiments.exploration import EmbodiedConfig, explore_embodied

    arena, k, range_m, seed, speed = (*case, None, SPEED_M_S)[:5]
    return explore_embodied(load_arena(arena), k, seed=seed, config=EmbodiedConfig(
        speed_m_s=speed, radio_range_m=range_m, connectivity="connected"))


def embodied_cell(case: tuple) -> str:
    r = embodied_run(case)
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


def grid(jobs: int) -> str:
    """``GRID`` in both worlds (walls block): a markdown table and the counts."""
    with ProcessPoolExecutor(jobs) as pool:
        bodies = list(pool.map(embodied_run, GRID))
    lines = ["| arena | K | R (m) | seed | speed (m/s) | graph, walls block | MuJoCo robots "
             "| contacts | cut ticks | stopped |", "|" + "---|" * 10]
    points_done = bodies_done = both = contacts = cut = stopped = 0
    for (arena, k, range_m, seed, speed), body in zip(GRID, bodies):
        point = graph_run(arena, k, range_m, True, seed)
        points_done += point.completed
        bodies_done += body.completed
        both += point.completed and body.completed
        contacts += body.collisions
        cut += body.cut_ticks > 0
        stopped += len(body.stopped_robots)
        lines.append(f"| `{arena}` | {k} | {range_m:g} | {seed} | {speed:g} | "
                     f"{outcome(point)} | {outcome(body)} | {body.collisions} | "
                     f"{body.cut_ticks} | {len(body.stopped_robots)} |")
    lines += ["", f"{len(GRID)} cases: the graph world with walls completes {points_done}, "
              f"the MuJoCo robots {bodies_done}; the bodies complete {both} of the "
              f"{points_done} the points complete; on the bodies {contacts} contact events, "
              f"{cut} runs with a robot cut off from the base, {stopped} robots stopped "
              f"for good."]
    return "\n".join(lines)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=2, help="MuJoCo runs at a time (default 2)")
    parser.add_argument("--grid", action="store_true", help="run the 40-case grid instead")
    args = parser.parse_args()
    print(grid(args.jobs) if args.grid else markdown(rows(CASES, args.jobs)))
