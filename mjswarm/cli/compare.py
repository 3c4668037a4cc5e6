"""``mjswarm compare <what>``: rerun a paper's comparison, write a table and PNG plots.

Each comparison is a module ``mjswarm.cli.compare_<what>`` exposing
``register(subparsers)``, like the top-level subcommands.
"""

from __future__ import annotations

from mjswarm.cli import register_modules

#: Comparison modules (``mjswarm.cli.compare_<name>``).
COMPARISONS: tuple[str, ...] = ("exploration", "connectivity")


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "compare",
        help="rerun the papers' comparisons (tables + PNG plots)",
        description="Rerun a paper's comparison and write a table plus PNG plots.",
    )
    comparisons = parser.add_subparsers(dest="comparison", metavar="WHAT", required=True)
    register_modules(comparisons, "compare_", COMPARISONS)
