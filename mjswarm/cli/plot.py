"""``mjswarm plot RESULT -o OUT.png``: a summary picture of a run."""

from __future__ import annotations

from pathlib import Path

from mjswarm.cli.output import atomic_output, check_writable


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "plot",
        help="draw a summary picture of a run from its recording or its JSON result",
        description=(
            "Draw a run: from a recording (FILE.rrd, written with --record) the arena, "
            "every robot's trajectory in its colour, the radio links at the end, where "
            "completion was declared, contact events and a table of headline figures; "
            "from a --json result of `mjswarm explore` the robots' vertex paths on the "
            "arena graph with Nagavarapu et al.'s exploration metrics, of a coverage experiment its S-coverage "
            "per episode against the paper's mean, of a patrol its headline figures. "
            "The format follows OUT's extension: .png, .svg or .pdf."
        ),
    )
    parser.add_argument("result", metavar="RESULT", help="a .rrd recording or a .json result")
    parser.add_argument("-o", "--output", required=True, metavar="OUT.png",
                        help="the picture to write (.png, .svg or .pdf)")
    parser.set_defaults(func=run)


def run(args) -> int:
    from mjswarm.errors import MjswarmError
    from mjswarm.outputs.plot import picture_format, plot

    fmt = picture_format(args.output)
    if not Path(args.result).is_file():
        raise MjswarmError(f"no such file: {args.result}")
    check_writable(args.output, "plot")
    with atomic_output(args.output, "plot") as temp:
        plot(args.result, temp, fmt)
    print(f"plot: {args.output}")
    return 0
