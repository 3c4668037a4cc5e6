"""Regenerate the screenshots of recordings in rerun's web viewer (docs/screenshots/*.png).

Makes the recordings (the main job, ``mjswarm explore --arena arena2 --robots 4``; seed
003's Fig. 9 in the graph world, plain and connected with a 1.5 m radio; a patrol in the
point world), serves each with rerun's web viewer on 127.0.0.1, opens it in a headless
Chromium (:mod:`mjswarm.outputs.webview`: needs ``apt-get install chromium
chromium-driver`` and selenium) and saves the default layout, plus single views of the
Fig. 9 run (R2's map and incidence matrix, the beacons). Run from the repository root::

    python docs/screenshots/make_screenshots.py [--only NAME ...]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import rerun.blueprint as rrb

from mjswarm.cli import main
from mjswarm.outputs.webview import Browser, screenshot

HERE = Path(__file__).resolve().parent
#: name -> the mjswarm command line that records it (``--record`` added).
RUNS = {
    "main_job": ["explore", "--arena", "arena2", "--robots", "4"],
    "fig9_graph": ["explore", "--world", "graph", "--arena", "fig9", "--robots", "2"],
    "fig9_connected": ["explore", "--world", "graph", "--arena", "fig9", "--robots", "3",
                       "--radio-range", "1.5", "--connectivity", "connected"],
    "patrol": ["experiment", "patrol", "--world", "point", "--robots", "8",
               "--steps", "400"],
}
#: name -> (recording, the view shown alone)
VIEWS = {
    "fig9_graph_R2": ("fig9_graph", rrb.Vertical(
        rrb.GraphView(name="map R2", origin="/map/R2"),
        rrb.TextDocumentView(name="incidence matrix R2", origin="/matrices/R2"))),
    "fig9_graph_beacons": ("fig9_graph", rrb.TextDocumentView(name="beacons",
                                                              origin="/beacons")),
    "fig9_connected_radio": ("fig9_connected", rrb.GraphView(name="radio",
                                                              origin="/radio/graph")),
}


def run() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="*", choices=[*RUNS, *VIEWS], default=None)
    args = parser.parse_args()
    wanted = set(args.only or [*RUNS, *VIEWS])
    needed = {n for n in RUNS if n in wanted} | {VIEWS[v][0] for v in VIEWS if v in wanted}
    with tempfile.TemporaryDirectory() as tmp, Browser() as browser:
        files = {}
        for name in RUNS:
            if name in needed:
                files[name] = Path(tmp) / f"{name}.rrd"
                print(f"recording {name}: mjswarm {' '.join(RUNS[name])}", flush=True)
                main([*RUNS[name], "--record", str(files[name])])
        for name in RUNS:
            if name in wanted:
                screenshot(files[name], HERE / f"{name}.png", browser=browser, strict=False)
                print(f"wrote {HERE / f'{name}.png'}", flush=True)
        for name, (source, view) in VIEWS.items():
            if name in wanted:
                screenshot(files[source], HERE / f"{name}.png", view=view, browser=browser,
                           strict=False)
                print(f"wrote {HERE / f'{name}.png'}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(run())
