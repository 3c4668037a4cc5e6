"""Connectivity awareness on moving embodied robots (issue 6, part 4): the radio's line of
sight and the ground truth the robots' beliefs are checked against.

With ``--radio-range R`` an embodied run gives every robot a radio (:class:`mjswarm.core.radio.
Radio`: range ``R``, one control tick of latency, links blocked by walls through
:attr:`mjswarm.core.simulation.Simulation.sight`, vectorised over pairs) and a connectivity
table of internally disjoint access paths to the reference robot R1 (seed 004,
:class:`algorithms.connectivity.tables.ConnectivityTable`, kept by each
:class:`~algorithms.exploration.explorer.Explorer`). Each robot's *belief* is its table's
answer to "does any single robot's loss cut me off the reference?": ``biconnected`` when
it has two internally disjoint access paths (``is_doubly_connected``), ``not`` otherwise;
the *truth* is :func:`truth`.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable, Mapping

import networkx as nx
import numpy as np

from algorithms.robot import NOTHING
from mjswarm.core.radio import Blocker
from mjswarm.core.simulation import Simulation

BICONNECTED, NOT = "biconnected", "not"


def truth(graph: nx.Graph, reference: Hashable, robots: Iterable[Hashable]) -> dict:
    """Ground truth of each robot's belief question, from the radio graph: ``biconnected``
    when it shares a biconnected component of three robots or more with ``reference``,
    else ``not`` (also for robots off the air)."""
    blocks = [c for c in nx.biconnected_components(graph) if reference in c and len(c) >= 3]
    return {i: BICONNECTED if any(i in c for c in blocks) else NOT for i in robots}


def sight_blocker(sim: Simulation, fixed: Mapping[Hashable, tuple[float, float]] = NOTHING,
                  mast_m: float = 0.0) -> Blocker:
    """The radio's line-of-sight test on a simulation: a link between robots i and j is
    blocked unless each sees the other (:attr:`Simulation.sight` both ways); a link
    between a robot and a fixed node (a base station at ``fixed[address]``, m, its antenna
    ``mast_m`` above the floor, or a robot docked at it) unless the robot is seen from the
    antenna; two fixed nodes always link."""

    def between_robots(pairs: np.ndarray) -> np.ndarray:
        i, j = np.asarray(pairs, np.int64).reshape(-1, 2).T
        seen = sim.sight(i, j)  # the way back only where the way there is clear
        seen[seen] = sim.sight(j[seen], i[seen])
        return ~seen

    if not fixed:
        return between_robots

    def blocked(pairs: np.ndarray) -> np.ndarray:
        pairs = np.asarray(pairs).reshape(-1, 2)
        cut = np.zeros(len(pairs), bool)
        robots = np.array([not (a in fixed or b in fixed) for a, b in pairs], bool)
        if robots.any():
            cut[robots] = between_robots(pairs[robots])
        for k in np.flatnonzero(~robots):
            a, b = pairs[k]
            node, robot = (a, b) if a in fixed else (b, a)
            if robot not in fixed:  # two masts see each other
                cut[k] = not sim.sight.from_point(fixed[node], [robot], mast_m)[0]
        return cut

    return blocked
