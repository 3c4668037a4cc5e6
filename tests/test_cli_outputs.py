"""A user's output files are never lost, every option is checked before any
output is opened, options that would be ignored are errors, and runs say what they do."""

from __future__ import annotations

import json
import subprocess

import pytest

import mjswarm.experiments.exploration
from mjswarm.arena import load_arena
from mjswarm.cli import main
from mjswarm.outputs.recording import rerun_command

ARENA2 = ["explore", "--arena", "arena2", "--robots", "4"]


def one_line_error(capsys, argv) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    return err


@pytest.mark.parametrize("bad", [
    ["--speed", "5"], ["--speed", "-1"], ["--strategy", "nope"], ["--launch-order", "1,1,2,3"],
    ["--radio-range", "-1"], ["--fault", "quake@1"], ["--max-time", "-5"],
])
def test_a_rejected_run_leaves_an_existing_recording_byte_for_byte(tmp_path, capsys, bad):
    target = tmp_path / "arena2.rrd"
    target.write_bytes(b"a good recording" * 1000)
    one_line_error(capsys, [*ARENA2, *bad, "--record", str(target)])
    assert target.read_bytes() == b"a good recording" * 1000
    assert [p.name for p in tmp_path.iterdir()] == ["arena2.rrd"]  # no temporary left


def test_an_interrupted_run_keeps_a_valid_partial_recording(tmp_path, capsys, monkeypatch):
    step = mjswarm.experiments.exploration.EmbodiedExploration.ticked
    calls = {"n": 0}

    def interrupt_after_a_while(self, *args):
        calls["n"] += 1
        if calls["n"] == 300:
            raise KeyboardInterrupt
        step(self, *args)

    monkeypatch.setattr(mjswarm.experiments.exploration.EmbodiedExploration, "ticked", interrupt_after_a_while)
    target = tmp_path / "run.rrd"
    target.write_bytes(b"old")
    assert main(["explore", "--arena", "arena1", "--robots", "2", "--record",
                 str(target)]) == 130
    err = capsys.readouterr().err
    partial = tmp_path / "run.partial.rrd"  # beside the user's earlier file
    assert "interrupted; partial output kept" in err and str(partial) in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.partial.rrd", "run.rrd"]
    assert target.read_bytes() == b"old"
    done = subprocess.run([*rerun_command(), "rrd", "verify", str(partial)], check=False,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr


def test_a_finished_run_replaces_the_recording_and_the_json(tmp_path, capsys):
    record, out = tmp_path / "run.rrd", tmp_path / "run.json"
    record.write_bytes(b"old")
    out.write_text("old")
    assert main(["explore", "--arena", "arena1", "--robots", "1", "--max-time", "20",
                 "--record", str(record), "--json", str(out)]) == 1  # not completed in 20 s
    assert record.stat().st_size > 1000
    assert json.loads(out.read_text())["ended_because"] == "max time"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.json", "run.rrd"]


@pytest.mark.parametrize("target,message", [
    ("missing/dir/out.json", "does not exist"), (".", "is a directory")])
def test_json_to_a_bad_path_fails_before_simulating(tmp_path, capsys, monkeypatch, target,
                                                    message):
    def no_simulation(*args, **kwargs):
        raise AssertionError("a simulation was built")

    monkeypatch.setattr(mjswarm.experiments.exploration, "Simulation", no_simulation)
    monkeypatch.chdir(tmp_path)
    assert message in one_line_error(capsys, [*ARENA2, "--json", target])


@pytest.mark.parametrize("option", [
    ["--speed", "0.1"], ["--launch-interval", "3"],
    ["--launch-order", "2,1"], ["--no-collision-avoidance"],
    ["--fault", "robot:1@3"], ["--wheel-slip", "0.01"], ["--physics", "kinematic"],
])
def test_embodied_options_with_the_graph_world_are_errors(capsys, option):
    err = one_line_error(capsys, ["explore", "--world", "graph", "--arena", "fig9",
                                  "--robots", "2", *option])
    assert option[0] in err and "embodied world" in err


@pytest.mark.parametrize("argv,message", [
    (["--max-time", "-5"], "--max-time must be a finite number > 0"),
    (["--max-time", "0"], "--max-time must be a finite number > 0"),
    (["--launch-interval", "-1"], "--launch-interval must be a finite number >= 0"),
    (["--edge-time", "length"], "--edge-time applies only to the graph world"),
])
def test_impossible_values_are_errors(capsys, argv, message):
    assert message in one_line_error(capsys, ["explore", "--arena", "fig9", "--robots", "2",
                                              *argv])


@pytest.mark.parametrize("robots,message", [
    ("5-2", "the range 5-2 is reversed"), ("1-100000", "more than 10000 values"),
    ("2000", "robot counts must be <= 1000"), ("0", "robot counts must be >= 1"),
])
def test_sweep_robot_counts_are_checked(tmp_path, capsys, robots, message):
    out = tmp_path / "sweep.jsonl"
    assert message in one_line_error(capsys, ["sweep", "--arenas", "fig9", "--robots", robots,
                                              "--seeds", "0", "--out", str(out)])
    assert not out.exists()


def test_runs_off_a_terminal_print_a_status_line(capsys):
    """Logs and CI see where a run is (pytest's stderr is no terminal)."""
    main(["explore", "--arena", "arena1", "--robots", "1", "--max-time", "10"])
    err = capsys.readouterr().err
    assert "explore arena1: 10 s simulated in" in err and "edge traversals" in err


def test_one_numbering_in_the_summary(capsys):
    assert main(["explore", "--world", "graph", "--arena", "fig9", "--robots", "2"]) == 0
    out = capsys.readouterr().out
    assert "R1 declared completion at v8; makespan 8 steps" in out


def test_a_stall_summary_counts_robots_and_relay_trips_in_their_number():
    """One robot, one relay trip: singular; two: plural."""
    from mjswarm.cli.explore import summary
    from mjswarm.experiments.runs import run_exploration

    result = run_exploration(load_arena("arena1"), 2, world="graph", radio_range_m=1.5,
                             connectivity="connected")
    d = result.to_dict()
    d["world"] = "graph"
    assert d["stalled"] and d["robots_needed"] == 2 and d["relay_trips"] == 1
    assert "though 2 robots could reach" in summary(d) and "1 relay trip;" in summary(d)
    d["robots_needed"], d["relay_trips"] = 1, 2
    assert "though 1 robot could reach" in summary(d) and "2 relay trips;" in summary(d)
