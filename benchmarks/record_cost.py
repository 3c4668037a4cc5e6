"""What recording costs the main job: ``mjswarm explore --arena arena2 --robots 4`` run
through the Python API with and without a rerun recording
(:class:`~mjswarm.outputs.exploration_recording.ExplorationRecording`), in one process,
interleaved ``--repeats`` times (the machine is shared: both meet the same load); prints
each run's wall and CPU time, the best of each, and the ratios recorded / bare.

    python benchmarks/record_cost.py [--repeats 2] [--max-time S]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mjswarm.arena import load_arena  # noqa: E402
from mjswarm.experiments.awareness import truth  # noqa: E402
from mjswarm.experiments.runs import run_exploration  # noqa: E402
from mjswarm.outputs.exploration_recording import ExplorationRecording  # noqa: E402
from mjswarm.outputs.recording import Recorder  # noqa: E402


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


def compare(repeats: int = 2, max_time: float | None = None, log=print) -> dict:
    """Bare and recorded runs interleaved ``repeats`` times: the best wall and CPU time of
    each (s), the simulated time (s) and the recording's size (MB)."""
    best = {"bare": [float("inf")] * 2, "recorded": [float("inf")] * 2}
    sim = size_mb = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(repeats):
            for kind in ("bare", "recorded"):
                path = None if kind == "bare" else Path(tmp) / f"run{k}.rrd"
                wall, cpu, sim = one(path, max_time)
                size = ""
                if path is not None:
                    size_mb = path.stat().st_size / 1e6
                    size = f", {size_mb:.1f} MB"
                log(f"{kind:9s} run {k + 1}: {sim:.1f} s simulated, wall {wall:.2f} s, "
                    f"CPU {cpu:.2f} s{size}")
                best[kind] = [min(best[kind][0], wall), min(best[kind][1], cpu)]
    (bw, bc), (rw, rc) = best["bare"], best["recorded"]
    return {"bare_wall_s": bw, "bare_cpu_s": bc, "recorded_wall_s": rw,
            "recorded_cpu_s": rc, "sim_time_s": sim, "size_mb": size_mb}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--max-time", type=float, default=None, metavar="S")
    args = parser.parse_args()
    r = compare(args.repeats, args.max_time, log=lambda line: print(line, flush=True))
    print(f"best wall: bare {r['bare_wall_s']:.2f} s, recorded {r['recorded_wall_s']:.2f} s: "
          f"ratio {r['recorded_wall_s'] / r['bare_wall_s']:.2f}")
    print(f"best CPU:  bare {r['bare_cpu_s']:.2f} s, recorded {r['recorded_cpu_s']:.2f} s: "
          f"ratio {r['recorded_cpu_s'] / r['bare_cpu_s']:.2f}")


if __name__ == "__main__":
    main()
