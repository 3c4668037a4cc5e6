"""Connectivity awareness on a static team: input files, the message-passing harness and
the message-count comparison (Ahmadi & Stone and Le et al.). The per-robot algorithms live in
:mod:`algorithms.connectivity`; the radio in :mod:`mjswarm.core.radio`.
"""

from mjswarm.experiments.connectivity.harness import (
    DEFAULT_MESSAGE_CAP,
    METHODS,
    CheckResult,
    drive,
    run_check,
)
from mjswarm.experiments.connectivity.team import Team, load_team, parse_team

__all__ = [
    "DEFAULT_MESSAGE_CAP",
    "METHODS",
    "CheckResult",
    "Team",
    "drive",
    "load_team",
    "parse_team",
    "run_check",
]
