"""The exploration benchmarks are callable from code and measure something sane."""

from __future__ import annotations

import importlib.util
import time
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


def load_bench(name: str = "graphworld_bench"):
    spec = importlib.util.spec_from_file_location(name, BENCHMARKS / f"{name}.py")
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


def test_embodied_bench_compares_the_loop_with_bare_physics_of_the_same_run():
    """The benchmark's run is the exploration itself (the same result as run on its own),
    and its two wall times are parts of the time the call took."""
    from mjswarm.arena import load_arena
    from mjswarm.experiments.exploration import EmbodiedConfig, EmbodiedExploration
    from mjswarm.experiments.minds import make_minds

    start = time.perf_counter()
    r = load_bench("exploration_bench").bench("fan:3:45", robots=1, speed_m_s=0.2)
    elapsed = time.perf_counter() - start
    alone = EmbodiedExploration(load_arena("fan:3:45"), make_minds("incidence-dfs", 1),
                                EmbodiedConfig(speed_m_s=0.2), 0).run()
    assert r["completed"] == alone.completed is True
    assert r["sim_time_s"] == alone.sim_time_s > 10
    assert 0 < r["full_wall_s"] and 0 < r["bare_wall_s"]
    assert r["full_wall_s"] + r["bare_wall_s"] < elapsed
    assert r["full_realtime"] * r["full_wall_s"] == pytest.approx(alone.sim_time_s)
    assert r["bare_realtime"] * r["bare_wall_s"] == pytest.approx(alone.sim_time_s)


def test_phase_benchmarks_time_every_phase_of_a_short_run():
    """``bench_phases`` and ``exploration_phases`` (a big swarm's first seconds): every
    phase they name is timed, and the phases fit inside the run's wall time."""
    spent, full_s, bare_s = load_bench("bench_phases").phases(3, 20, "kinematic")
    names = load_bench("bench_phases").PHASES
    assert all(spent[p] > 0 for p in names) and bare_s > 0
    assert spent[names[4]] < full_s
    explore = load_bench("exploration_phases")
    spent, ticks, wall_s = explore.phases("fig9", 2, 0.2, "kinematic", max_time_s=2.0)
    assert ticks == 100 and 0 < spent["controllers"] < wall_s
