"""The command line's edges: impossible numbers, caps, SIGTERM, partial outputs named as
written, a quick ``--help``, and help texts that name the papers."""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import mujoco
import pytest
from test_outputs_trust import interrupt_after

import mjswarm.experiments.exploration
from mjswarm.cli import build_parser, main

REPO = Path(__file__).resolve().parent.parent


def one_line_error(capsys, argv) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("mjswarm: error:"), err
    return err


# ------------------------------------------------------------------ numbers and caps


@pytest.mark.parametrize("argv, words", [
    (["explore", "--arena", "arena2", "--robots", "2", "--max-time", "inf"],
     "--max-time must be a finite number > 0, got inf"),
    (["explore", "--arena", "arena2", "--robots", "2", "--radio-range", "1e308",
      "--connectivity", "connected"], "--radio-range must be at most 10000"),
    (["explore", "--arena", "arena2", "--robots", "2", "--radio-range", "1e308"],
     "--radio-range must be at most 10000"),
    (["explore", "--world", "graph", "--arena", "arena2", "--robots", "2",
      "--radio-range", "1e308"], "--radio-range must be at most 10000"),
    (["experiment", "biconnected-coverage", "--cr", "2", "--region-diameter", "1e308",
      "--world", "point"], "--region-diameter must be at most 10"),
    (["arena", "export", "arena2", "."], "it is a directory"),
    (["bench", "--robots", "2", "--seconds", "nan"], "--seconds must be a finite number > 0"),
    (["bench", "--robots", "2", "--seconds", "inf"], "--seconds must be a finite number > 0"),
    (["experiment", "patrol", "--robots", "-1"], "--robots must be a whole number >= 3"),
    (["arena", "export", "arena2", "out.xml", "--robots", "5000"],
     "--robots must be at most 1000 (the largest team any run takes)"),
    (["bench", "--robots", "5000"], "--robots takes counts up to 1000"),
    (["experiment", "patrol", "--robots", "100000", "--world", "point"],
     "--robots must be at most 200"),
    (["compare", "exploration", "--out", "missing/dir"], "directory"),
    (["compare", "connectivity", "--out", "missing/dir"], "directory"),
    (["connectivity", "--positions", "team.json", "--method", "stamps", "--range", "inf"],
     "--range must be a finite number > 0"),
])
def test_impossible_numbers_and_caps_are_one_line_before_any_file(tmp_path, capsys,
                                                                  monkeypatch, argv, words):
    monkeypatch.chdir(tmp_path)
    assert words in one_line_error(capsys, argv)
    assert list(tmp_path.iterdir()) == []


def test_a_missing_output_directory_is_named(tmp_path, capsys):
    err = one_line_error(capsys, ["compare", "exploration", "--out",
                                  str(tmp_path / "a" / "b")])
    assert f"directory {tmp_path / 'a'} does not exist" in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("option, words", [
    (["--video", "x.mp4"], "--video applies only to the embodied world"),
    (["--speed", "0.1"], "--speed applies only to the embodied world"),
    (["--speed", "0.1", "--video", "x.mp4"], "--speed, --video apply only to the embodied"),
])
def test_embodied_options_in_the_graph_world_read_well(tmp_path, capsys, monkeypatch, option,
                                                       words):
    monkeypatch.chdir(tmp_path)
    assert words in one_line_error(capsys, ["explore", "--world", "graph", "--arena", "fig9",
                                            "--robots", "2", *option])


def test_the_random_walk_example_refuses_a_missing_folder_in_one_line(tmp_path):
    done = subprocess.run([sys.executable, str(REPO / "examples" / "random_walk.py"), "--out",
                           "missing_dir"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=120, check=False)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        "random_walk.py: error: --out missing_dir is not a directory"]


# ------------------------------------------------------------------ arena export


def test_exported_robots_stand_apart_in_the_depot(tmp_path, capsys):
    out = tmp_path / "arena2.xml"
    assert main(["arena", "export", "arena2", str(out), "--robots", "4"]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    data = mujoco.MjData(model)
    root = model.body_rootid[model.geom_bodyid]  # each geom's robot (0: the world)
    touching = 0
    for _ in range(200):  # 0.4 s at rest
        mujoco.mj_step(model, data)
        for c in data.contact[:data.ncon]:
            a, b = root[c.geom1], root[c.geom2]
            touching += bool(a and b and a != b)
    assert touching == 0
    assert len({tuple(data.xpos[b]) for b in set(root) if b}) == 4


# ------------------------------------------------------------------ interruptions


def test_the_summary_and_json_name_the_partial_actually_written(tmp_path, capsys,
                                                                monkeypatch):
    interrupt_after(monkeypatch, 20)
    record = tmp_path / "run.rrd"
    record.write_bytes(b"an earlier recording")
    assert main(["explore", "--arena", "arena1", "--robots", "1", "--record", str(record),
                 "--json", "-"]) == 130
    partial = str(tmp_path / "run.partial.rrd")
    result = json.loads(capsys.readouterr().out)
    assert result["recording"] == partial and result["ended_because"] == "interrupted"
    interrupt_after(monkeypatch, 20)
    assert main(["explore", "--arena", "arena1", "--robots", "1", "--record", str(record)]) \
        == 130
    assert f"recording: {tmp_path / 'run.partial-2.rrd'}" in capsys.readouterr().out


def test_ctrl_c_before_the_first_pose_keeps_no_recording_and_says_so(tmp_path, capsys,
                                                                     monkeypatch):
    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt  # while the world is being built: after the recording opened

    monkeypatch.setattr(mjswarm.experiments.exploration.EmbodiedExploration, "run", interrupt)
    record = tmp_path / "run.rrd"
    assert main(["explore", "--arena", "arena1", "--robots", "1", "--record",
                 str(record)]) == 130
    assert "nothing recorded yet, so not kept: " + str(record) in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_sigterm_ends_a_run_as_ctrl_c_does(tmp_path):
    """The partial recording and JSON are kept under their names, the summary printed."""
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    run = subprocess.Popen(
        [sys.executable, "-m", "mjswarm.cli", "explore", "--arena", "arena1", "--robots", "1",
         "--record", "run.rrd", "--json", "run.json"], cwd=tmp_path, env=env,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not list(tmp_path.glob(".run.rrd.*.part")) and time.monotonic() < deadline:
        time.sleep(0.05)  # the recording has started
    time.sleep(1.0)
    run.send_signal(signal.SIGTERM)
    out, err = run.communicate(timeout=120)
    assert run.returncode == 130, err
    assert "partial output kept: run.rrd, run.json" in err
    assert "not completed (interrupted)" in out and "recording: run.rrd" in out
    assert json.loads((tmp_path / "run.json").read_text())["ended_because"] == "interrupted"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.json", "run.rrd"]


# ------------------------------------------------------------------ plot


def test_plot_of_a_truncated_recording_prints_only_its_error(tmp_path, capsys):
    """In a process of its own: pytest would catch the reader's warnings."""
    record = tmp_path / "run.rrd"
    assert main(["explore", "--arena", "arena1", "--robots", "1", "--max-time", "1",
                 "--record", str(record)]) == 1
    record.write_bytes(record.read_bytes()[: record.stat().st_size // 2])
    done = subprocess.run([sys.executable, "-m", "mjswarm.cli", "plot", str(record), "-o",
                           str(tmp_path / "run.png")], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(REPO)}, timeout=120,
                          check=False)
    err = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(err) == 1, done.stderr
    assert err[0].startswith("mjswarm: error: cannot read recording")


# ------------------------------------------------------------------ help


HEAVY = ("mujoco", "rerun", "numba", "scipy", "matplotlib")


def test_building_the_parser_imports_no_heavy_library():
    code = ("import sys, mjswarm.cli; mjswarm.cli.build_parser(); "
            f"print(*[m for m in {HEAVY!r} if m in sys.modules])")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(REPO)}, timeout=120,
                          check=True)
    assert done.stdout.split() == []


def _parsers(parser: argparse.ArgumentParser):
    """``parser`` and every subparser under it."""
    yield parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                yield from _parsers(sub)


def test_help_texts_name_papers_not_history():
    parsers = list(_parsers(build_parser()))
    assert len(parsers) > 15
    for parser in parsers:
        text = parser.format_help().lower()
        for word in ("issue", "session", "seed 00", "was:"):
            assert word not in text, (parser.prog, word)
