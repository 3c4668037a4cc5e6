"""What recording costs the main job: ``mjswarm explore --arena arena2 --robots 4`` run
through the Python API with and without a rerun recording
(:class:`~mjswarm.outputs.exploration_recording.ExplorationRecording`), in one process,
interleaved ``--repeats`` times (the machine is shared: both meet the same load); prints
each run's wall and CPU time, the best of each, and the ratios recorded / bare.

    python benchmarks/record_cost.py [--repeats 2] [--max-time S]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from mjswarm.arena import load_arena
from mjswarm.experiments.awareness import truth
from mjswarm.experiments.runs import run_exploration
from mjswarm.outputs.exploration_recording import ExplorationRecording
from mjswarm.outputs.recording import Recorder


def one(record: Path | None, max_time: float | None) -> tuple[float, float, float]:
    """One run: (wall s, CPU s, simulated s)."""
    spec = load_arena("arena2")
    wall, cpu = time.perf_counter(), time.process_time()
    if record is None:
        result = run_exploration(spec, 4, world="embodied", max_time=max_time)
    else:
        with Recorder(record, spec, 4) as recorder:
            result = run_exploration(spec, 4, world="embodied", max_time=max_time,
                                     functions=[ExplorationRecording(recorder, spec, truth)])
    return time.perf_counter() - wall, time.process_time() - cpu, result.sim_time_s


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--max-time", type=float, default=None, metavar="S")
    args = parser.parse_args()
    best = {"bare": [float("inf")] * 2, "recorded": [float("inf")] * 2}
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(args.repeats):
            for kind in ("bare", "recorded"):
                path = None if kind == "bare" else Path(tmp) / f"run{k}.rrd"
                wall, cpu, sim = one(path, args.max_time)
                size = "" if path is None else f", {path.stat().st_size / 1e6:.1f} MB"
                print(f"{kind:9s} run {k + 1}: {sim:.1f} s simulated, wall {wall:.2f} s, "
                      f"CPU {cpu:.2f} s{size}", flush=True)
                best[kind] = [min(best[kind][0], wall), min(best[kind][1], cpu)]
    (bw, bc), (rw, rc) = best["bare"], best["recorded"]
    print(f"best wall: bare {bw:.2f} s, recorded {rw:.2f} s: ratio {rw / bw:.2f}")
    print(f"best CPU:  bare {bc:.2f} s, recorded {rc:.2f} s: ratio {rc / bc:.2f}")


if __name__ == "__main__":
    main()
