"""Regenerate the screenshots of recordings in rerun's web viewer (docs/screenshots/*.png).

Makes the recordings (the main job, ``mjswarm explore --arena arena2 --robots 4``;
Nagavarapu et al.'s Fig. 9 in the graph world, plain and connected with a 2 m radio
that walls block; a patrol and a biconnected coverage run in the point world), serves
each with rerun's web viewer on 127.0.0.1, opens it in a headless
Chromium (:mod:`mjswarm.outputs.webview`: needs ``apt-get install chromium
chromium-driver`` and selenium) and saves the default layout as ``NAME.png``, and for the
Fig. 9 graph run and the main job each view of it as ``NAME_VIEW.png``. Run from the
repository root::

    python docs/screenshots/make_screenshots.py [--only NAME ...]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from mjswarm.cli import main
from mjswarm.outputs.webview import LAYOUT_REGIONS, Browser, crop, save_png, screenshot

HERE = Path(__file__).resolve().parent
#: name -> the mjswarm command line that records it (``--record`` added).
RUNS = {
    "main_job": ["explore", "--arena", "arena2", "--robots", "4"],
    "fig9_graph": ["explore", "--world", "graph", "--arena", "fig9", "--robots", "2"],
    "fig9_connected": ["explore", "--world", "graph", "--arena", "fig9", "--robots", "3",
                       "--radio-range", "2", "--connectivity", "connected"],
    "patrol": ["experiment", "patrol", "--world", "point", "--robots", "8",
               "--steps", "400"],
    "coverage": ["experiment", "biconnected-coverage", "--cr", "2", "--world", "point",
                 "--episodes", "12"],
}
#: Recordings whose views are also saved one by one, cut out of the default layout.
VIEWS = ("fig9_graph", "main_job")


def run() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="*", choices=list(RUNS), default=None)
    args = parser.parse_args()
    wanted = args.only or list(RUNS)
    with tempfile.TemporaryDirectory() as tmp, Browser() as browser:
        for name in wanted:
            path = Path(tmp) / f"{name}.rrd"
            print(f"recording {name}: mjswarm {' '.join(RUNS[name])}", flush=True)
            main([*RUNS[name], "--record", str(path)])
            pixels = screenshot(path, HERE / f"{name}.png", browser=browser, strict=False)
            print(f"wrote {HERE / f'{name}.png'}", flush=True)
            if name in VIEWS:
                for view in LAYOUT_REGIONS:
                    out = HERE / f"{name}_{view.replace(' ', '_')}.png"
                    save_png(crop(pixels, view), out)
                    print(f"wrote {out}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(run())
