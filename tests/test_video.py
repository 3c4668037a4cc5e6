"""Videos, summary pictures and camera frames in recordings: they render on a
machine without a display (MUJOCO_GL=egl), decode, and show what the robots did."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import imageio.v2 as imageio
import numpy as np
import pytest
import rerun as rr

from mjswarm.cli import main
from mjswarm.outputs.recording import rerun_command, robot_color
from mjswarm.outputs.video import FPS, HEIGHT_PX, LINK_RGB, MARK_RGBA, WIDTH_PX

SECONDS = 20.0
SPEEDUP = 10.0


@pytest.fixture(scope="module")
def filmed_run(tmp_path_factory):
    """fig9 with 2 robots for 20 s, filmed at 10x and recorded."""
    folder = tmp_path_factory.mktemp("video")
    video, rrd, result = folder / "fig9.mp4", folder / "fig9.rrd", folder / "fig9.json"
    main(["explore", "--arena", "fig9", "--robots", "2", "--speed", "0.15", "--max-time",
          str(SECONDS), "--video", str(video), "--video-speed", str(SPEEDUP),
          "--record", str(rrd), "--json", str(result)])
    return video, rrd, json.loads(result.read_text())


def frames(path):
    with imageio.get_reader(path) as reader:
        return [frame for frame in reader]


def test_the_video_has_one_frame_per_interval_at_the_set_size(filmed_run):
    video, _, result = filmed_run
    shot = frames(video)
    interval = SPEEDUP / FPS
    assert len(shot) == 1 + int(result["sim_time_s"] / interval + 1e-6)
    assert shot[0].shape == (HEIGHT_PX, WIDTH_PX, 3)


def test_frames_far_apart_differ_where_the_robots_moved(filmed_run):
    video, _, _ = filmed_run
    shot = frames(video)
    body = slice(30, None)  # below the time written on every frame
    first, last = (f[body].astype(int) for f in (shot[0], shot[-1]))
    changed = np.abs(first - last).sum(axis=2) > 60
    assert 0.0005 < changed.mean() < 0.2  # robots and trails moved; the arena did not
    # a robot's colour (R1 red, R2 blue) is somewhere in the last frame, as trail or body
    red = (last[..., 0] > 180) & (last[..., 1] < 120) & (last[..., 2] < 120)
    blue = (last[..., 2] > 180) & (last[..., 0] < 120)
    assert red.sum() > 20 and blue.sum() > 20
    same = np.abs(shot[1][body].astype(int) - shot[2][body].astype(int)).sum(axis=2) > 60
    assert same.mean() < changed.mean()  # a third of a second apart: far less change


def test_the_recording_holds_the_video_and_verifies(filmed_run):
    _, rrd, _ = filmed_run
    done = subprocess.run([*rerun_command(), "rrd", "verify", str(rrd)],
                          check=False, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    paths = {chunk.entity_path for chunk in rr.chunk.RrdReader(rrd).stream()}
    assert {"/camera/video", "/camera"} <= paths


@pytest.mark.parametrize("source", ["rrd", "json"])
def test_a_summary_picture_is_written_and_is_not_blank(filmed_run, tmp_path, capsys, source):
    _, rrd, result = filmed_run
    if source == "rrd":
        given = rrd
    else:
        given = tmp_path / "result.json"
        given.write_text(json.dumps(result))
    out = tmp_path / "run.png"
    assert main(["plot", str(given), "-o", str(out)]) == 0
    picture = imageio.imread(out)[..., :3].astype(int)
    assert picture.shape[0] > 300 and picture.std() > 20
    assert len(np.unique(picture.reshape(-1, 3), axis=0)) > 50  # lines, labels, a table


def test_a_coverage_run_films_its_point_robots(tmp_path, capsys):
    video = tmp_path / "cov.mp4"
    assert main(["experiment", "biconnected-coverage", "--cr", "2", "--world", "point",
                 "--episodes", "2", "--video", str(video)]) == 0
    assert len(frames(video)) > 2


@pytest.mark.parametrize("argv,message", [
    (["--video", "{tmp}/missing/run.mp4"], "does not exist"),
    (["--video", "{tmp}/run.gif"], "MP4"),
    (["--video-speed", "10"], "--video-speed needs --video"),
    (["--video", "{tmp}/run.mp4", "--video-speed", "0"], "positive"),
])
def test_bad_video_options_give_one_line_and_no_file(tmp_path, capsys, argv, message):
    argv = [a.format(tmp=tmp_path) for a in argv]
    code = main(["explore", "--arena", "fig9", "--robots", "1", *argv])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and message in err[0]
    assert not list(tmp_path.rglob("*.mp4")) and not list(tmp_path.rglob("*.part"))


def test_a_bad_plot_target_gives_one_line(tmp_path, capsys):
    code = main(["plot", str(tmp_path / "none.rrd"), "-o", str(tmp_path / "x.jpg")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and ".png, .svg or .pdf" in err[0]


def test_no_working_gl_backend_is_one_line_and_no_file(tmp_path):
    """GLX without a display cannot render: the run stops at once, says why in one line
    and leaves no file behind."""
    env = {k: v for k, v in os.environ.items() if k != "DISPLAY"} | {"MUJOCO_GL": "glx"}
    target = tmp_path / "run.mp4"
    done = subprocess.run([sys.executable, "-m", "mjswarm", "explore", "--arena", "fig9",
                           "--robots", "1", "--max-time", "5", "--video", str(target)],
                          env=env, capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [done.stderr.strip()]
    assert "no working OpenGL backend (MUJOCO_GL=glx;" in done.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv", [
    ["experiment", "biconnected-coverage", "--cr", "2", "--world", "point", "--episodes", "3"],
    ["experiment", "patrol", "--world", "point", "--robots", "5", "--steps", "50"],
])
def test_coverage_and_patrol_results_are_pictured(tmp_path, capsys, argv):
    result, out = tmp_path / "result.json", tmp_path / "result.pdf"
    assert main([*argv, "--json", str(result)]) == 0
    assert main(["plot", str(result), "-o", str(out)]) == 0
    assert out.read_bytes().startswith(b"%PDF") and out.stat().st_size > 5_000


def near(frame, rgb, tolerance=40):
    """Where ``frame`` (H, W, 3) has colour ``rgb`` (after H.264's blur)."""
    return (np.abs(frame.astype(int) - np.array(rgb[:3])).sum(axis=2) < tolerance)


def test_the_legend_names_every_robot_and_the_depot_at_the_start(filmed_run):
    """At t = 0 only R1 is on the floor; the legend (top right) still shows R1's and
    R2's colours, and dark text beside them."""
    video, _, _ = filmed_run
    first = frames(video)[0]
    legend = first[24:140, 400:]
    for i in range(2):
        assert near(legend, robot_color(i)).sum() > 20, f"R{i + 1} not in the legend"
    assert (legend.sum(axis=2) < 150).sum() > 100  # its text
    assert near(legend, [int(255 * c) for c in MARK_RGBA]).sum() > 20  # the beacon's entry


def test_the_patrol_video_names_roles_target_and_links(tmp_path, capsys):
    video = tmp_path / "patrol.mp4"
    assert main(["experiment", "patrol", "--world", "point", "--robots", "4", "--steps", "40",
                 "--video", str(video)]) == 0
    last = frames(video)[-1]
    legend = last[24:200, 440:]
    assert near(legend, LINK_RGB).sum() > 10  # the radio link's entry
    for i in range(4):
        assert near(legend, robot_color(i)).sum() > 20, f"R{i + 1} not in the legend"
    assert near(last[:, :440], LINK_RGB).sum() > 10  # links drawn on the floor
