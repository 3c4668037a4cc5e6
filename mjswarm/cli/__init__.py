"""The ``mjswarm`` command line: a thin layer over the Python API.

Each subcommand lives in its own module ``mjswarm.cli.<name>`` exposing
``register(subparsers)``, which adds its parser and sets ``func`` (called with the
parsed arguments, returns an exit status). User errors (:class:`MjswarmError`)
become one line on stderr and exit status 2.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from mjswarm import __version__
from mjswarm.cli.output import interrupted_outputs
from mjswarm.errors import MjswarmError

#: Subcommand modules, in the order ``--help`` lists them.
SUBCOMMANDS = ("bench", "arena", "explore", "compare", "view", "plot", "connectivity",
               "experiment", "sweep")


def register_modules(subparsers, prefix: str, names: tuple[str, ...]) -> None:
    """Let each module ``mjswarm.cli.<prefix><name>`` add its parser to ``subparsers``."""
    for name in names:
        importlib.import_module(f"mjswarm.cli.{prefix}{name}").register(subparsers)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="mjswarm",
        description="Embodied multi-robot exploration and connectivity on MuJoCo.",
    )
    parser.add_argument("--version", action="version", version=f"mjswarm {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    register_modules(subparsers, "", SUBCOMMANDS)
    return parser


def check_seeds(seeds, flag: str) -> None:
    """Seeds seed numpy's generators, which take any whole number >= 0; refuse the rest
    in one line."""
    bad = [s for s in seeds if s is not None and s < 0]
    if bad:
        raise MjswarmError(f"{flag} must be a whole number >= 0, got {bad[0]}")


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        check_seeds([getattr(args, "seed", None)], "--seed")
        return int(args.func(args) or 0)
    except MjswarmError as exc:
        print(f"mjswarm: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        kept = ", ".join(where if where == asked else f"{where} ({asked} left as it was)"
                         for asked, where in interrupted_outputs.items())
        print("mjswarm: interrupted" + (f"; partial output kept: {kept}" if kept else ""),
              file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. `mjswarm ... | head`: the reader left, nothing to say
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    sys.exit(main())
