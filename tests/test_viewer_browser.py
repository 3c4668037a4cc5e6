"""A recording as a reader sees it: served with rerun's own web viewer on 127.0.0.1 and
opened in a headless Chromium (selenium, the system's chromedriver; nothing downloaded).

Two page loads, an embodied and a graph-world recording (some 20-40 s each): the default
layout, once the data has loaded, must show every robot's colour in the arena view and no
empty view; and, from the recording's data,
every map view's vertices must stand farther apart than a label is wide in rerun's graph
units (else the labels stack on one spot). The screenshot, and each view cut out of it,
are kept under ``tmp_path``.
``MJSWARM_BROWSER_RRD=FILE.rrd`` checks that recording instead of a fresh one.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
import rerun as rr

from mjswarm.cli import main
from mjswarm.outputs.recording import robot_color
from mjswarm.outputs.webview import (LAYOUT_REGIONS, Browser, browser_missing, crop,
                                    save_png, serve)

#: Width of a vertex label in rerun's graph view (its units), with room to spare.
LABEL_UNITS = 60.0

pytestmark = pytest.mark.skipif(browser_missing() is not None,
                                reason=f"no browser test: {browser_missing()}")


def map_positions(path: Path) -> dict[str, list[np.ndarray]]:
    """Graph view entity (each robot's map, the radio graph) -> the node positions (graph
    units) of each graph logged."""
    maps: dict[str, list[np.ndarray]] = {}
    for chunk in rr.chunk.RrdReader(path).stream():
        if not chunk.entity_path.startswith(("/map/", "/radio/graph")):
            continue
        batch = chunk.to_record_batch()
        if "GraphNodes:positions" in batch.schema.names:
            for row in batch.column("GraphNodes:positions").to_pylist():
                if row:
                    maps.setdefault(chunk.entity_path, []).append(np.array(row, float))
    return maps


@pytest.fixture(scope="module")
def recording(tmp_path_factory) -> Path:
    given = os.environ.get("MJSWARM_BROWSER_RRD")
    if given:
        return Path(given)
    path = tmp_path_factory.mktemp("browser") / "fig9.rrd"
    main(["explore", "--arena", "fig9", "--robots", "2", "--max-time", "80",
          "--record", str(path)])
    assert path.is_file()
    return path


#: Runs of every world that records graphs, for the check of their graph views' units.
GRAPH_RUNS = {
    "graph world": ["explore", "--world", "graph", "--arena", "fig9", "--robots", "2"],
    "radio graph world": ["explore", "--world", "graph", "--arena", "fig9", "--robots", "3",
                          "--radio-range", "2", "--connectivity", "connected"],
}


def assert_labels_apart(maps: dict[str, list[np.ndarray]]) -> None:
    assert maps, "no graph view in the recording"
    for entity, logged in maps.items():
        for xy in logged:
            if len(xy) > 1:
                d = np.hypot(*(xy[:, None] - xy[None]).transpose(2, 0, 1))
                closest = d[np.triu_indices(len(xy), 1)].min()
                assert closest > LABEL_UNITS, (entity, closest)


def test_map_vertices_stand_farther_apart_than_a_label(recording):
    assert_labels_apart(map_positions(recording))


@pytest.mark.parametrize("run", GRAPH_RUNS, ids=str)
def test_every_worlds_graph_views_keep_labels_apart(run, tmp_path):
    path = tmp_path / "run.rrd"
    assert main([*GRAPH_RUNS[run], "--record", str(path)]) in (0, 1)
    maps = map_positions(path)
    assert "/radio/graph" not in maps  # laid out by the viewer: robots share vertices
    assert_labels_apart(maps)


def test_default_layout_in_a_browser(recording, tmp_path):
    """The embodied recording and a graph-world one, in one browser."""
    graph = tmp_path / "graph.rrd"
    assert main([*GRAPH_RUNS["graph world"], "--record", str(graph)]) == 0
    with Browser() as browser:
        for kind, path in (("embodied", recording), ("graph", graph)):
            with serve([path]) as address:
                browser.look(address)
                pixels = browser.save(tmp_path / f"{kind}_default_layout.png")
            for name in LAYOUT_REGIONS:
                view = crop(pixels, name)
                save_png(view, tmp_path / f"{kind}_{name}.png")
                assert view.std() > 3.0, f"the {name} view of the {kind} run is empty"
            arena = crop(pixels, "arena").astype(int)
            for i in range(2):
                near = (np.abs(arena - np.array(robot_color(i)[:3])) < 30).all(axis=2)
                assert near.sum() >= 30, f"R{i + 1}'s colour is not in the {kind} arena view"
