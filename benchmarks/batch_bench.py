"""Does ``mujoco.batch`` help replicate embodied runs?

For one world and R replicate simulations of it, measures physics throughput in
simulated robot-seconds per wall second (R replicates x N robots x simulated seconds /
wall seconds) of three ways of stepping, all at the control rate of
:class:`mjswarm.core.simulation.Simulation` (k physics steps per 50 Hz tick):

* ``loop`` (a): a Python loop over R ``MjData``, ``mj_step(m, d, nstep=k)`` per tick,
  sensors disabled for every substep, constant controls;
* ``batch_tT`` (b): ``mujoco.batch.Batch(model, nsim=R, nthread=T)``, one
  ``step(nstep=k)`` call per tick, sensors disabled, the same constant controls;
* ``tick_loop`` / ``tick_batch_tT`` (c): what an embodied run needs every tick. Each
  replicate's Python controller reads its own line sensors and writes new wheel
  commands (a proportional steer towards the side whose line rangefinder reads shorter),
  then physics advances one tick as :meth:`Simulation.step` does with
  ``sensing="mujoco"`` (its default below ``GRID_SENSING_MIN_ROBOTS`` = 32 robots):
  sensors disabled for the first k-1 substeps and enabled for the last. (From 32 robots
  Simulation casts the rangefinders itself, in Python/numba after a sensorless tick; the
  batch analogue of that is (b) plus per-replicate ray casting the batch does not run,
  so it is not measured here.) The loop toggles
  ``m.opt.disableflags``; the batch toggles its per-simulation copy
  (``expand('opt.disableflags')``), so it makes two ``step`` calls per tick
  (``nstep=k-1`` then ``nstep=1``) with the controllers' Python work between ticks.

Replicate r drives every robot forward at ``BENCH_SPEED_M_S * (1 - 0.01 r)`` (through
:meth:`Simulation.set_velocity`), so replicates differ and the bit-identity check
(``identical``: every replicate's final ``qpos`` from the batch equals the loop's, and in
(c) also its ``sensordata``) compares distinct trajectories. Each rate is the best of
``repeats`` timed runs from the initial state, the variants' runs interleaved (the machine
is shared: every variant meets the same load, and its best run is its least disturbed);
building ``MjData``/``Batch`` objects is not timed.

Worlds: ``bench:N`` is :func:`mjswarm.worlds.bench.bench_world` with N robots; anything else is
an arena (:func:`mjswarm.arena.load_arena`) with ``arena_robots`` robots placed by
:func:`vertex_poses`.

Result keys (:func:`bench`): ``world``, ``robots``, ``sensing`` (what
:class:`Simulation` would use for this world; (c) always uses MuJoCo's), ``substeps``, ``ticks``,
``sim_seconds``, ``cpus``, ``threads``, ``mujoco``, ``load_average`` (the machine's 1, 5
and 15 min load after the run: other work competes for the cores) and ``rows``, one per
replicate count R with ``replicates``, ``rates`` (variant -> robot-s per wall s),
``speedups`` (``batch_tT`` over ``loop``, ``tick_batch_tT`` over ``tick_loop``),
``identical`` (batch variant -> bool) and ``cores_busy`` (variant -> process CPU seconds
per wall second of its fastest run: about T when T threads really ran in parallel).

Run ``python benchmarks/batch_bench.py --help`` from the repository root.
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import mujoco
import mujoco.batch
import numpy as np

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mjswarm.arena import ArenaSpec, load_arena
from mjswarm.arena.builder import arena_world_spec
from mjswarm.experiments.bench import BENCH_SPEED_M_S
from mjswarm.worlds.bench import bench_world
from mjswarm.errors import MjswarmError
from mjswarm.core.robot import ACTUATORS, LINE_SENSORS
from mjswarm.core.simulation import SENSOR_OFF, Simulation
from mjswarm.core.world import Pose2D

#: Wheel-speed difference commanded per metre of left/right line-reading difference
#: ((rad/s) / m): a strip under one outer sensor (2 mm shorter reading) gives 2 rad/s.
STEER_GAIN = 1000.0
#: Replicate r runs at BENCH_SPEED_M_S * (1 - SPEED_STEP * r).
SPEED_STEP = 0.01


def vertex_poses(spec: ArenaSpec, k: int) -> list[Pose2D]:
    """k robots on distinct vertices, spread evenly over the spec's vertex order, each
    facing its vertex's first neighbour in edge order (so it drives along a corridor).

    Chosen instead of :class:`mjswarm.experiments.exploration.EmbodiedExploration`'s depot, which parks
    robots on bare floor outside the arena where they would touch no strip or wall.
    """
    ids = list(spec.vertices)
    if not 1 <= k <= len(ids):
        raise MjswarmError(f"arena {spec.name} has {len(ids)} vertices, cannot place {k} robots")
    poses = []
    for i in range(k):
        v = ids[i * len(ids) // k]
        w = next(b if a == v else a for a, b in spec.edges if v in (a, b))
        (x, y), (wx, wy) = spec.vertices[v], spec.vertices[w]
        poses.append(Pose2D(x, y, float(np.arctan2(wy - y, wx - x))))
    return poses


def build_world(world: str, arena_robots: int = 4) -> Simulation:
    """``bench:N`` -> :func:`bench_world` (N robots); otherwise an arena with robots at
    :func:`vertex_poses`."""
    kind, sep, count = world.partition(":")
    if kind == "bench" and sep:
        if not count.isdigit():
            raise MjswarmError(f"world {world!r}: expected bench:N with N a robot count")
        return bench_world(int(count))
    spec = load_arena(world)
    return Simulation(arena_world_spec(spec, vertex_poses(spec, arena_robots)))


def _ids(m: mujoco.MjModel, obj: mujoco.mjtObj, n: int, names: Sequence[str]) -> np.ndarray:
    """(n, len(names)) ids of ``r<i>/<name>`` objects."""
    return np.array([[mujoco.mj_name2id(m, obj, f"r{i}/{s}") for s in names] for i in range(n)])


class _Replicates:
    """One world's model, replicate controls and controller, shared by all variants.

    The model is a copy with MuJoCo's sensors enabled (a grid-sensing Simulation keeps
    them disabled in its own model); each variant sets the sensor flag it needs.
    """

    def __init__(self, sim: Simulation, replicates: int) -> None:
        self.model, self.n, self.k = copy.copy(sim.model), sim.n, sim.substeps
        self.model.opt.disableflags &= ~SENSOR_OFF
        self.replicates = replicates
        ctrl = []
        for r in range(replicates):
            sim.set_velocity(np.full(sim.n, BENCH_SPEED_M_S * (1.0 - SPEED_STEP * r)), 0.0)
            ctrl.append(sim.data.ctrl.copy())
        self.ctrl = np.array(ctrl)  # (R, nu) constant controls
        self.actuators = _ids(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, sim.n, ACTUATORS)
        line = _ids(self.model, mujoco.mjtObj.mjOBJ_SENSOR, sim.n, LINE_SENSORS)
        self.line_adr = self.model.sensor_adr[line]  # (N, 3): left, centre, right

    def steer(self, r: int, sensordata: np.ndarray, ctrl: np.ndarray) -> None:
        """Replicate r's controller: wheel speeds (rad/s) = its constant command
        -+ STEER_GAIN x (right - left line reading (m)), written into ``ctrl``."""
        line = sensordata[self.line_adr]
        turn = STEER_GAIN * (line[:, 2] - line[:, 0])
        ctrl[self.actuators] = self.ctrl[r, self.actuators] + turn[:, None] * [-1.0, 1.0]

    # ------------------------------------------------------------- (a) and (b)
    def loop(self, ticks: int) -> tuple[np.ndarray, list[mujoco.MjData]]:
        m, k = self.model, self.k
        datas = [mujoco.MjData(m) for _ in range(self.replicates)]
        for d, u in zip(datas, self.ctrl):
            d.ctrl[:] = u
        m.opt.disableflags |= SENSOR_OFF
        start = _clock()
        for _ in range(ticks):
            for d in datas:
                mujoco.mj_step(m, d, nstep=k)
        elapsed = _clock() - start
        m.opt.disableflags &= ~SENSOR_OFF
        return elapsed, datas

    def batch(self, ticks: int, threads: int) -> tuple[np.ndarray, mujoco.batch.Batch]:
        self.model.opt.disableflags |= SENSOR_OFF  # the batch copies the model, flags too
        b = mujoco.batch.Batch(self.model, nsim=self.replicates, nthread=threads)
        self.model.opt.disableflags &= ~SENSOR_OFF
        b.ctrl = self.ctrl
        k = self.k
        start = _clock()
        for _ in range(ticks):
            b.step(nstep=k)
        return _clock() - start, b

    # ------------------------------------------------------------- (c)
    def tick_loop(self, ticks: int) -> tuple[np.ndarray, list[mujoco.MjData]]:
        m, k = self.model, self.k
        datas = [mujoco.MjData(m) for _ in range(self.replicates)]
        for d in datas:
            mujoco.mj_forward(m, d)  # first readings, as Simulation.__init__
        start = _clock()
        for _ in range(ticks):
            for r, d in enumerate(datas):
                self.steer(r, d.sensordata, d.ctrl)
                if k > 1:
                    m.opt.disableflags |= SENSOR_OFF
                    mujoco.mj_step(m, d, nstep=k - 1)
                    m.opt.disableflags &= ~SENSOR_OFF
                mujoco.mj_step(m, d)  # as Simulation.step with sensing="mujoco"
        return _clock() - start, datas

    def tick_batch(self, ticks: int, threads: int) -> tuple[np.ndarray, mujoco.batch.Batch]:
        b = mujoco.batch.Batch(self.model, nsim=self.replicates, nthread=threads)
        flags = b.expand("opt.disableflags")  # the batch's own copy; the model's is not read
        on, off = flags.copy(), flags | SENSOR_OFF
        b.forward()
        ctrl, sensordata = b.ctrl, b.sensordata  # live views: bind once
        k = self.k
        start = _clock()
        for _ in range(ticks):
            for r in range(self.replicates):
                self.steer(r, sensordata[r], ctrl[r])
            if k > 1:
                flags[:] = off
                b.step(nstep=k - 1)
                flags[:] = on
            b.step(nstep=1)
        return _clock() - start, b


def _clock() -> np.ndarray:
    """Wall and process CPU time (s): their quotient over a run is the cores it kept busy."""
    return np.array([time.perf_counter(), time.process_time()])


def _loop_of(batch_variant: str) -> str:
    """The loop variant a batch variant is compared with: ``tick_batch_t2`` -> ``tick_loop``."""
    return batch_variant.split("batch_")[0] + "loop"


def _same(datas: list[mujoco.MjData], b: mujoco.batch.Batch, sensors: bool) -> bool:
    """Every replicate's qpos (and sensordata) from the loop equals the batch's, bit for bit."""
    fields = ("qpos", "sensordata") if sensors else ("qpos",)
    return all(
        np.array_equal(np.array([getattr(d, f) for d in datas]), getattr(b, f)) for f in fields
    )


def bench(
    world: str = "arena2",
    replicates: Sequence[int] = (1, 2, 4, 8, 16),
    ticks: int = 50,
    threads: Sequence[int] = (1, 2),
    repeats: int = 3,
    arena_robots: int = 4,
    progress: bool = False,
) -> dict:
    """Measure every variant for each replicate count on one world (see module docstring).

    ``ticks`` control ticks (50 Hz) per timed run; rates in robot-seconds per wall second.
    """
    if ticks < 1 or repeats < 1:
        raise MjswarmError(f"ticks and repeats must be >= 1, got {ticks} and {repeats}")
    if not replicates or min(replicates) < 1:
        raise MjswarmError(f"replicate counts must be >= 1, got {list(replicates)}")
    if not threads or min(threads) < 1:
        raise MjswarmError(f"thread counts must be >= 1, got {list(threads)}")
    sim = build_world(world, arena_robots)
    sim_seconds = ticks * sim.control_dt_s
    rows = []
    bar = _progress(len(replicates) * repeats * 2 * (1 + len(threads)), progress, world)
    for R in replicates:
        reps = _Replicates(sim, R)
        variants = {"loop": (reps.loop,), "tick_loop": (reps.tick_loop,)}
        variants |= {f"batch_t{T}": (reps.batch, T) for T in threads}
        variants |= {f"tick_batch_t{T}": (reps.tick_batch, T) for T in threads}
        best: dict[str, np.ndarray] = {}
        final = {}
        for _ in range(repeats):  # interleaved, so every variant meets the same load
            for name, (run, *args) in variants.items():
                elapsed, final[name] = run(ticks, *args)
                if name not in best or elapsed[0] < best[name][0]:
                    best[name] = elapsed
                bar.update()
        rates = {name: R * sim.n * sim_seconds / wall for name, (wall, _) in best.items()}
        batches = [name for name in variants if "batch" in name]
        rows.append({
            "replicates": R,
            "rates": rates,
            "speedups": {b: rates[b] / rates[_loop_of(b)] for b in batches},
            "identical": {b: _same(final[_loop_of(b)], final[b], b.startswith("tick_"))
                          for b in batches},
            "cores_busy": {name: cpu / wall for name, (wall, cpu) in best.items()},
        })
    bar.close()
    return {
        "world": world,
        "robots": sim.n,
        "sensing": sim.sensing,
        "substeps": sim.substeps,
        "ticks": ticks,
        "sim_seconds": sim_seconds,
        "cpus": os.cpu_count(),
        "threads": list(threads),
        "mujoco": mujoco.__version__,
        "load_average": [round(x, 2) for x in os.getloadavg()],
        "rows": rows,
    }


def _progress(total: int, enabled: bool, label: str):
    from tqdm import tqdm

    return tqdm(total=total, desc=label, disable=not enabled, file=sys.stderr, leave=False)


def format_table(result: dict) -> str:
    """One line per replicate count: rates (robot-s per wall s) and speedups over the loop."""
    threads = result["threads"]
    head = (f"{result['world']}: {result['robots']} robots, {result['substeps']} substeps/tick, "
            f"{result['ticks']} ticks ({result['sim_seconds']:g} s simulated), "
            f"{result['cpus']} CPUs (load {result['load_average'][0]}), mujoco {result['mujoco']}; "
            "rates in robot-s per wall s, x = speedup over the loop")
    cols = ["R", "loop"] + [f"batch T{T}" for T in threads] + [f"x T{T}" for T in threads]
    cols += ["tick loop"] + [f"tick T{T}" for T in threads] + [f"x T{T}" for T in threads]
    cols += ["identical", f"cores T{threads[-1]}", f"tick cores T{threads[-1]}"]
    lines = [head, "  ".join(f"{c:>10}" for c in cols)]
    for row in result["rows"]:
        r, s = row["rates"], row["speedups"]
        cells = [str(row["replicates"]), f"{r['loop']:.1f}"]
        cells += [f"{r[f'batch_t{T}']:.1f}" for T in threads]
        cells += [f"{s[f'batch_t{T}']:.2f}" for T in threads]
        cells += [f"{r['tick_loop']:.1f}"]
        cells += [f"{r[f'tick_batch_t{T}']:.1f}" for T in threads]
        cells += [f"{s[f'tick_batch_t{T}']:.2f}" for T in threads]
        cells += ["yes" if all(row["identical"].values()) else "NO"]
        cells += [f"{row['cores_busy'][f'{p}batch_t{threads[-1]}']:.2f}" for p in ("", "tick_")]
        lines.append("  ".join(f"{c:>10}" for c in cells))
    return "\n".join(lines)


def _int_list(text: str) -> list[int]:
    try:
        return [int(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated integers, got {text!r}") from None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description="Physics throughput of R replicate simulations of one world: a Python "
        "loop over MjData against mujoco.batch.Batch on T threads (see the module docstring).")
    parser.add_argument("--worlds", default="arena2,bench:10,bench:100",
                        help="comma-separated worlds: bench:N (bench grid of N robots) or an "
                             "arena name/file/generator (default: %(default)s)")
    parser.add_argument("--arena-robots", type=int, default=4,
                        help="robots placed on an arena's vertices (default: %(default)s)")
    parser.add_argument("--replicates", type=_int_list, default=[1, 2, 4, 8, 16],
                        help="comma-separated replicate counts R (default: 1,2,4,8,16)")
    parser.add_argument("--threads", type=_int_list, default=[1, 2],
                        help="comma-separated batch thread counts T (default: 1,2)")
    parser.add_argument("--ticks", type=int, default=50,
                        help="50 Hz control ticks per timed run (default: %(default)s = 1 s)")
    parser.add_argument("--repeats", type=int, default=3,
                        help="timed runs per variant; the best is reported (default: %(default)s)")
    parser.add_argument("--json", metavar="PATH|-",
                        help="write the results as a JSON object ({'results': [...]}); - = stdout")
    args = parser.parse_args(argv)
    try:
        results = [
            bench(w, args.replicates, args.ticks, args.threads, args.repeats, args.arena_robots,
                  progress=sys.stderr.isatty())
            for w in args.worlds.split(",")
        ]
    except MjswarmError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.json != "-":
        print("\n\n".join(format_table(r) for r in results))
    if args.json:
        text = json.dumps({"results": results}, indent=2)
        if args.json == "-":
            print(text)
        else:
            Path(args.json).write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
