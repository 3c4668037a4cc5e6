"""Connectivity awareness on moving embodied robots (issue 6, part 4): the ground truth the
robots' beliefs are checked against (the radio's line of sight is
:func:`mjswarm.core.radio.sight_blocker`).

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

from collections.abc import Hashable, Iterable

import networkx as nx

BICONNECTED, NOT = "biconnected", "not"


def truth(graph: nx.Graph, reference: Hashable, robots: Iterable[Hashable]) -> dict:
    """Ground truth of each robot's belief question, from the radio graph: ``biconnected``
    when it shares a biconnected component of three robots or more with ``reference``,
    else ``not`` (also for robots off the air)."""
    blocks = [c for c in nx.biconnected_components(graph) if reference in c and len(c) >= 3]
    return {i: BICONNECTED if any(i in c for c in blocks) else NOT for i in robots}
