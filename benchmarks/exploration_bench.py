"""The embodied exploration loop against bare physics of the same world, in one run.

Runs one embodied exploration (default: the main job, ``arena2`` with 4 robots at the
paper's 5 cm/s), then steps a fresh copy of the same compiled world with bare
``mj_step`` (sensors off, the robots standing in the depot and on the root as at the
start, constant controls) for as many physics steps, and prints both rates and their
quotient: how many times longer the full loop (sensing, bearings, controllers, stations,
radio) takes than the physics alone. The target is at most 1.3 on the main job.

    python benchmarks/exploration_bench.py [--arena arena2] [--robots 4] [--speed 0.05]
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import mujoco  # noqa: E402

from mjswarm.arena import load_arena  # noqa: E402
from mjswarm.core.simulation import SENSOR_OFF  # noqa: E402
from mjswarm.experiments.exploration import EmbodiedConfig, EmbodiedExploration  # noqa: E402
from mjswarm.experiments.minds import make_minds  # noqa: E402


def bench(arena: str = "arena2", robots: int = 4, speed_m_s: float = 0.05) -> dict:
    """Wall time of one exploration and of bare physics for as many steps (s)."""
    spec = load_arena(arena)
    config = EmbodiedConfig(speed_m_s=speed_m_s)
    run = EmbodiedExploration(spec, make_minds("incidence-dfs", robots), config, 0)
    start = time.perf_counter()
    result = run.run()
    full_s = time.perf_counter() - start
    steps = run.sim.data.time / run.sim.model.opt.timestep

    bare = EmbodiedExploration(spec, make_minds("incidence-dfs", robots), config, 0).sim
    bare.model.opt.disableflags |= SENSOR_OFF
    start = time.perf_counter()
    mujoco.mj_step(bare.model, bare.data, nstep=round(steps))
    bare_s = time.perf_counter() - start
    return {"arena": arena, "robots": robots, "completed": result.completed,
            "sim_time_s": result.sim_time_s, "full_wall_s": full_s, "bare_wall_s": bare_s,
            "full_realtime": result.sim_time_s / full_s,
            "bare_realtime": result.sim_time_s / bare_s, "overhead_ratio": full_s / bare_s}


def main_job_parser(doc: str) -> argparse.ArgumentParser:
    """The command line of a benchmark of one exploration: arena, robots, speed (m/s)."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--arena", default="arena2")
    parser.add_argument("--robots", type=int, default=4)
    parser.add_argument("--speed", type=float, default=0.05, help="m/s (default 0.05)")
    return parser


if __name__ == "__main__":
    args = main_job_parser(__doc__).parse_args()
    r = bench(args.arena, args.robots, args.speed)
    print(f"machine: {platform.machine()}, Python {platform.python_version()}, "
          f"MuJoCo {mujoco.__version__}")
    print(f"{r['arena']}, {r['robots']} robots: {r['sim_time_s']:.1f} s simulated "
          f"(completed: {r['completed']})")
    print(f"  full loop: {r['full_wall_s']:.2f} s wall ({r['full_realtime']:.1f}x real time)")
    print(f"  bare mj_step: {r['bare_wall_s']:.2f} s wall ({r['bare_realtime']:.1f}x real time)")
    print(f"  overhead_ratio: {r['overhead_ratio']:.2f}")
