"""The ``mjswarm`` command line: a thin layer over the Python API.

Each subcommand lives in its own module ``mjswarm.cli.<name>`` exposing
``register(subparsers)``, which adds its parser and sets ``func`` (called with the
parsed arguments, returns an exit status). Building the parser imports no heavy library
(MuJoCo, rerun, numba, scipy, matplotlib): each module imports those inside its ``func``,
so that ``--help`` is quick. User errors (:class:`MjswarmError`) become one line on
stderr and exit status 2. SIGTERM ends a run as Ctrl-C does: partial outputs kept and
named, the summary printed, exit status 130.
"""

from __future__ import annotations

import argparse
import importlib
import signal
import sys
import threading

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


def _outputs_note() -> str:
    """What became of an interrupted run's outputs, for its last line."""
    kept = ", ".join(where if where == asked else f"{where} ({asked} left as it was)"
                     for asked, where in interrupted_outputs.items() if where is not None)
    empty = ", ".join(asked for asked, where in interrupted_outputs.items() if where is None)
    return ((f"; partial output kept: {kept}" if kept else "")
            + (f"; nothing recorded yet, so not kept: {empty}" if empty else ""))


def _interrupt(signum, frame) -> None:
    """SIGTERM's handler: stop the run as Ctrl-C does."""
    raise KeyboardInterrupt


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    interrupted_outputs.clear()
    handle = threading.current_thread() is threading.main_thread()  # signal's rule
    previous = signal.signal(signal.SIGTERM, _interrupt) if handle else None
    try:
        args = parser.parse_args(argv)
        return int(args.func(args) or 0)
    except MjswarmError as exc:
        print(f"mjswarm: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"mjswarm: interrupted{_outputs_note()}", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. `mjswarm ... | head`: the reader left, nothing to say
        sys.stderr.close()
        return 0
    finally:
        if handle:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":
    sys.exit(main())
