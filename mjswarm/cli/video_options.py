"""``--video`` and ``--video-speed``: the options of every command that runs a MuJoCo or
point world (:mod:`mjswarm.outputs.video`)."""

from __future__ import annotations

import math

from mjswarm.cli.output import check_writable
from mjswarm.errors import MjswarmError
from mjswarm.outputs.video_format import DEFAULT_SPEEDUP, FPS, HEIGHT_PX, WIDTH_PX


def add_video_options(parser) -> None:
    parser.add_argument("--video", default=None, metavar="FILE.mp4",
                        help=f"write an MP4 video of the run ({WIDTH_PX}x{HEIGHT_PX}, {FPS} "
                             "fps, rendered offscreen: no display needed): the robots in "
                             "their recording colours with their trails and the simulated "
                             "time; with --record the recording holds it too")
    parser.add_argument("--video-speed", type=float, default=None, metavar="X",
                        help=f"simulated seconds per second of video (default "
                             f"{DEFAULT_SPEEDUP:g}: a 420 s run lasts 14 s)")


def check_video(args) -> float:
    """Refuse impossible video options in one line; the speed-up to use."""
    if args.video_speed is not None and not args.video:
        raise MjswarmError("--video-speed needs --video")
    speed = DEFAULT_SPEEDUP if args.video_speed is None else args.video_speed
    if not (math.isfinite(speed) and speed > 0):
        raise MjswarmError(f"--video-speed must be a positive number, got {speed:g}")
    if args.video:
        if not args.video.lower().endswith(".mp4"):
            raise MjswarmError(f"--video writes MP4 files: give a FILE.mp4, got {args.video}")
        check_writable(args.video, "video")
    return speed
