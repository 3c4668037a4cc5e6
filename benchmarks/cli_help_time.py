"""How long ``mjswarm --help`` takes: the median wall time of a few runs.

Each run is a fresh ``python -m mjswarm.cli --help`` (interpreter start, the parser built
with every subcommand, the help printed), timed from outside. The same for
``python -c pass`` gives the interpreter's own start-up, so the difference is mjswarm's.

    python benchmarks/cli_help_time.py            # 7 runs each
    python benchmarks/cli_help_time.py --runs 15
"""

import argparse
import statistics
import subprocess
import sys
import time


def median_wall_s(command: list[str], runs: int) -> float:
    """The median wall time of ``runs`` runs of ``command`` (s), after one warm-up run."""
    subprocess.run(command, capture_output=True, check=True)  # disk caches warm
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        subprocess.run(command, capture_output=True, check=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def measure(runs: int = 7) -> tuple[float, float]:
    """Median wall times (s) of ``mjswarm --help`` and of ``python -c pass``."""
    bare = median_wall_s([sys.executable, "-c", "pass"], runs)
    return median_wall_s([sys.executable, "-m", "mjswarm.cli", "--help"], runs), bare


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7, help="timed runs of each command")
    args = parser.parse_args()
    help_, bare = measure(args.runs)
    print(f"mjswarm --help: {help_:.3f} s median of {args.runs} runs "
          f"(python -c pass: {bare:.3f} s; mjswarm's share {help_ - bare:.3f} s)")
