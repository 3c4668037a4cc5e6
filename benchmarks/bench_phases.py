"""Where a tick of ``mjswarm bench``'s loop goes, phase by phase, against bare physics.

Builds the bench world of N robots (:func:`mjswarm.worlds.bench.bench_world`) and its
batched loop (:func:`mjswarm.experiments.bench.bench_loop`), runs ``--ticks`` control
ticks with a wall-clock timer around each phase (the team's observation, its step, its
commands, the world's step and, inside it, the simulation's step and the radio's), then
as many ticks of bare ``mj_step`` on a second copy of the world (sensors off, constant
controls, as the bench), and prints each (us a control tick). The timers cost about a
microsecond each: compare the phases with each other and with bare physics.

    python benchmarks/bench_phases.py [--robots 10] [--ticks 3000] [--physics dynamic]
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from benchmarks.exploration_phases import timed  # noqa: E402
from mjswarm.core.simulation import SENSOR_OFF  # noqa: E402
from mjswarm.experiments.bench import BENCH_SPEED_M_S, bench_loop  # noqa: E402
from mjswarm.worlds.bench import bench_world  # noqa: E402

PHASES = ("team's observation", "  of which the radio's inboxes", "team's step",
          "team's commands", "world step", "  simulation step", "  radio (delivery, relink)")


def phases(robots: int, ticks: int, physics: str) -> tuple[Counter, float, float]:
    """Each phase's wall time (s), and the loop's and bare physics' wall time (s)."""
    loop = bench_loop(bench_world(robots, physics=physics))
    loop.step()  # warm-up: the compiled kernels load
    world, spent = loop.world, Counter()
    world.observe_all = timed(spent, PHASES[0], world.observe_all)
    world.radio.receive_all = timed(spent, PHASES[1], world.radio.receive_all)
    loop.team.step_all = timed(spent, PHASES[2], loop.team.step_all)
    world.act_all = timed(spent, PHASES[3], world.act_all)
    world.step = timed(spent, PHASES[4], world.step)
    world.sim.step = timed(spent, PHASES[5], world.sim.step)
    world._radio_step = timed(spent, PHASES[6], world._radio_step)
    start = time.perf_counter()
    loop.run(max_ticks=loop.ticks + ticks)
    full_s = time.perf_counter() - start
    bare = bench_world(robots)
    bare.model.opt.disableflags |= SENSOR_OFF
    bare.set_velocity(np.full(robots, BENCH_SPEED_M_S), np.zeros(robots))
    start = time.perf_counter()
    mujoco.mj_step(bare.model, bare.data, nstep=ticks * bare.substeps)
    return spent, full_s, time.perf_counter() - start


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=10)
    parser.add_argument("--ticks", type=int, default=3000)
    parser.add_argument("--physics", choices=("dynamic", "kinematic"), default="dynamic")
    args = parser.parse_args()
    spent, full_s, bare_s = phases(args.robots, args.ticks, args.physics)
    per_tick = 1e6 / args.ticks
    print(f"{args.robots} robots, {args.physics}: {full_s * per_tick:.0f} us a tick in all, "
          f"bare physics {bare_s * per_tick:.0f} us (ratio {full_s / bare_s:.2f})")
    for phase in PHASES:
        print(f"  {phase:32s} {spent[phase] * per_tick:8.1f} us")
