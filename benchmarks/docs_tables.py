"""Regenerates the tables of the documentation's performance and papers pages.

Each table is measured here and written to ``docs/tables/NAME.md`` with a line naming
the command, the date and the machine (cores, processor, Python, MuJoCo); the pages
include those files, so a figure on them is never typed by hand and a new run replaces
the old one. Run from the repository root:

    python benchmarks/docs_tables.py papers          # the papers' results, reproduced
    python benchmarks/docs_tables.py performance     # speed against bare mj_step
    python benchmarks/docs_tables.py papers --only fig9,coverage
    python benchmarks/docs_tables.py connected       # exploration that stays connected

Wall-clock figures depend on what else the machine is doing: run it on a quiet machine.
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

if __package__ in (None, ""):  # run as a script: the repository and its benchmarks importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    sys.path.insert(0, str(Path(__file__).resolve().parent))

ROOT = Path(__file__).resolve().parents[1]
TABLES = ROOT / "docs" / "tables"

#: Fig. 9 of Nagavarapu et al.: each robot's vertex sequence, and completion.
FIG9_PAPER = (["v1", "v2", "v4", "v2", "v5", "v6", "v5", "v7", "v8"],
              ["v1", "v3", "v4", "v6", "v8", "v9", "v10", "v9", "v8"])
#: Embodied runs of Nagavarapu et al., Sec. 6: edge traversals by the busiest robot.
EMBODIED_PAPER = {"arena1": (2, 7), "arena2": (4, 10)}
#: Ahmadi & Stone's S-coverage (cr, placement) -> mean over 100 episodes (%).
COVERAGE_PAPER = {(2.0, "heuristic"): 73, (4.0, "heuristic"): 91,
                  (2.0, "min-intersection"): 75}


def machine() -> str:
    import mujoco

    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return (f"{os.cpu_count()} cores ({cpu}), Python {platform.python_version()}, "
            f"MuJoCo {mujoco.__version__}")


def write_table(name: str, group: str, body: str) -> Path:
    """Write ``body`` and its provenance to ``docs/tables/NAME.md`` (replaced whole)."""
    TABLES.mkdir(parents=True, exist_ok=True)
    today = datetime.date.today().isoformat()
    text = (body.rstrip() + "\n\n"
            f"*Measured by `python benchmarks/docs_tables.py {group} --only {name}` on "
            f"{today}, {machine()}.*\n")
    path = TABLES / f"{name}.md"
    fd, temp = tempfile.mkstemp(dir=TABLES, prefix=f".{name}.", suffix=".part")
    with os.fdopen(fd, "w") as out:
        out.write(text)
    os.replace(temp, path)
    print(f"wrote {path.relative_to(ROOT)}", file=sys.stderr)
    return path


def table(header: list[str], rows: list[list]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


# --- the papers ---------------------------------------------------------------------

def fig9() -> str:
    from mjswarm.arena import load_arena
    from mjswarm.experiments.runs import run_exploration

    r = run_exploration(load_arena("fig9"), 2, world="graph")
    rows = [[f"R{i + 1}", "-".join(path), "-".join(FIG9_PAPER[i]),
             "yes" if path == FIG9_PAPER[i] else "no"] for i, path in enumerate(r.paths)]
    return (table(["robot", "mjswarm", "paper (Fig. 9)", "same"], rows) + "\n\n"
            f"Completion declared by R{r.declared_by} at {r.declared_at} after "
            f"{r.makespan:g} steps (paper: R1 at v8 after 8); map equal to the arena's: "
            f"{'yes' if r.map_correct else 'no'}. Command: "
            "`mjswarm explore --world graph --arena fig9 --robots 2`.")


def comparisons() -> str:
    from mjswarm.experiments.exploration_compare import markdown, run_comparison

    seeds = 10
    text = markdown(run_comparison(seeds=seeds, progress=True), seeds)
    lines = text.splitlines()[1:]  # the page gives the title
    return ("\n".join(line.replace("## ", "#### ", 1) if line.startswith("## ") else line
                      for line in lines)
            + "\n\nCommand: `mjswarm compare exploration` (also writes the plots).")


def trees() -> str:
    from benchmarks.trees_proposed_vs_mr_dfs import N_TREES, compare

    c = compare(N_TREES)
    rows = [["makespan <= E (Proposition 2)", "always", f"{c.total - c.over_e} of {c.total}"],
            ["makespan <= MR-DFS's", "always", f"{c.total - c.worse} of {c.total}"],
            ["above MR-DFS by (steps: runs)", "-",
             ", ".join(f"{m}: {n}" for m, n in sorted(c.margins.items())) or "-"]]
    return (table(["claim, random trees", "paper", "mjswarm"], rows) + "\n\n"
            f"Trees `random-tree:E:SEED` for SEED = 0..{N_TREES - 1} (E = 5..30 edges), "
            "K = 2..8 robots, graph world, unit edge time. Command: "
            "`python benchmarks/trees_proposed_vs_mr_dfs.py`.")


def embodied() -> str:
    from mjswarm.arena import load_arena
    from mjswarm.experiments.runs import run_exploration

    rows = []
    for arena, (k, paper) in EMBODIED_PAPER.items():
        r = run_exploration(load_arena(arena), k, world="embodied")
        rows.append([f"`{arena}`", k, paper, r.makespan, r.total_traversals,
                     "yes" if r.map_correct else "no", r.collisions,
                     f"{r.sim_time_s:.0f}"])
    return (table(["arena", "robots", "paper: busiest robot", "mjswarm: busiest robot",
                   "all robots", "true map", "contacts", "simulated (s)"], rows) + "\n\n"
            "Edge traversals to completion at 5 cm/s, MuJoCo robots. Command: "
            "`mjswarm explore --arena ARENA --robots K`.")


def coverage() -> str:
    from mjswarm.experiments.coverage import run_coverage

    rows = []
    for (cr, placement), paper in COVERAGE_PAPER.items():
        cells = []
        for world in ("point", "embodied"):
            r = run_coverage(cr, placement, 100, 0, world)
            cells.append(f"{100 * r.mean_coverage:.1f} %")
        rows.append([f"{cr:g}", placement, f"{paper} %", *cells])
    return (table(["cr", "placement", "paper", "point world", "embodied"], rows) + "\n\n"
            "Mean S-coverage over 100 episodes of random adds and removes, seed 0. "
            "Command: `mjswarm experiment biconnected-coverage --cr CR --placement P "
            "--world W --seed 0`.")


def forwarding() -> str:
    from benchmarks.tables_forwarding_rules import compare_rules

    rows = [[name, f"{robots_wrong} of {robots}", f"{teams_wrong} of {teams}", messages]
            for name, robots_wrong, robots, teams_wrong, teams, messages in compare_rules()]
    return (table(["forwarding rule", "robots' beliefs wrong", "team verdicts wrong",
                   "table-building messages"], rows) + "\n\n"
            "Connectivity tables (Le et al., Algorithm 1) on 500 connected random "
            "geometric teams, n = 5..30. Command: "
            "`python benchmarks/tables_forwarding_rules.py`.")


# --- performance ----------------------------------------------------------------------

def bench() -> str:
    from mjswarm.experiments.bench import as_dict, run_bench

    rows = []
    for physics, counts in (("dynamic", (1, 10, 100)), ("kinematic", (10, 100, 1000))):
        for n in counts:
            d = as_dict(run_bench(n, sim_seconds=4.0, physics=physics))
            rows.append([n, physics, d["sensing"], f"{d['realtime_factor']:.1f}x",
                         f"{d['physics_only_realtime_factor']:.1f}x", f"{d['overhead_ratio']:.2f}"])
    return (table(["robots", "physics", "sensing", "full loop (x real time)",
                   "bare mj_step (x real time)", "overhead ratio"], rows) + "\n\n"
            "Every robot senses (line, IR, encoders, bearings with line of sight), talks "
            "(1 m radio, line of sight, a heartbeat a tick), runs the speed rule and a line "
            "follower. Command: `mjswarm bench --robots 1,10,100 --seconds 4` and "
            "`mjswarm bench --physics kinematic --robots 10,100,1000 --seconds 4`.")


def main_job() -> str:
    from benchmarks.exploration_bench import bench as exploration_bench

    r = exploration_bench()
    rows = [["full loop", f"{r['full_wall_s']:.1f}", f"{r['full_realtime']:.1f}x"],
            ["bare `mj_step`, same world and steps", f"{r['bare_wall_s']:.1f}",
             f"{r['bare_realtime']:.1f}x"]]
    return (table(["main job (`arena2`, 4 robots)", "wall time (s)", "x real time"], rows)
            + f"\n\nOverhead ratio {r['overhead_ratio']:.2f} for {r['sim_time_s']:.0f} s "
            "simulated. Command: `python benchmarks/exploration_bench.py`.")


def graph_world() -> str:
    from benchmarks.graphworld_bench import bench as graph_bench

    r = graph_bench()
    return (table(["arena", "robots", "strategy", "makespan", "runs / s (median of 5 x 50)"],
                  [[f"`{r['arena']}`", r["robots"], r["strategy"], r["makespan"],
                    r["runs_per_s_median"]]])
            + "\n\nCommand: `python benchmarks/graphworld_bench.py`.")


def record_cost() -> str:
    from benchmarks.record_cost import compare

    r = compare(repeats=2, log=lambda line: print(line, file=sys.stderr))
    rows = [["without a recording", f"{r['bare_wall_s']:.1f}", f"{r['bare_cpu_s']:.1f}"],
            [f"with `--record` ({r['size_mb']:.0f} MB)", f"{r['recorded_wall_s']:.1f}",
             f"{r['recorded_cpu_s']:.1f}"],
            ["ratio", f"{r['recorded_wall_s'] / r['bare_wall_s']:.2f}",
             f"{r['recorded_cpu_s'] / r['bare_cpu_s']:.2f}"]]
    return (table(["main job (`arena2`, 4 robots)", "wall time (s)", "CPU time (s)"], rows)
            + f"\n\nBest of two interleaved runs each, {r['sim_time_s']:.0f} s simulated. "
            "Command: `python benchmarks/record_cost.py`.")


def cli_help() -> str:
    from benchmarks.cli_help_time import measure

    runs = 7
    help_s, bare_s = measure(runs)
    rows = [["`mjswarm --help`", f"{help_s:.2f}"], ["`python -c pass`", f"{bare_s:.2f}"]]
    return (table(["command", f"wall time (s), median of {runs}"], rows)
            + "\n\nCommand: `python benchmarks/cli_help_time.py`.")


# --- exploration that stays connected ----------------------------------------------

def connected_arena2() -> str:
    from connected_worlds import outcome
    from mjswarm.arena import load_arena
    from mjswarm.experiments.runs import run_exploration

    rows = []
    for walls in (True, False):
        for range_m, constraint in ((1.5, "connected"), (2.5, "connected"),
                                    (1.5, "biconnected"), (2.5, "biconnected")):
            r = run_exploration(load_arena("arena2"), 4, radio_range_m=range_m,
                                connectivity=constraint, radio_walls=walls)
            rows.append(["walls" if walls else "open", f"{range_m:g}", constraint, outcome(r),
                         f"{r.makespan:.1f}" if r.completed else "-", r.messages,
                         r.relay_trips, f"{100 * r.connected_share:.1f} %",
                         f"{100 * r.biconnected_share:.1f} %"])
    return (table(["radio", "R (m)", "constraint", "outcome", "makespan", "messages",
                   "relay trips", "every robot reached the base", "biconnected"], rows)
            + "\n\nCommand: `mjswarm explore --world graph --arena arena2 --robots 4 "
              "--radio-range R --connectivity C --radio-model M`.")


def connected_worlds() -> str:
    from connected_worlds import CASES, markdown, rows

    return markdown(rows(CASES, jobs=2)) + (
        "\n\nCommand: `python benchmarks/connected_worlds.py`.")


GROUPS: dict[str, dict[str, Callable[[], str]]] = {
    "papers": {"fig9": fig9, "comparisons": comparisons, "trees": trees,
               "embodied": embodied, "coverage": coverage, "forwarding": forwarding},
    "performance": {"bench": bench, "main_job": main_job, "graph_world": graph_world,
                    "record_cost": record_cost, "cli_help": cli_help},
    "connected": {"connected_arena2": connected_arena2, "connected_worlds": connected_worlds},
}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("group", choices=sorted(GROUPS))
    parser.add_argument("--only", metavar="NAME,...",
                        help="only these tables (default: all of the group)")
    args = parser.parse_args(argv)
    tables = GROUPS[args.group]
    names = args.only.split(",") if args.only else list(tables)
    unknown = [n for n in names if n not in tables]
    if unknown:
        parser.error(f"unknown table {unknown[0]!r} (choose from {', '.join(tables)})")
    for name in names:
        print(f"measuring {name} ...", file=sys.stderr)
        write_table(name, args.group, tables[name]())
    return 0


if __name__ == "__main__":
    sys.exit(main())
