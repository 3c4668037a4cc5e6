"""``mjswarm view FILE.rrd [--web [--port N]]``: open a recording in the rerun viewer, or
serve it to a browser with rerun's web viewer (for machines without a display)."""

from __future__ import annotations


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "view",
        help="open a .rrd recording in the rerun viewer, or serve it to a browser (--web)",
        description="Open a recording written with --record in the rerun viewer, laid out "
        "for review (the arena from above, each robot's map and incidence matrix, beacons, "
        "controller states, events, sensors) on the sim_time timeline. The viewer needs a "
        "display; without one it says so in one line and exits with status 2. With --web "
        "it serves rerun's web viewer on 127.0.0.1 instead, prints the address to open, "
        "and serves until Ctrl-C.",
    )
    parser.add_argument("file", metavar="FILE.rrd", help="the recording to open")
    parser.add_argument("--web", action="store_true",
                        help="serve the recording with rerun's web viewer on 127.0.0.1 and "
                             "print the address to open (no display needed)")
    parser.add_argument("--port", type=int, default=None, metavar="N",
                        help="with --web: the web viewer's port (default: a free one)")
    parser.set_defaults(func=run)


def run(args) -> int:
    """``mjswarm view``: :func:`mjswarm.outputs.webview.serve_web` with ``--web``, else
    :func:`mjswarm.outputs.recording.open_viewer`."""
    from mjswarm.errors import MjswarmError

    if args.port is not None and not args.web:
        raise MjswarmError("--port applies to --web only")
    if args.port is not None and not 0 < args.port < 65536:
        raise MjswarmError(f"--port must be a port number (1..65535), got {args.port}")
    if args.web:
        from mjswarm.outputs.webview import serve_web

        return serve_web(args.file, args.port)
    from mjswarm.outputs.recording import open_viewer

    return open_viewer(args.file)
