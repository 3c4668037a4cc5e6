"""``mjswarm view FILE.rrd``: open a recording in the rerun viewer (needs a display)."""

from __future__ import annotations


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "view",
        help="open a .rrd recording in the rerun viewer (needs a display)",
        description="Open a recording written with --record in the rerun viewer, laid out "
        "for review (3-D arena, explored graphs, time series, event log) on the sim_time "
        "timeline (s). Without a display it says so in one line and exits with status 2.",
    )
    parser.add_argument("file", metavar="FILE.rrd", help="the recording to open")
    parser.set_defaults(func=run)


def run(args) -> int:
    """``mjswarm view``: :func:`mjswarm.outputs.recording.open_viewer` on FILE."""
    from mjswarm.outputs.recording import open_viewer

    return open_viewer(args.file)
