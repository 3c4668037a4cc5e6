"""Connected exploration's random cases in one line per constraint: completions and total makespan.

Runs the graph-world cases of ``tests/test_connected_exploration.py`` (``CASES``: random
graphs and trees, 2 to 6 robots, ranges 0.7 to 2.5 m) under ``connected`` and
``biconnected`` and prints, per constraint, how many completed, their total makespan
(time units), and the ticks of the ground-truth checks that failed (the tests hold these
at 0). A quick measure of a rule change over many graphs (about 10 s).

    python benchmarks/connected_cases_summary.py
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(ROOT))


def load_cases():
    """The tests' module (its ``CASES`` and ``run``)."""
    spec = importlib.util.spec_from_file_location(
        "cases", ROOT / "tests" / "test_connected_exploration.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def summary(constraint: str) -> str:
    tests = load_cases()
    done = cut = fragile = 0
    makespan = 0.0
    for arena, robots, range_m in tests.CASES:
        result, _ = tests.run(arena, robots, range_m, constraint)
        done += result.completed
        makespan += result.makespan if result.completed else 0.0
        cut += result.cut_ticks
        fragile += result.fragile_ticks if constraint == "biconnected" else 0
    return (f"{constraint}: {done} of {len(tests.CASES)} completed, total makespan "
            f"{makespan:.1f}; ticks cut off {cut}, not biconnected {fragile}")


if __name__ == "__main__":
    for constraint in ("connected", "biconnected"):
        print(summary(constraint))
