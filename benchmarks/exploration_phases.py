"""Where a tick of one embodied exploration goes, phase by phase, in one run.

Runs one exploration (default: the main job, ``arena2`` with 4 robots at 5 cm/s) with a
wall-clock timer around each phase of :meth:`mjswarm.worlds.loop.Loop.step` and prints
the time of each (us a control tick): the loop functions' hooks (stations, metrics), the
observations (of which the bearing sensor), the controllers, the commands, and the
world's step (of which MuJoCo's ``mj_step``). The timers cost about a microsecond each,
so the phases add up to a little more than an untimed run; compare them with each other
and with ``mj_step``, not with ``benchmarks/exploration_bench.py``.

    python benchmarks/exploration_phases.py [--arena arena2] [--robots 4] [--speed 0.05]
        [--physics dynamic|kinematic] [--max-time S] [--seed S]

``--physics kinematic --max-time S`` profiles the first S simulated seconds of a big
swarm's run, e.g. ``--arena lattice:30x30 --robots 1000 --speed 0.2 --physics kinematic
--max-time 300 --seed 0`` (``--seed``: the strategies' seed, as ``mjswarm explore
--seed``; by default unseeded, as ``benchmarks/exploration_bench.py``).
"""

from __future__ import annotations

import sys
import time
from collections import Counter
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import mujoco  # noqa: E402

from benchmarks.exploration_bench import main_job_parser  # noqa: E402
from mjswarm.arena import load_arena  # noqa: E402
from mjswarm.core import simulation  # noqa: E402
from mjswarm.experiments.exploration import EmbodiedConfig, EmbodiedExploration  # noqa: E402
from mjswarm.experiments.minds import make_minds  # noqa: E402

PHASES = ("loop functions (stations, metrics)", "observe", "  of which the bearing sensor",
          "controllers", "act", "world step", "  of which mj_step")


def timed(spent: Counter, phase: str, function):
    """``function``, adding its wall time (s) to ``spent[phase]`` at every call."""
    def wrapper(*args, **kwargs):
        start = time.perf_counter()
        try:
            return function(*args, **kwargs)
        finally:
            spent[phase] += time.perf_counter() - start
    return wrapper


def phases(arena: str, robots: int, speed_m_s: float, physics: str = "dynamic",
           max_time_s: float | None = None, seed: int | None = None) -> tuple[Counter, int, float]:
    """Each phase's wall time (s), the control ticks and the whole run's wall time (s):
    the whole run, or its first ``max_time_s`` simulated seconds."""
    until = {} if max_time_s is None else {"max_sim_time_s": max_time_s}
    config = EmbodiedConfig(speed_m_s=speed_m_s, physics=physics, **until)
    run = EmbodiedExploration(load_arena(arena), make_minds("incidence-dfs", robots, seed),
                              config, 0)
    spent: Counter = Counter()
    world = run.world
    world.observe = timed(spent, PHASES[1], world.observe)
    world.bearing.read_pairs = timed(spent, PHASES[2], world.bearing.read_pairs)
    for robot in run.robots:
        robot.step = timed(spent, PHASES[3], robot.step)
    world.act = timed(spent, PHASES[4], world.act)
    world.step = timed(spent, PHASES[5], world.step)
    simulation.mujoco.mj_step = timed(spent, PHASES[6], mujoco.mj_step)
    for function in run.loop.functions:
        for hook in ("before_step", "after_step", "should_stop"):
            setattr(function, hook, timed(spent, PHASES[0], getattr(function, hook)))
    start = time.perf_counter()
    try:
        run.run()
    finally:
        simulation.mujoco.mj_step = mujoco.mj_step
    return spent, run.loop.ticks, time.perf_counter() - start


if __name__ == "__main__":
    parser = main_job_parser(__doc__)
    parser.add_argument("--physics", choices=("dynamic", "kinematic"), default="dynamic")
    parser.add_argument("--max-time", type=float, default=None, metavar="S",
                        help="stop after S simulated seconds (default: the whole run)")
    parser.add_argument("--seed", type=int, default=None,
                        help="the strategies' seed (default: none, as the main job's bench)")
    args = parser.parse_args()
    spent, ticks, wall_s = phases(args.arena, args.robots, args.speed, args.physics,
                                  args.max_time, args.seed)
    print(f"{args.arena}, {args.robots} robots: {ticks} control ticks, "
          f"{wall_s / ticks * 1e6:.0f} us a tick in all")
    for phase in PHASES:
        print(f"  {phase:40s} {spent[phase] / ticks * 1e6:7.1f} us")
