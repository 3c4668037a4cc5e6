"""The mujoco.batch benchmark: batch stepping is bit-identical to the MjData loop."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from mjswarm.errors import MjswarmError

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "batch_bench.py"
ROW_KEYS = {"replicates", "rates", "speedups", "identical", "cores_busy"}
TOP_KEYS = {"world", "robots", "sensing", "substeps", "ticks", "sim_seconds", "cpus", "threads",
            "mujoco", "load_average", "rows"}


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("batch_bench", BENCH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("world, robots, sensing", [("arena2", 4, "mujoco"), ("bench:33", 33, "grid")])
def test_batch_matches_loop_bit_for_bit(bench, world, robots, sensing):
    """Also on a grid-sensing world, whose Simulation keeps MuJoCo's sensors disabled."""
    r = bench.bench(world, replicates=[2], ticks=3, threads=[1, 2], repeats=1)
    assert set(r) == TOP_KEYS and r["substeps"] == 10
    assert (r["robots"], r["sensing"]) == (robots, sensing)
    (row,) = r["rows"]
    assert set(row) == ROW_KEYS and row["replicates"] == 2
    variants = {"batch_t1", "batch_t2", "tick_batch_t1", "tick_batch_t2"}
    assert set(row["identical"]) == set(row["speedups"]) == variants
    assert set(row["rates"]) == set(row["cores_busy"]) == variants | {"loop", "tick_loop"}
    assert all(row["identical"].values())
    assert all(v > 0 for v in row["rates"].values())


def test_replicates_differ_and_robots_move(bench):
    """The identity check compares distinct trajectories, and the controller steers."""
    reps = bench._Replicates(bench.build_world("bench:2"), 2)
    _, loop = reps.loop(ticks=5)
    assert not (loop[0].qpos == loop[1].qpos).all()
    assert not (loop[0].qpos == reps.model.qpos0).all()
    sensordata, ctrl = np.zeros(reps.model.nsensor), np.zeros(reps.model.nu)
    sensordata[reps.line_adr[1]] = [0.018, 0.02, 0.02]  # robot 1: strip under its left sensor
    reps.steer(1, sensordata, ctrl)
    left, right = ctrl[reps.actuators].T
    base = reps.ctrl[1, reps.actuators[:, 0]]
    assert left[0] == right[0] == base[0]  # robot 0 sees no difference: straight on
    assert left[1] == pytest.approx(base[1] - 2.0) and right[1] == pytest.approx(base[1] + 2.0)


def test_vertex_poses_are_distinct_vertices(bench):
    from mjswarm.arena import load_arena

    spec = load_arena("arena2")
    poses = bench.vertex_poses(spec, 4)
    assert len({(p.x, p.y) for p in poses}) == 4
    assert all((p.x, p.y) in spec.vertices.values() for p in poses)
    with pytest.raises(MjswarmError, match="cannot place 14 robots"):
        bench.vertex_poses(spec, 14)


def test_cli_json_and_errors(bench, capsys):
    assert bench.main(["--worlds", "bench:1", "--replicates", "1", "--threads", "1",
                       "--ticks", "1", "--repeats", "1", "--json", "-"]) == 0
    (result,) = json.loads(capsys.readouterr().out)["results"]
    assert result["robots"] == 1
    assert bench.main(["--worlds", "bench:x", "--ticks", "1"]) == 2
    assert bench.main(["--worlds", "nowhere", "--ticks", "1"]) == 2
    assert bench.main(["--worlds", "bench:1", "--replicates", "0"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3 and all(line.startswith("error: ") for line in err)
