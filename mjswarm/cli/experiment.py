"""``mjswarm experiment <name>``: rerun a paper's experiment on the open floor.

Each experiment is a module ``mjswarm.cli.experiment_<name>`` exposing
``register(subparsers)``, like the top-level subcommands.
"""

from __future__ import annotations

from mjswarm.cli import register_modules

#: Experiment modules (``mjswarm.cli.experiment_<name>``).
EXPERIMENTS: tuple[str, ...] = ("biconnected_coverage", "patrol")


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "experiment",
        help="rerun the papers' connectivity-maintenance experiments",
        description="Rerun a paper's experiment (embodied MuJoCo robots or kinematic points).",
    )
    experiments = parser.add_subparsers(dest="experiment", metavar="NAME", required=True)
    register_modules(experiments, "experiment_", EXPERIMENTS)
