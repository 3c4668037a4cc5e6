"""``mjswarm plot`` pictures read on their own: read back as SVG with
text kept as text, they name the arena's parts, every robot (one that never left the
depot too), the end dots, how the run ended, a partial recording, and the graph world's
visit order."""

from __future__ import annotations

import json
import re

import matplotlib
import numpy as np
import pytest

from mjswarm.arena import load_arena
from mjswarm.cli import main
from mjswarm.outputs.plot import plot
from mjswarm.outputs.recording import Recorder


def svg_texts(result, out):
    """The texts of ``result``'s picture, drawn as SVG with its text as text."""
    with matplotlib.rc_context({"svg.fonttype": "none"}):
        plot(result, out)
    svg = out.read_text()
    return [re.sub(r"<[^>]+>", "", t).strip() for t in re.findall(r"<text[^>]*>(.*?)</text>",
                                                                     svg, re.S)]


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """fig9 with 2 robots for 15 s: R1 launched and moving, R2 still in the depot."""
    rrd = tmp_path_factory.mktemp("plot") / "fig9.rrd"
    main(["explore", "--arena", "fig9", "--robots", "2", "--max-time", "15", "--record",
          str(rrd)])
    return rrd


def test_a_recording_plot_names_the_arena_every_robot_and_the_ending(recorded, tmp_path):
    texts = svg_texts(recorded, tmp_path / "run.svg")
    for entry in ("line on the floor", "wall", "vertex", "R1", "R2 (never left the depot)", "where a robot was last", "run ended",
                  "max time"):
        assert entry in texts, entry
    assert set(load_arena("fig9").vertices) <= set(texts)  # every vertex is named
    assert "figure" not in texts and not any("PARTIAL" in t for t in texts)


def test_a_recording_without_its_ending_is_titled_partial(tmp_path):
    spec = load_arena("fig9")
    rrd = tmp_path / "cut.rrd"
    with Recorder(rrd, spec, 1, sensors=False) as recorder:  # no "run ended" event
        for k in range(5):
            recorder.log_tick(k, 0.1 * k, np.array([[0.05 * k, 0.0, 0.0]]))
    texts = svg_texts(rrd, tmp_path / "cut.svg")
    assert any("PARTIAL" in t for t in texts)
    assert "not recorded (partial)" in texts


def test_a_graph_world_plot_lists_each_robots_vertices_in_visit_order(tmp_path, capsys):
    result = tmp_path / "graph.json"
    assert main(["explore", "--world", "graph", "--arena", "fig9", "--robots", "2", "--json",
                 str(result)]) in (0, 1)
    paths = json.loads(result.read_text())["paths"]
    text = " ".join(svg_texts(result, tmp_path / "graph.svg"))
    assert "visit order" in text
    for i, path in enumerate(paths):
        assert f"R{i + 1}: {' '.join(path[:4])}" in text
