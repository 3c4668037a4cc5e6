"""``mjswarm bench`` end to end: JSON figures and one-line errors."""

from __future__ import annotations

import hashlib
import json
import time

import pytest

from mjswarm.cli import main
from mjswarm.core.robot import DEFAULT_ROBOT_XML
from mjswarm.experiments.bench import BLOCKS, bench_loop
from mjswarm.worlds.bench import bench_world


#: the figures of one robot count in ``mjswarm bench --json``
KEYS = {"robots", "physics", "sensing", "sim_seconds", "realtime_factor",
        "physics_only_realtime_factor", "overhead_ratio", "robot_steps_per_s"}


def test_bench_json_reports_every_key(capsys):
    """The documented keys, in their units: ``sim_seconds`` is the whole number of
    control ticks asked for; the loop's and bare physics' wall times (simulated seconds
    over each rate) are parts of the time the command took; robot steps per second are
    the robots' physics steps over the loop's wall time."""
    sim = bench_world(1, str(DEFAULT_ROBOT_XML))
    dt = sim.control_dt_s
    substeps = round(dt / sim.model.opt.timestep)
    start = time.perf_counter()
    assert main(["bench", "--robots", "1,3", "--seconds", "0.2", "--json"]) == 0
    elapsed = time.perf_counter() - start
    out = json.loads(capsys.readouterr().out)
    assert [r["robots"] for r in out["results"]] == [1, 3]
    walls = 0.0
    for r in out["results"]:
        assert r.keys() == KEYS
        assert (r["sensing"], r["physics"]) == ("mujoco", "dynamic")  # auto, small teams
        ticks = max(BLOCKS, round(0.2 / dt))
        assert r["sim_seconds"] == pytest.approx(ticks * dt, rel=1e-12)
        full_wall = r["sim_seconds"] / r["realtime_factor"]
        bare_wall = r["sim_seconds"] / r["physics_only_realtime_factor"]
        assert full_wall > 0 and bare_wall > 0
        walls += full_wall + bare_wall
        assert r["overhead_ratio"] == pytest.approx(full_wall / bare_wall)
        steps = r["robots"] * ticks * substeps
        assert r["robot_steps_per_s"] == pytest.approx(steps / full_wall)
    assert walls < elapsed


def test_batched_and_per_robot_loops_step_the_same_trajectory():
    """What the bench measures either way is one run: after the same ticks, the batched
    team's world and the per-robot controllers' world hold the same state, bit for bit."""
    digests = []
    for batched in (True, False):
        sim = bench_world(4, str(DEFAULT_ROBOT_XML))
        bench_loop(sim, batched).run(max_ticks=40)
        digests.append(hashlib.sha256(sim.data.qpos.tobytes() + sim.data.qvel.tobytes()
                                      + sim.readings().tobytes()).hexdigest())
    assert digests[0] == digests[1]


def test_bench_runs_the_full_loop_with_grid_sensing(capsys):
    assert main(["bench", "--robots", "4", "--seconds", "0.2", "--sensing", "grid", "--json"]) == 0
    (result,) = json.loads(capsys.readouterr().out)["results"]
    assert result.keys() == KEYS and result["sensing"] == "grid"
    full_wall = result["sim_seconds"] / result["realtime_factor"]
    assert result["robot_steps_per_s"] * full_wall == pytest.approx(
        4 * result["sim_seconds"] / 0.002)  # 2 ms physics steps


@pytest.mark.parametrize(
    "argv,message",
    [
        (["bench", "--robots", "0"], "--robots needs counts >= 1"),
        (["bench", "--robots", "ten"], "comma-separated whole numbers"),
        (["bench", "--model", "/nonexistent/spark.xml"], "robot model not found"),
    ],
)
def test_bench_bad_input_is_one_line(capsys, argv, message):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1


def test_bench_measures_the_per_robot_loop_on_request(capsys):
    assert main(["bench", "--robots", "3", "--seconds", "0.1", "--per-robot", "--json"]) == 0
    (result,) = json.loads(capsys.readouterr().out)["results"]
    assert result.keys() == KEYS and result["robots"] == 3
    assert result["sim_seconds"] == pytest.approx(BLOCKS * 0.02)  # at least one tick a block
