"""The graph-world benchmark is callable from code and measures something sane."""

from __future__ import annotations

import importlib.util
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "graphworld_bench.py"


def load_bench():
    spec = importlib.util.spec_from_file_location("graphworld_bench", BENCH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_bench_reports_runs_per_second(capsys):
    bench = load_bench()
    r = bench.bench("lattice:4x4", robots=5, runs=3, repeats=2)
    assert r["makespan"] == 9 and r["runs_per_batch"] == 3
    assert 0 < r["runs_per_s_median"] <= r["runs_per_s_best"]
    assert bench.main(["--arena", "fig9", "--robots", "2", "--runs", "2", "--repeats", "1"]) == 0
    assert "runs/s" in capsys.readouterr().out
