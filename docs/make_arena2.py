"""Regenerates ``docs/arena2.png``, README's still: the frame at 280 s of the main job's
video (arena2, 4 robots, as README runs it). Run from the repository root:

    python docs/make_arena2.py

(with this clone installed, ``pip install -e .``, or with ``PYTHONPATH=.``).

The run stops at 280 s (a deterministic run: the same frame as the full run's video).
"""

import sys
import tempfile
from pathlib import Path

import imageio.v2 as imageio

from mjswarm.cli import main

#: Simulated time of the still (s).
STILL_S = 280


def make_still(out: Path) -> None:
    with tempfile.TemporaryDirectory() as folder:
        video = Path(folder) / "arena2.mp4"
        main(["explore", "--arena", "arena2", "--robots", "4", "--max-time", str(STILL_S),
              "--video", str(video)])
        with imageio.get_reader(video) as reader:
            *_, last = reader
    imageio.imwrite(out, last)


if __name__ == "__main__":
    make_still(Path(sys.argv[0]).resolve().parent / "arena2.png")
