"""The robustness stress grid (issue 13): embodied exploration beyond the paper's arenas.

Arenas with vertices whose edges are 45-90 degrees apart, at arbitrary rotations (fans,
wheels, hexagonal and triangular lattices, random planar graphs, rotated lattices and
paper arenas), 1 to 10 robots, speeds from the paper's 0.05 m/s to the top speed 0.2
m/s, several seeds. Every run must complete with the true map, no robot stopped and no
robot-robot contact. ``python -m mjswarm.experiments.stress`` runs the grid on a process pool and
prints its table (the one in README); ``tests/test_stress.py`` runs a fast
representative of each failure class by default and the whole grid with ``-m slow``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

from tqdm import tqdm

from mjswarm.arena import ArenaSpec, load_arena, parse_arena_spec
from mjswarm.experiments.exploration import EmbodiedConfig, EmbodiedResult, explore_embodied

#: Issue 13's first report: one robot arriving at v1, whose edges are 67.5 degrees
#: apart, was carried out along a neighbouring spoke.
ISSUE_13_FAN = {
    "name": "issue13-fan", "root": "v0",
    "vertices": {"v1": [0, 0], "v0": [0.3515, 0.8485], "v2": [-0.8485, -0.3515],
                 "c": [-0.6494, 0.6494]},
    "edges": [["v0", "v1"], ["v1", "v2"], ["v1", "c"]],
}

#: Arenas of the grid (names as ``--arena`` takes them); ``issue13-fan`` is the dict above.
ARENAS = (
    "issue13-fan", "fan:3:45@17", "wheel:4@8", "wheel:8", "hex:2x2@30", "tri:2x3@7",
    "lattice:4x4@33", "fig9@20", "random-planar:8:1", "random-planar:12:2",
)
SPEEDS_M_S = (0.05, 0.1, 0.15, 0.2)
TEAMS = (1, 4, 10)


@dataclass(frozen=True)
class StressRun:
    """One cell of the grid."""

    arena: str
    robots: int
    speed_m_s: float
    seed: int | None

    def spec(self) -> ArenaSpec:
        if self.arena == ISSUE_13_FAN["name"]:
            return parse_arena_spec(ISSUE_13_FAN, "issue 13")
        return load_arena(self.arena)

    def run(self, max_sim_time_s: float = 3600.0) -> EmbodiedResult:
        config = EmbodiedConfig(speed_m_s=self.speed_m_s, max_sim_time_s=max_sim_time_s)
        return explore_embodied(self.spec(), self.robots, config=config, seed=self.seed)


def grid(arenas=ARENAS, speeds=SPEEDS_M_S, teams=TEAMS, seeds=(0,)) -> list[StressRun]:
    """Every combination; teams larger than an arena's edge count are left out."""
    runs = []
    for arena in arenas:
        edges = len(StressRun(arena, 1, 0.05, 0).spec().edges)
        runs += [StressRun(arena, k, v, s) for k in teams if k <= edges
                 for v in speeds for s in seeds]
    return runs


def passed(result: EmbodiedResult) -> bool:
    """The grid's criterion: complete, true map, nobody stopped, no contact."""
    return (result.completed and result.map_correct and not result.stopped_robots
            and result.collisions == 0)


def _timed(run: StressRun) -> tuple[StressRun, EmbodiedResult, float]:
    start = time.perf_counter()
    result = run.run()
    return run, result, time.perf_counter() - start


def run_grid(runs: list[StressRun], workers: int) -> list[tuple[StressRun, EmbodiedResult, float]]:
    """Run ``runs`` on ``workers`` processes, with a progress bar; results in grid order."""
    with ProcessPoolExecutor(max_workers=workers) as pool:
        done = list(tqdm(pool.map(_timed, runs), total=len(runs), unit="run",
                         desc="stress grid", disable=not sys.stderr.isatty()))
    return done


def table(rows: list[tuple[StressRun, EmbodiedResult, float]]) -> str:
    """Markdown table, one line per arena: runs, passed, completed, contacts, stopped
    robots, worst heading error and wall time."""
    lines = ["| arena | runs | passed | completed with the true map | contact events | "
             "stopped robots | worst heading error (deg) | wall time (s) |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for arena in dict.fromkeys(r.arena for r, _, _ in rows):
        mine = [(r, res, t) for r, res, t in rows if r.arena == arena]
        lines.append(
            f"| `{arena}` | {len(mine)} | {sum(passed(res) for _, res, _ in mine)} | "
            f"{sum(res.completed and res.map_correct for _, res, _ in mine)} | "
            f"{sum(res.collisions for _, res, _ in mine)} | "
            f"{sum(len(res.stopped_robots) for _, res, _ in mine)} | "
            f"{max(res.heading_error_deg for _, res, _ in mine):.1f} | "
            f"{sum(t for _, _, t in mine):.0f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m mjswarm.experiments.stress",
        description="Run issue 13's robustness stress grid and print its table (markdown); "
                    "exit status 1 if any run failed (the failures are listed).")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                        help="processes (default: all cores)")
    parser.add_argument("--arenas", default=",".join(ARENAS),
                        help="comma-separated arenas (default: the whole grid)")
    parser.add_argument("--seeds", type=int, default=1, help="seeds 0..N-1 (default: 1)")
    args = parser.parse_args(argv)
    runs = grid(arenas=args.arenas.split(","), seeds=range(args.seeds))
    rows = run_grid(runs, args.workers)
    print(table(rows))
    failures = [(r, res) for r, res, _ in rows if not passed(res)]
    for r, res in failures:
        print(f"FAILED {r}: {res.ended_because}, contacts {res.collisions}, "
              f"stopped {res.stopped_robots}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
