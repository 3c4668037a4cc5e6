"""The connected-exploration table: the price of staying connected, in the graph world.

For each arena, team size K and radio range R (m), one run per constraint (``none``,
``connected``, ``biconnected``; Nagavarapu et al.'s incidence-DFS, canonical tie rules) in
:class:`~mjswarm.worlds.radiograph.RadioGraphWorld`; prints a markdown table: makespan
(time units, or the verdict), total traversals, radio messages and relay trips, with
the unconstrained run's shares of ticks in which every robot reached the base and the
team with the base was biconnected (ground truth; the constrained runs hold theirs in
every tick, which the tests check). ``mjswarm sweep --radio-ranges ... --connectivity ...`` runs
the same grid to a results file.

    python benchmarks/connected_exploration_table.py [--arenas arena2,lattice:5x5,random-graph:12:16:3]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mjswarm.experiments.sweep import grid, run_cell  # noqa: E402

ARENAS = "arena2,lattice:5x5,random-graph:12:16:3"
ROBOTS = "4,8"
RANGES = "1,1.5,2.5"
CONSTRAINTS = ("none", "connected", "biconnected")


def rows(arenas: list[str], robots: list[int], ranges: list[float]) -> list[str]:
    """One row per arena, K and R: the three constraints side by side."""
    out = ["| arena | K | R (m) | none: makespan / traversals / connected, biconnected "
           "| connected: makespan / traversals / messages / relay trips "
           "| biconnected: makespan / traversals / messages / relay trips |",
           "|---|---:|---:|---|---|---|"]
    cells = grid("graph", arenas, robots, ["incidence-dfs"], [0], ranges, CONSTRAINTS)
    for i in range(0, len(cells), len(CONSTRAINTS)):
        free, *tied = (run_cell(c) for c in cells[i:i + len(CONSTRAINTS)])
        c = cells[i]
        line = (f"| {c.arena} | {c.robots} | {c.radio_range_m:g} | {_span(free)} / "
                f"{free['total_traversals']} / {100 * free['connected_share']:.0f} %, "
                f"{100 * free['biconnected_share']:.0f} % |")
        for r in tied:
            line += (f" {_span(r)} / {r['total_traversals']} / {r['messages']} / "
                     f"{r['relay_trips']} |")
        out.append(line)
    return out


def _span(r: dict) -> str:
    """The makespan (time units), or the verdict."""
    if r["completed"]:
        return f"{r['makespan']:g}"
    if r["reason"] is None:
        return "time limit"
    return r["reason"].split(" with ")[0] + " (" + r["reason"].split(": ")[1] + ")"


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arenas", default=ARENAS)
    parser.add_argument("--robots", default=ROBOTS)
    parser.add_argument("--ranges", default=RANGES, help="radio ranges, m")
    args = parser.parse_args()
    print("\n".join(rows(args.arenas.split(","), [int(k) for k in args.robots.split(",")],
                         [float(r) for r in args.ranges.split(",")])))
