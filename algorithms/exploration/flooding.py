"""Flooding, the tree exploration of Cabrera-Mora and Xiao (IEEE T-SMC-B 2012; "A flooding
algorithm for multirobot exploration"), compared in Nagavarapu et al. section 6 (E + r steps with
two robots on a tree).

The paper's abstract: robots are "fed into the tree one at a time", and the number of
robots allowed to traverse an edge and to enter a vertex per step is restricted; active
landmarks at the vertices coordinate them. Rules inferred from that, on top of the MR-DFS
bookkeeping and choices (:mod:`~algorithms.exploration.mr_dfs`):

* Feeding: robot Rk (0-based index k) waits k steps at the root before moving, so robots
  enter the tree one per step; that staggering is the only form of the per-step capacity
  restriction modelled here.
* Robots help in unfinished subtrees as in MR-DFS. A variant in which robots never enter
  an edge another robot took exceeds Nagavarapu et al.'s E + r bound for two robots on trees (by up
  to 15 steps on random 5 x 5 grid trees), so it is not what the paper compared with.
* Cycles (the paper is for trees) are handled as in MR-DFS.
"""

from __future__ import annotations

from collections.abc import Sequence

from algorithms.exploration.base import IDLE, Beacon, Decision
from algorithms.exploration.mr_dfs import MRDFS


class Flooding(MRDFS):
    """MR-DFS with robots fed into the graph one per step."""

    name = "flooding"

    def __init__(self, index, n_robots, rng=None):
        super().__init__(index, n_robots, rng)
        self._feed_wait = index

    def on_vertex(
        self, beacon: Beacon, angles: Sequence[float], arrived_by: float | None
    ) -> Decision:
        if self._feed_wait:
            self._feed_wait -= 1
            self.first_step(beacon, angles, arrived_by)
            return IDLE
        return super().on_vertex(beacon, angles, arrived_by)
