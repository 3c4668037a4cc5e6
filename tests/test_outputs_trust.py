"""Outputs a user can trust (special files, symlinks, interruptions, one path for
two outputs, file modes) and inputs refused in one line before any work."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
import threading
from pathlib import Path

import pytest

import mjswarm.experiments.exploration
from mjswarm.cli import main

SHORT = ["explore", "--arena", "arena1", "--robots", "1", "--max-time", "2"]
GRAPH = ["explore", "--world", "graph", "--arena", "fig9", "--robots", "2"]


def one_line_error(capsys, argv) -> str:
    assert main(argv) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("mjswarm: error:"), err
    return err


class Reader(threading.Thread):
    """Reads a FIFO or a pipe to its end, as `cat` would."""

    def __init__(self, path: Path | None = None, fd: int | None = None) -> None:
        super().__init__(daemon=True)
        self.path, self.fd, self.data = path, fd, b""

    def run(self) -> None:
        with (open(self.path, "rb") if self.path else os.fdopen(self.fd, "rb")) as source:
            self.data = source.read()


# ------------------------------------------------------------------ special files


def test_json_into_a_fifo_reaches_its_reader_and_the_fifo_stays(tmp_path, capsys):
    fifo = tmp_path / "results"
    os.mkfifo(fifo)
    reader = Reader(fifo)
    reader.start()
    assert main([*GRAPH, "--json", str(fifo)]) == 0
    reader.join(timeout=30)
    assert json.loads(reader.data)["makespan"] == 8
    assert stat.S_ISFIFO(fifo.lstat().st_mode)
    assert [p.name for p in tmp_path.iterdir()] == ["results"]  # no temporary beside it


def test_json_into_dev_fd_of_a_pipe_is_written(capsys):
    """``--json >(cat)``: the shell passes /dev/fd/N, a pipe; nothing can be renamed there."""
    r, w = os.pipe()
    reader = Reader(fd=r)
    reader.start()
    try:
        assert main([*GRAPH, "--json", f"/dev/fd/{w}"]) == 0
    finally:
        os.close(w)
    reader.join(timeout=30)
    assert json.loads(reader.data)["declared_at"] == "v8"


def test_a_character_device_stays_a_device(tmp_path, capsys):
    null = tmp_path / "mynull"
    try:
        os.mknod(null, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    except PermissionError:
        pytest.skip("making a device node needs CAP_MKNOD")
    assert main([*GRAPH, "--json", str(null)]) == 0
    assert stat.S_ISCHR(null.lstat().st_mode) and null.lstat().st_rdev == os.makedev(1, 3)


def test_a_symlink_is_written_through_and_stays_a_link(tmp_path, capsys):
    real, link = tmp_path / "real.json", tmp_path / "link.json"
    real.write_text("old")
    link.symlink_to(real.name)
    assert main([*GRAPH, "--json", str(link)]) == 0
    assert link.is_symlink() and os.readlink(link) == "real.json"
    assert json.loads(real.read_text())["makespan"] == 8


def test_a_recording_to_a_fifo_streams_to_its_reader(tmp_path, capsys):
    fifo = tmp_path / "stream.rrd"
    os.mkfifo(fifo)
    reader = Reader(fifo)
    reader.start()
    assert main([*SHORT, "--record", str(fifo)]) == 1  # not completed in 2 s
    reader.join(timeout=60)
    assert len(reader.data) > 1000 and stat.S_ISFIFO(fifo.lstat().st_mode)


# ------------------------------------------------------------------ modes


def test_outputs_get_the_mode_open_would_give_and_keep_an_existing_one(tmp_path, capsys):
    old = os.umask(0o022)
    try:
        new, kept = tmp_path / "new.json", tmp_path / "kept.json"
        kept.write_text("old")
        kept.chmod(0o664)
        assert main([*GRAPH, "--json", str(new)]) == 0
        assert main([*GRAPH, "--json", str(kept)]) == 0
        record = tmp_path / "run.rrd"
        assert main([*SHORT, "--record", str(record)]) == 1
    finally:
        os.umask(old)
    assert stat.S_IMODE(new.stat().st_mode) == 0o644
    assert stat.S_IMODE(kept.stat().st_mode) == 0o664
    assert stat.S_IMODE(record.stat().st_mode) == 0o644


# ------------------------------------------------------------------ interruptions


def interrupt_after(monkeypatch, ticks: int) -> None:
    step = mjswarm.experiments.exploration.EmbodiedExploration.ticked
    calls = {"n": 0}

    def step_then_interrupt(self, *args):
        calls["n"] += 1
        if calls["n"] == ticks:
            raise KeyboardInterrupt
        step(self, *args)

    monkeypatch.setattr(mjswarm.experiments.exploration.EmbodiedExploration, "ticked",
                        step_then_interrupt)


def test_ctrl_c_keeps_the_earlier_recording_and_json_and_writes_the_partial_beside(
        tmp_path, capsys, monkeypatch):
    interrupt_after(monkeypatch, 200)
    record, out = tmp_path / "keep.rrd", tmp_path / "keep.json"
    record.write_bytes(b"a complete recording" * 100)
    out.write_text('{"complete": true}')
    assert main(["explore", "--arena", "arena1", "--robots", "2", "--record", str(record),
                 "--json", str(out)]) == 130
    captured = capsys.readouterr()
    assert record.read_bytes() == b"a complete recording" * 100
    assert json.loads(out.read_text()) == {"complete": True}
    partial = json.loads((tmp_path / "keep.partial.json").read_text())
    assert partial["ended_because"] == "interrupted" and partial["sim_time_s"] > 3.0
    assert (tmp_path / "keep.partial.rrd").stat().st_size > 1000
    assert "keep.partial.rrd (" in captured.err and "left as it was" in captured.err
    assert "not completed (interrupted)" in captured.out  # the summary is still printed


def test_ctrl_c_with_no_earlier_file_writes_the_json_under_its_name(tmp_path, capsys,
                                                                    monkeypatch):
    interrupt_after(monkeypatch, 100)
    out = tmp_path / "run.json"
    assert main([*SHORT[:-2], "--json", str(out)]) == 130
    assert json.loads(out.read_text())["ended_because"] == "interrupted"
    assert [p.name for p in tmp_path.iterdir()] == ["run.json"]


# ------------------------------------------------------------------ refused before work


@pytest.mark.parametrize("argv, words", [
    (["--record", "same.rrd", "--json", "same.rrd"], "--record and --json name the same file"),
    (["--record", "x.mp4", "--video", "x.mp4"], "--record writes .rrd files"),
    (["--record", "x.rrd", "--video", "./x.rrd"], "--record and --video name the same"),
    (["--seed", "-1"], "--seed must be a whole number >= 0, got -1"),
    (["--speed", "nan"], "--speed must be a finite number > 0, got nan"),
    (["--line-noise", "-0.1"], "--line-noise must be a finite number >= 0"),
    (["--stall-timeout", "nan"], "--stall-timeout must be a finite number > 0"),
    (["--launch-order", "1,1,2"], "--launch-order must name each of R1..R3 once"),
    (["--fault", "robot:1@100", "--max-time", "50"], "fault robot:1@100 can never fire"),
    (["--robots", "1001"], "at most 1000 robots"),
])
def test_bad_explore_input_is_one_line_before_any_file(tmp_path, capsys, monkeypatch, argv,
                                                       words):
    monkeypatch.chdir(tmp_path)
    robots = [] if "--robots" in argv else ["--robots", "3"]
    assert words in one_line_error(capsys, ["explore", "--arena", "arena1", *robots, *argv])
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv", [
    ["explore", "--world", "graph", "--arena", "fig9", "--robots", "2", "--seed", "-1"],
    ["sweep", "--arenas", "fig9", "--robots", "2", "--seeds", "-1", "--out", "s.jsonl"],
    ["experiment", "patrol", "--seed", "-1"],
    ["experiment", "biconnected-coverage", "--cr", "2", "--seed", "-1"],
])
def test_negative_seeds_are_one_line_and_exit_2(tmp_path, capsys, monkeypatch, argv):
    monkeypatch.chdir(tmp_path)
    assert "must be a whole number >= 0" in one_line_error(capsys, argv)


@pytest.mark.parametrize("arena, words", [
    ("lattice:100000x100000", "arenas have at most 10000"),
    ("random-tree:20000:1", "arenas have at most 10000"),
])
def test_arenas_too_big_for_the_machine_are_refused_at_once(capsys, arena, words):
    assert words in one_line_error(capsys, ["arena", "show", arena])


def test_a_vertex_far_beyond_any_floor_is_refused(tmp_path, capsys):
    spec = tmp_path / "far.json"
    spec.write_text(json.dumps({"name": "far", "root": "a", "edges": [["a", "b"]],
                                "vertices": {"a": [0, 0], "b": [1e300, 0]}}))
    assert "within +-1000 m" in one_line_error(capsys, ["arena", "show", str(spec)])


# ------------------------------------------------------------------ what a run reports


def test_a_fault_the_run_never_reached_is_reported_not_fired(capsys):
    """The only robot fails at 1 s, so the run ends ('all robots stopped') before the
    beacon fault's time: the result says so instead of dropping it."""
    assert main(["explore", "--arena", "arena1", "--robots", "1", "--fault", "robot:1@1",
                 "--fault", "beacon:v2@50", "--json", "-"]) == 1
    faults = json.loads(capsys.readouterr().out)["faults"]
    assert faults == [{"fault": "robot:1@1", "fired": True, "at_s": 1.0},
                      {"fault": "beacon:v2@50", "fired": False, "at_s": None}]


def test_every_ending_gets_the_full_summary(tmp_path, capsys):
    record = tmp_path / "r.rrd"
    assert main([*SHORT, "--record", str(record)]) == 1
    out = capsys.readouterr().out
    assert "not completed (max time)" in out
    for words in ("physics: 2.0 s simulated in", "collisions: 0 robot-robot contact",
                  "traversals: 0 in total", f"recording: {record}"):
        assert words in out


# ------------------------------------------------------------------ OpenGL backends


@pytest.mark.parametrize("backend", ["bogus", "osmesa"])
def test_an_unusable_gl_backend_breaks_only_videos(tmp_path, backend):
    env = {**os.environ, "MUJOCO_GL": backend}
    run = [sys.executable, "-m", "mjswarm.cli"]
    for argv in (["--help"], ["explore", "--arena", "arena1", "--robots", "1",
                              "--max-time", "1"]):
        done = subprocess.run([*run, *argv], env=env, cwd=tmp_path, capture_output=True,
                              text=True, timeout=120, check=False)
        assert done.returncode in (0, 1), done.stderr
    if backend == "osmesa" and "OSMesa" in subprocess.run(
            ["ldconfig", "-p"], capture_output=True, text=True, check=False).stdout:
        return  # installed here: videos work with it
    done = subprocess.run([*run, "explore", "--arena", "arena1", "--robots", "1",
                           "--max-time", "1", "--video", "v.mp4"], env=env, cwd=tmp_path,
                          capture_output=True, text=True, timeout=120, check=False)
    err = done.stderr.strip().splitlines()
    assert done.returncode == 2 and "set MUJOCO_GL=egl" in err[-1], done.stderr
    assert f"MUJOCO_GL={backend}" in err[-1] and not (tmp_path / "v.mp4").exists()
