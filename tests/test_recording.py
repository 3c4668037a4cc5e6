"""Recordings: files rerun accepts, the documented entity tree, and the
per-tick data read back equal to what was logged, over seeded random runs."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest
import rerun as rr

from mjswarm.arena import load_arena
from mjswarm.arena.builder import arena_primitives
from mjswarm.cli import main
from mjswarm.errors import MjswarmError
from mjswarm.outputs.recording import Recorder, has_display, open_viewer, rerun_command

REPO = Path(__file__).resolve().parents[1]


def _random_run(rng: np.random.Generator, n: int, ticks: int) -> dict:
    """Synthetic per-tick data: poses, sensors (some IR NaN), speeds, sparse bearings."""
    poses = np.column_stack([rng.uniform(-1, 3, (ticks * n, 2)),
                             rng.uniform(-math.pi, math.pi, ticks * n)]).reshape(ticks, n, 3)
    ir = rng.uniform(0.0, 0.1, (ticks, n, 3))
    ir[rng.random((ticks, n, 3)) < 0.4] = np.nan
    bearings = [[[(j, float(rng.uniform(-1.0, 1.0))) for j in range(n)
                  if j != i and rng.random() < 0.3] for i in range(n)] for _ in range(ticks)]
    return {
        "steps": np.arange(ticks) * 3 + 5,
        "times": (np.arange(ticks) * 3 + 5) * 0.013,
        "poses": poses,
        "line": rng.uniform(0.0, 0.05, (ticks, n, 3)),
        "ir": ir,
        "speed": rng.uniform(0.0, 0.2, (ticks, n)),
        "bearings": bearings,
        "encoders": np.cumsum(rng.uniform(-0.2, 0.2, (ticks, n, 2)), axis=0),
        "battery": rng.uniform(8.0, 10.0, (ticks, n)),
    }


def _record(path: Path, arena, run: dict, chunk_ticks: int) -> None:
    n = run["poses"].shape[1]
    with Recorder(path, arena, n, chunk_ticks=chunk_ticks) as rec:
        for k, step in enumerate(run["steps"]):
            rec.log_tick(int(step), float(run["times"][k]), run["poses"][k], run["line"][k],
                         run["ir"][k], run["speed"][k], run["bearings"][k],
                         run["encoders"][k], run["battery"][k])


def _read(path: Path) -> dict[str, dict[str, list]]:
    """Recording store of an .rrd: entity -> column -> values, all chunks concatenated
    (static chunks under the key 'static:<entity>'); sim_time as integer nanoseconds."""
    out: dict[str, dict[str, list]] = defaultdict(lambda: defaultdict(list))
    for chunk in rr.chunk.RrdReader(path).stream():
        batch = chunk.to_record_batch()
        key = f"static:{chunk.entity_path}" if chunk.is_static else chunk.entity_path
        for name in batch.schema.names:
            column = batch.column(name)
            if name == "sim_time":
                column = column.cast(pa.int64())
            if name != "rerun.controls.RowId":
                out[key][name].extend(column.to_pylist())
    return out


def _by_step(columns: dict[str, list], name: str) -> tuple[np.ndarray, list]:
    order = np.argsort(columns["step"], kind="stable")
    return np.asarray(columns["step"])[order], [columns[name][i] for i in order]


@pytest.fixture(scope="module")
def fig9_recording(tmp_path_factory) -> tuple[Path, dict]:
    """3 robots, 300 ticks on fig9 with events, graphs, a beacon and a radio graph."""
    path = tmp_path_factory.mktemp("rec") / "fig9.rrd"
    arena = load_arena("fig9")
    run = _random_run(np.random.default_rng(9), 3, 300)
    with Recorder(path, arena, 3, chunk_ticks=128, radio=True) as rec:
        for k, step in enumerate(run["steps"]):
            t = float(run["times"][k])
            rec.log_tick(int(step), t, run["poses"][k], run["line"][k], run["ir"][k],
                         run["speed"][k], run["bearings"][k], run["encoders"][k],
                         run["battery"][k])
            if k == 10:
                rec.log_event(int(step), t, "run started")
                rec.log_event(int(step), t, "arrived at vertex b1", robot=2)
            if k in (20, 21):  # the same graph twice: logged once
                rec.log_explored_graph(int(step), t, 1, {"b1": (0.0, 0.6), "b2": (0.6, 0.6)},
                                       [("b1", "b2")])
            if k == 30:
                rec.log_beacon(int(step), t, "b1", "I(b1): e1 explored")
            if k == 40:
                rec.log_radio(int(step), t, [(0, 1), (1, 2)], {0: "yes", 1: "no"}, truth="yes")
    return path, run


def test_rerun_verifies_the_file(fig9_recording):
    path, _ = fig9_recording
    done = subprocess.run([*rerun_command(), "rrd", "verify", str(path)],
                          check=False, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr


def test_entity_tree_and_timelines(fig9_recording):
    path, _ = fig9_recording
    data = _read(path)
    expected = {"static:/arena/strips", "static:/arena/walls", "static:/arena/vertices",
                "/map/R2", "/beacons/b1", "/radio/graph", "/radio/links", "/radio/truth",
                "/events", "/events/R3"}
    for r in ("R1", "R2", "R3"):
        expected |= {f"/robots/{r}/pose", f"static:/robots/{r}/pose",
                     f"static:/robots/{r}/pose/heading", f"/robots/{r}/trail",
                     f"/robots/{r}/speed", f"/robots/{r}/sensors/line",
                     f"/robots/{r}/sensors/ir", f"/robots/{r}/sensors/encoders",
                     f"/robots/{r}/battery"}
    assert expected <= set(data)
    assert not any("/r0" in key or "/r1" in key for key in data)  # one numbering: R1..RK
    assert any(key.startswith("/robots/R1/bearings/R") for key in data)
    for key, columns in data.items():
        if not key.startswith("static:") and key != "/__properties":
            assert {"step", "sim_time"} <= set(columns), key
    assert len(data["/map/R2"]["step"]) == 1  # the repeated identical graph was skipped
    assert data["/radio/graph"]["GraphNodes:labels"] == [["R1: yes", "R2: no", "R3"]]
    assert data["/events/R3"]["TextLog:text"] == [["arrived at vertex b1"]]


def test_static_arena_matches_the_spec(fig9_recording):
    path, _ = fig9_recording
    arena = load_arena("fig9")
    strips, walls = arena_primitives(arena)
    data = _read(path)
    centres = np.array(data["static:/arena/strips"]["Boxes3D:centers"][0])[:, :2]
    midpoints = [((s.start[0] + s.end[0]) / 2, (s.start[1] + s.end[1]) / 2) for s in strips]
    np.testing.assert_allclose(centres, midpoints, atol=1e-6)
    assert len(data["static:/arena/walls"]["Boxes3D:centers"][0]) == len(walls)
    assert data["static:/arena/vertices"]["Points3D:labels"][0] == list(arena.vertices)


def _view_names(path: Path) -> list[str]:
    reader = rr.chunk.RrdReader(path)
    names = []
    for chunk in reader.stream(store=reader.blueprints()[0]):
        batch = chunk.to_record_batch()
        if "ViewBlueprint:display_name" in batch.schema.names:
            names += [row[0] for row in batch.column("ViewBlueprint:display_name").to_pylist()
                      if row]
    return names


def test_blueprint_has_the_review_views(fig9_recording):
    path, _ = fig9_recording
    reader = rr.chunk.RrdReader(path)
    kinds = []
    for chunk in reader.stream(store=reader.blueprints()[0]):
        batch = chunk.to_record_batch()
        if "ViewBlueprint:class_identifier" in batch.schema.names:
            kinds += [row[0] for row in batch.column("ViewBlueprint:class_identifier").to_pylist()]
    assert {"3D", "Graph", "TimeSeries", "TextLog", "TextDocument"} <= set(kinds)
    names = _view_names(path)
    assert {"radio", "radio truth", "battery (V)", "encoders (rad)", "map R1"} <= set(names)


def test_blueprint_without_radio_has_no_radio_views(tmp_path):
    """A run without radios does not open on empty radio views."""
    path = tmp_path / "quiet.rrd"
    Recorder(path, load_arena("fig9"), 2).close()
    names = _view_names(path)
    assert "map R2" in names and "radio" not in names and "radio truth" not in names


@pytest.mark.parametrize("seed", range(6))
def test_ticks_read_back_equal_to_what_was_logged(tmp_path, seed):
    rng = np.random.default_rng(seed)
    n, ticks = int(rng.integers(1, 6)), int(rng.integers(1, 260))
    chunk_ticks = int(rng.choice([1, 7, 64, 500]))
    run = _random_run(rng, n, ticks)
    arena = load_arena(str(rng.choice(["fig9", "arena1", "arena2", "lattice:3x4"])))
    path = tmp_path / "run.rrd"
    _record(path, arena, run, chunk_ticks)
    data = _read(path)
    for i in range(n):
        robot = f"/robots/R{i + 1}"
        steps, translation = _by_step(data[f"{robot}/pose"], "Transform3D:translation")
        np.testing.assert_array_equal(steps, run["steps"])
        xy = run["poses"][:, i, :2]
        np.testing.assert_allclose(np.array(translation)[:, 0, :2], xy, atol=1e-5)
        _, quaternion = _by_step(data[f"{robot}/pose"], "Transform3D:quaternion")
        q = np.array(quaternion)[:, 0]
        yaw = 2 * np.arctan2(q[:, 2], q[:, 3])
        np.testing.assert_allclose(np.angle(np.exp(1j * (yaw - run["poses"][:, i, 2]))), 0,
                                   atol=1e-5)
        _, times = _by_step(data[f"{robot}/pose"], "sim_time")
        np.testing.assert_allclose(np.array(times) * 1e-9, run["times"], atol=1e-9)
        _, trail = _by_step(data[f"{robot}/trail"], "LineStrips3D:strips")
        segments = np.array(trail)[:, 0, :, :2]  # (ticks, 2 points, xy)
        np.testing.assert_allclose(segments[:, 1], xy, atol=1e-5)
        np.testing.assert_allclose(segments[1:, 0], xy[:-1], atol=1e-5)
        for entity, key in (("speed", "speed"), ("sensors/line", "line"), ("sensors/ir", "ir"),
                            ("sensors/encoders", "encoders"), ("battery", "battery")):
            _, values = _by_step(data[f"{robot}/{entity}"], "Scalars:scalars")
            np.testing.assert_array_equal(np.array(values, dtype=float).reshape(ticks, -1),
                                          run[key][:, i].reshape(ticks, -1))
    logged = defaultdict(list)
    for k, per_robot in enumerate(run["bearings"]):
        for i, seen in enumerate(per_robot):
            for j, bearing in seen:
                logged[f"/robots/R{i + 1}/bearings/R{j + 1}"].append((run["steps"][k], bearing))
    read = {key: list(zip(*_by_step(columns, "Scalars:scalars")))
            for key, columns in data.items() if key.startswith("/robots/") and "/bearings/" in key}
    assert set(read) == set(logged)
    for key, rows in logged.items():
        assert [s for s, _ in read[key]] == [s for s, _ in rows]
        np.testing.assert_array_equal([v[0] for _, v in read[key]], [v for _, v in rows])


def test_missing_directory_is_one_line_error(tmp_path):
    with pytest.raises(MjswarmError, match="does not exist") as err:
        Recorder(tmp_path / "nope" / "run.rrd", load_arena("fig9"), 2)
    assert "\n" not in str(err.value)
    with pytest.raises(MjswarmError, match="is a directory"):
        Recorder(tmp_path, load_arena("fig9"), 2)
    with pytest.raises(MjswarmError, match="at least 1 robot"):
        Recorder(tmp_path / "run.rrd", load_arena("fig9"), 0)


def test_misuse_is_caught(tmp_path):
    rec = Recorder(tmp_path / "run.rrd", load_arena("fig9"), 2)
    with pytest.raises(ValueError, match="poses"):
        rec.log_tick(0, 0.0, np.zeros(3), np.zeros((2, 3)), np.zeros((2, 3)), np.zeros(2),
                     [[], []], np.zeros((2, 2)), np.zeros(2))
    with pytest.raises(ValueError, match="outside"):
        rec.log_radio(0, 0.0, [(0, 2)])
    rec.close()
    rec.close()
    with pytest.raises(RuntimeError, match="closed"):
        rec.log_event(1, 0.02, "late")


def _env_without_display() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(REPO), env.get("PYTHONPATH")]))
    return env


@pytest.mark.skipif(sys.platform in ("darwin", "win32"), reason="these always have a display")
def test_view_without_display_exits_2_with_one_line(fig9_recording):
    path, _ = fig9_recording
    done = subprocess.run([sys.executable, "-m", "mjswarm.cli", "view", str(path)],
                          check=False, capture_output=True, text=True, timeout=60, cwd=REPO,
                          env=_env_without_display())
    assert done.returncode == 2
    assert done.stdout == ""
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "no display" in lines[0]


def test_view_rejects_missing_and_non_rrd_files(tmp_path, capsys):
    assert main(["view", str(tmp_path / "none.rrd")]) == 2
    text = tmp_path / "notes.rrd"
    text.write_text("not a recording")
    assert main(["view", str(text)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "no recording" in err[0] and "not a rerun" in err[1]


def test_view_with_display_runs_the_rerun_viewer(fig9_recording, monkeypatch):
    path, _ = fig9_recording
    calls = []
    monkeypatch.setenv("DISPLAY", ":0")
    monkeypatch.setattr(subprocess, "call", lambda argv: calls.append(argv) or 0)
    assert has_display()
    assert open_viewer(path) == 0
    (argv,) = calls
    assert argv[-1] == str(path) and os.access(argv[0], os.X_OK)


@pytest.mark.parametrize("argv,entities", [
    (["experiment", "biconnected-coverage", "--cr", "2", "--world", "embodied",
      "--episodes", "3"],
     {"/robots/R1/trail", "/robots/R1/state/busy", "/robots/R6/state/known_regions",
      "/radio/graph", "/radio/links", "/events/R6"}),
    (["experiment", "patrol", "--world", "point", "--robots", "5", "--steps", "120"],
     {"/robots/R2/trail", "/states/R2/role", "/robots/R1/state/connections",
      "/radio/graph", "/radio/links"}),
])
def test_coverage_and_patrol_runs_record_and_verify(tmp_path, capsys, argv, entities):
    """Recording hangs off the one loop: the open-floor experiments record too."""
    rrd = tmp_path / "run.rrd"
    assert main([*argv, "--record", str(rrd)]) == 0
    done = subprocess.run([*rerun_command(), "rrd", "verify", str(rrd)],
                          check=False, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    paths = {chunk.entity_path for chunk in rr.chunk.RrdReader(rrd).stream()}
    assert entities <= paths
    assert not list(tmp_path.glob(".*.part"))  # the temporary file was moved into place


def test_an_experiments_bad_recording_path_fails_before_work(tmp_path, capsys):
    target = tmp_path / "missing" / "run.rrd"
    code = main(["experiment", "patrol", "--world", "point", "--record", str(target)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "does not exist" in err[0]
    assert not target.parent.exists()
