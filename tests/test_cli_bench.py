"""``mjswarm bench`` end to end: JSON figures and one-line errors."""

from __future__ import annotations

import json

import pytest

from mjswarm.cli import main


def test_bench_json_reports_every_key(capsys):
    assert main(["bench", "--robots", "1,3", "--seconds", "0.2", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [r["robots"] for r in out["results"]] == [1, 3]
    assert {r["sensing"] for r in out["results"]} == {"mujoco"}  # auto, small teams
    for r in out["results"]:
        assert r["realtime_factor"] > 0 and r["physics_only_realtime_factor"] > 0
        ratio = r["physics_only_realtime_factor"] / r["realtime_factor"]
        assert r["overhead_ratio"] == pytest.approx(ratio)


def test_bench_runs_the_full_loop_with_grid_sensing(capsys):
    assert main(["bench", "--robots", "4", "--seconds", "0.2", "--sensing", "grid", "--json"]) == 0
    (result,) = json.loads(capsys.readouterr().out)["results"]
    assert result["sensing"] == "grid" and result["robot_steps_per_s"] > 0


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
    assert result["robots"] == 3 and result["realtime_factor"] > 0
