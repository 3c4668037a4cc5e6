"""The robustness stress grid: embodied exploration beyond the paper's arenas.

Arenas with vertices whose edges are 45-90 degrees apart, at arbitrary rotations (fans,
wheels, hexagonal and triangular lattices, random planar graphs, rotated lattices and
paper arenas), 1 to 10 robots, speeds from the paper's 0.05 m/s to the top speed 0.2
m/s, several seeds. Every run must complete with the true map, no robot stopped and no
robot-robot contact. ``python -m mjswarm.experiments.stress`` runs the grid on a process pool and
prints its table (the one in ``docs/exploration.md``); ``tests/test_stress.py`` runs a fast
representative of each failure class by default and the whole grid with ``-m slow``.

The noise grid (``--noise``): one arena of each class at every speed, under
line noise 0.5 mm, IR noise 2 mm, bearing noise 2 degrees and wheel slip 0.05, each alone
and all together, in both physics tiers, two seeds; it adds the criterion that the
robots' odometry heading stays within ``MAX_HEADING_ERROR_DEG`` of the truth.

The dense-team grid (``--dense``): lattices, a hexagonal lattice and a random
planar graph with one robot for every 7, 5 and 4 edges, at 0.15 and 0.2 m/s, three seeds;
every run must pass as the stress grid's do.

The dead-robot grid (``--dead``): one robot fails (``--fault robot:I@T``) on
trees, the paper's arenas, a lattice and a random planar graph, teams of 2, 4 and 8,
fault times from before the launch to a whole robot's share of the work, speeds
0.05-0.2 m/s in turn, both physics tiers. A run passes when it ends completed with the
true map or with everything still reachable mapped and the rest named, no robot but the
failed one stopped, and no contact.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

from tqdm import tqdm

from mjswarm.arena import ArenaSpec, load_arena, parse_arena_spec
from mjswarm.core import PHYSICS
from mjswarm.experiments.exploration import EmbodiedConfig, EmbodiedResult, explore_embodied
from mjswarm.experiments.faults import parse_fault

#: A fan whose vertex v1 has edges 67.5 degrees apart: a robot arriving at v1 must not be
#: carried out along a neighbouring spoke.
NARROW_FAN = {
    "name": "narrow-fan", "root": "v0",
    "vertices": {"v1": [0, 0], "v0": [0.3515, 0.8485], "v2": [-0.8485, -0.3515],
                 "c": [-0.6494, 0.6494]},
    "edges": [["v0", "v1"], ["v1", "v2"], ["v1", "c"]],
}

#: Arenas of the grid (names as ``--arena`` takes them); ``narrow-fan`` is the dict above.
ARENAS = (
    "narrow-fan", "fan:3:45@17", "wheel:4@8", "wheel:8", "hex:2x2@30", "tri:2x3@7",
    "lattice:4x4@33", "fig9@20", "random-planar:8:1", "random-planar:12:2",
)
SPEEDS_M_S = (0.05, 0.1, 0.15, 0.2)
TEAMS = (1, 4, 10)


@dataclass(frozen=True)
class Noise:
    """Sensor noise and wheel slip of a run (:class:`EmbodiedConfig`'s fields; SI units,
    bearings in degrees)."""

    line_m: float = 0.0
    ir_m: float = 0.0
    bearing_deg: float = 0.0
    wheel_slip: float = 0.0

    def __str__(self) -> str:
        parts = [f"line {self.line_m * 1e3:g} mm" if self.line_m else "",
                 f"IR {self.ir_m * 1e3:g} mm" if self.ir_m else "",
                 f"bearing {self.bearing_deg:g} deg" if self.bearing_deg else "",
                 f"slip {self.wheel_slip:g}" if self.wheel_slip else ""]
        return ", ".join(p for p in parts if p) or "none"


#: The noise levels: each at its largest alone, then all together.
#: The wheel slip the noise grid asks for.
GRID_SLIP = 0.05


def noises(slip: float = GRID_SLIP) -> tuple[Noise, ...]:
    """The noise grid's levels, each alone and all together, with wheel slip ``slip``."""
    return (Noise(line_m=0.0005), Noise(ir_m=0.002), Noise(bearing_deg=2.0),
            Noise(wheel_slip=slip),
            Noise(line_m=0.0005, ir_m=0.002, bearing_deg=2.0, wheel_slip=slip))


NOISES = noises()
#: The noise grid's arena classes: one of each kind of the grid above (fan, wheel, hex,
#: triangular, rotated lattice, paper arena, random planar), teams of 1 and 4.
NOISE_ARENAS = ("fan:3:45@17", "wheel:4@8", "hex:2x2@30", "tri:2x3@7", "lattice:4x4@33",
                "arena2", "random-planar:8:1")
NOISE_TEAMS = (1, 4)
#: ``--sample``: the noise grid's declared subset, one seed of every arena class, noise and
#: tier at the paper's speed and the top speed, teams of 4 (140 runs).
SAMPLE_SPEEDS_M_S = (0.05, 0.2)
SAMPLE_TEAMS = (4,)
#: The noise grid's heading criterion (deg): heading error within 5 degrees.
MAX_HEADING_ERROR_DEG = 5.0


#: The dense teams: arenas, team sizes as edges per robot, speeds (m/s).
DENSE_ARENAS = ("lattice:5x5", "lattice:6x6", "lattice:8x8", "hex:3x3", "random-planar:24:3")
DENSE_EDGES_PER_ROBOT = (7, 5, 4)
DENSE_SPEEDS_M_S = (0.15, 0.2)
#: ``--dense --sample``: the densest two teams at the top speed, one seed.
DENSE_SAMPLE = {"edges_per_robot": (5, 4), "speeds": (0.2,), "seeds": (0,)}


#: The dead-robot grid: arenas, teams, speeds (m/s, taken in turn) and fault times
#: as fractions of a robot's share of the work (its ``E / K`` edges, each a traversal of
#: the mean edge at the run's speed and a scan's full turn at 1 rad/s).
DEAD_ARENAS = ("tree3", "tree4", "arena1", "arena2", "lattice:4x4", "random-planar:12:2")
DEAD_TEAMS = (2, 4, 8)
DEAD_SPEEDS_M_S = (0.05, 0.1, 0.15, 0.2)
DEAD_FRACTIONS = (0.0, 0.3, 1.0)


@dataclass(frozen=True)
class StressRun:
    """One cell of the grid (``fault``: a ``--fault`` text, "" for none)."""

    arena: str
    robots: int
    speed_m_s: float
    seed: int | None
    noise: Noise = Noise()
    physics: str = "dynamic"
    fault: str = ""

    def spec(self) -> ArenaSpec:
        if self.arena == NARROW_FAN["name"]:
            return parse_arena_spec(NARROW_FAN, "the stress grid")
        return load_arena(self.arena)

    def run(self, max_sim_time_s: float = 3600.0) -> EmbodiedResult:
        n = self.noise
        config = EmbodiedConfig(speed_m_s=self.speed_m_s, max_sim_time_s=max_sim_time_s,
                                line_noise_m=n.line_m, ir_noise_m=n.ir_m,
                                bearing_noise_deg=n.bearing_deg, wheel_slip=n.wheel_slip,
                                physics=self.physics,
                                faults=[parse_fault(self.fault)] if self.fault else [])
        return explore_embodied(self.spec(), self.robots, config=config, seed=self.seed)


def grid(arenas=ARENAS, speeds=SPEEDS_M_S, teams=TEAMS, seeds=(0,)) -> list[StressRun]:
    """Every combination; teams larger than an arena's edge count are left out."""
    runs = []
    for arena in arenas:
        edges = len(StressRun(arena, 1, 0.05, 0).spec().edges)
        runs += [StressRun(arena, k, v, s) for k in teams if k <= edges
                 for v in speeds for s in seeds]
    return runs


def noise_grid(arenas=NOISE_ARENAS, speeds=SPEEDS_M_S, teams=NOISE_TEAMS, noises=NOISES,
               physics=PHYSICS, seeds=(0, 1)) -> list[StressRun]:
    """The noise grid: every arena class at every speed under every noise, both tiers."""
    return [StressRun(arena, k, v, s, noise, tier) for arena in arenas for k in teams
            for v in speeds for noise in noises for tier in physics for s in seeds]


def dense_grid(arenas=DENSE_ARENAS, edges_per_robot=DENSE_EDGES_PER_ROBOT,
               speeds=DENSE_SPEEDS_M_S, seeds=(0, 1, 2)) -> list[StressRun]:
    """The dense-team grid: ``E // n`` robots for each ``n`` of ``edges_per_robot``
    (E: the arena's edges), at every speed and seed."""
    runs = []
    for arena in arenas:
        edges = len(StressRun(arena, 1, 0.05, 0).spec().edges)
        runs += [StressRun(arena, edges // n, v, s) for n in edges_per_robot
                 for v in speeds for s in seeds]
    return runs


def dead_grid(arenas=DEAD_ARENAS, teams=DEAD_TEAMS, fractions=DEAD_FRACTIONS,
              physics=PHYSICS, seeds=(0,)) -> list[StressRun]:
    """The dead-robot grid: in every arena, team (no larger than the arena's edge
    count), fault time, tier and seed, robot ``1 + (cell number) mod K`` fails; speeds
    go round ``DEAD_SPEEDS_M_S`` cell by cell."""
    runs = []
    for arena in arenas:
        spec = StressRun(arena, 1, 0.05, 0).spec()
        edge_m = sum(math.dist(spec.vertices[u], spec.vertices[v])
                     for u, v in spec.edges) / len(spec.edges)
        for k in (k for k in teams if k <= len(spec.edges)):
            for fraction in fractions:
                for tier in physics:
                    for seed in seeds:
                        cell = len(runs)
                        v = DEAD_SPEEDS_M_S[cell % len(DEAD_SPEEDS_M_S)]
                        share_s = len(spec.edges) / k * (edge_m / v + 2.0 * math.pi)
                        fault = f"robot:{1 + cell % k}@{fraction * share_s:.0f}"
                        runs.append(StressRun(arena, k, v, seed, physics=tier, fault=fault))
    return runs


def passed(result: EmbodiedResult, max_heading_error_deg: float = math.inf) -> bool:
    """The grid's criterion: complete, true map, nobody stopped (but robots failed by a
    fault), no contact (and, for the noise grid, ``MAX_HEADING_ERROR_DEG``)."""
    stopped = [s for s in result.stopped_robots if not s["reason"].startswith("failed (fault")]
    return (result.completed and result.map_correct and not stopped
            and result.collisions == 0 and result.heading_error_deg <= max_heading_error_deg)


def _timed(run: StressRun) -> tuple[StressRun, EmbodiedResult, float]:
    start = time.perf_counter()
    result = run.run()
    return run, result, time.perf_counter() - start


def run_grid(runs: list[StressRun], workers: int, log=None,
             max_heading_error_deg: float = math.inf) -> list[tuple[StressRun, EmbodiedResult, float]]:
    """Run ``runs`` on ``workers`` processes, with a progress bar; results in grid order.
    ``log``: a text file that gets one line per run as it is done, passed or not by
    :func:`passed` with ``max_heading_error_deg`` (a long grid's partial results survive
    an interruption)."""
    done = []
    with ProcessPoolExecutor(max_workers=workers) as pool:
        for run, result, wall in tqdm(pool.map(_timed, runs), total=len(runs), unit="run",
                                      desc="stress grid", disable=not sys.stderr.isatty()):
            done.append((run, result, wall))
            if log is not None:
                print(f"{run.arena} k={run.robots} v={run.speed_m_s:g} {run.noise} "
                      f"{run.physics} seed={run.seed} fault={run.fault or 'none'}: "
                      f"{result.ended_because} "
                      f"map={result.map_correct} contacts={result.collisions} "
                      f"stopped={len(result.stopped_robots)} "
                      f"heading={result.heading_error_deg:.1f} "
                      f"give_ups={result.queue_give_ups} sim={result.sim_time_s:.0f}s "
                      f"pass={passed(result, max_heading_error_deg)} wall={wall:.0f}s",
                      file=log, flush=True)
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


def noise_table(rows: list[tuple[StressRun, EmbodiedResult, float]]) -> str:
    """Markdown table of the noise grid, one line per noise and physics tier."""
    lines = ["| noise | physics | runs | passed | completed with the true map | "
             "contact events | stopped robots | worst heading error (deg) | wall time (s) |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for noise, tier in dict.fromkeys((r.noise, r.physics) for r, _, _ in rows):
        mine = [(res, t) for r, res, t in rows if (r.noise, r.physics) == (noise, tier)]
        lines.append(
            f"| {noise} | {tier} | {len(mine)} | "
            f"{sum(passed(res, MAX_HEADING_ERROR_DEG) for res, _ in mine)} | "
            f"{sum(res.completed and res.map_correct for res, _ in mine)} | "
            f"{sum(res.collisions for res, _ in mine)} | "
            f"{sum(len(res.stopped_robots) for res, _ in mine)} | "
            f"{max(res.heading_error_deg for res, _ in mine):.1f} | "
            f"{sum(t for _, t in mine):.0f} |")
    return "\n".join(lines)


def parser() -> argparse.ArgumentParser:
    """The command line of ``python -m mjswarm.experiments.stress``."""
    parser = argparse.ArgumentParser(
        prog="python -m mjswarm.experiments.stress",
        description="Run the robustness stress grid and print its table (markdown); "
                    "exit status 1 if any run failed (the failures are listed).")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                        help="processes (default: all cores)")
    parser.add_argument("--arenas", default=None,
                        help="comma-separated arenas (default: the whole grid)")
    parser.add_argument("--seeds", type=int, default=None,
                        help="seeds 0..N-1 (default: 1; the noise grid: 2)")
    parser.add_argument("--noise", action="store_true",
                        help="run the noise grid instead (--arenas defaults to its "
                             "classes; every speed, noise level and physics tier)")
    parser.add_argument("--log", type=argparse.FileType("a"), default=None, metavar="FILE",
                        help="append one line per run to FILE as it is done")
    parser.add_argument("--dense", action="store_true",
                        help="run the dense-team grid instead (one robot for every "
                             "7, 5 and 4 edges, 0.15 and 0.2 m/s, three seeds: 90 runs)")
    parser.add_argument("--dead", action="store_true",
                        help="run the dead-robot grid instead (one robot fails; "
                             "trees, paper arenas, a lattice, a random planar graph; teams "
                             "of 2, 4 and 8; both physics tiers)")
    parser.add_argument("--sample", action="store_true",
                        help="with --noise: only 0.05 and 0.2 m/s, teams of 4 and one seed "
                             "(140 runs); with --dense: one robot for every 5 and 4 edges "
                             "at 0.2 m/s, one seed (10 runs)")
    parser.add_argument("--slip", type=float, default=GRID_SLIP, metavar="S",
                        help=f"with --noise: the wheel slip of its slip levels (default "
                             f"{GRID_SLIP:g})")
    parser.add_argument("--only-slip", action="store_true",
                        help="with --noise: only the levels with wheel slip (alone, and "
                             "with every noise together)")
    return parser


def main(argv: list[str] | None = None) -> int:
    command = parser()
    args = command.parse_args(argv)
    if args.noise + args.dense + args.dead > 1:
        command.error("choose one of --noise, --dense and --dead")
    if (args.only_slip or args.slip != GRID_SLIP) and not args.noise:
        command.error("--slip and --only-slip need --noise")
    if args.sample and not (args.noise or args.dense):
        command.error("--sample needs --noise or --dense")
    if not 0.0 <= args.slip < 1.0:
        command.error(f"--slip must be in [0, 1), got {args.slip:g}")
    if args.noise:
        arenas = NOISE_ARENAS if args.arenas is None else args.arenas.split(",")
        levels = tuple(n for n in noises(args.slip) if n.wheel_slip or not args.only_slip)
        if args.sample:
            runs = noise_grid(arenas=arenas, speeds=SAMPLE_SPEEDS_M_S, teams=SAMPLE_TEAMS,
                              noises=levels, seeds=range(args.seeds or 1))
        else:
            runs = noise_grid(arenas=arenas, noises=levels, seeds=range(args.seeds or 2))
        heading = MAX_HEADING_ERROR_DEG
    elif args.dense:
        arenas = DENSE_ARENAS if args.arenas is None else args.arenas.split(",")
        options = dict(DENSE_SAMPLE) if args.sample else {}
        if args.seeds is not None:
            options["seeds"] = range(args.seeds)
        runs, heading = dense_grid(arenas=arenas, **options), math.inf
    elif args.dead:
        arenas = DEAD_ARENAS if args.arenas is None else args.arenas.split(",")
        runs = dead_grid(arenas=arenas, seeds=range(args.seeds or 1))
        heading = math.inf
    else:
        arenas = ARENAS if args.arenas is None else args.arenas.split(",")
        runs, heading = grid(arenas=arenas, seeds=range(args.seeds or 1)), math.inf
    rows = run_grid(runs, args.workers, args.log, heading)
    print(noise_table(rows) if args.noise else table(rows))
    failures = [(r, res) for r, res, _ in rows if not passed(res, heading)]
    for r, res in failures:
        print(f"FAILED {r}: {res.ended_because}, contacts {res.collisions}, "
              f"stopped {res.stopped_robots}, heading error {res.heading_error_deg:.1f} deg",
              file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
