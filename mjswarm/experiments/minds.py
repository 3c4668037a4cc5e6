"""The robots' exploration minds for a run: one :class:`~algorithms.exploration.Strategy`
per robot, from a strategy's name or a factory, with seeded tie-breaking."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from algorithms.exploration import STRATEGIES, Strategy
from mjswarm.errors import MjswarmError

#: Builds robot ``index``'s mind for a team of ``n_robots``, with its tie-breaking rng.
StrategyFactory = Callable[[int, int, np.random.Generator | None], Strategy]

#: Largest team any run takes: the largest the benchmarks measure. The graph world's
#: minds take about 0.4 MB a robot (arena1 with 10,000 robots: 3.9 GB, 67 s; measured
#: with ``/usr/bin/time mjswarm explore --world graph --arena arena1 --robots 10000``).
MAX_ROBOTS = 1000


def make_minds(
    strategy: str | StrategyFactory, n_robots: int, seed: int | None = None
) -> list[Strategy]:
    """One mind per robot; ``strategy`` is a name from ``STRATEGIES`` or a factory.
    With a ``seed``, robot i gets the generator ``default_rng([seed, i])``."""
    if isinstance(n_robots, bool) or not isinstance(n_robots, int) or n_robots < 1:
        raise MjswarmError(f"need at least one robot, got {n_robots}")
    if n_robots > MAX_ROBOTS:
        raise MjswarmError(f"at most {MAX_ROBOTS} robots, got {n_robots} (the largest team "
                           "the benchmarks measure; the graph world's minds alone take "
                           "about 0.4 MB a robot)")
    if isinstance(strategy, str):
        if strategy not in STRATEGIES:
            raise MjswarmError(
                f"unknown strategy '{strategy}' (choose from {', '.join(STRATEGIES)})"
            )
        strategy = STRATEGIES[strategy]
    return [
        strategy(i, n_robots, None if seed is None else np.random.default_rng([seed, i]))
        for i in range(n_robots)
    ]


def strategy_name(minds: list[Strategy]) -> str:
    """The name a result gives the team's strategy."""
    return getattr(minds[0], "name", type(minds[0]).__name__)
