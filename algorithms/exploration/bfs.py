"""Multi-robot breadth-first exploration, the BFS baseline of Nagavarapu et al. (refs. [5, 6]).

Nagavarapu et al. describes BFS only as "gradually increases the distance from root vertex"; the
rules below are inferred. Each robot keeps and merges the incidence matrix like the
proposed method (same beacons, same travel over its known completed graph, same
re-selection and Theorem 1 completion: :class:`~algorithms.exploration.incidence_dfs.FrontierExplorer`).
Only the choice differs: the unexplored edge whose known end is fewest hops from the root
over the robot's completed graph; ties by hops from the robot, then beacon id and angle.
With no unexplored edge known, an out edge chosen the same way (the robot follows an
unfinished branch, as the proposed method does with ``Eo``).
"""

from __future__ import annotations

from algorithms.exploration.incidence_dfs import FrontierExplorer
from algorithms.exploration.incidence_matrix import End


class BFS(FrontierExplorer):
    """Breadth first: the frontier edge nearest to the root."""

    name = "bfs"

    def select(self) -> End:
        candidates = self.matrix.unexplored() or list(self.matrix.out)
        depth = self.matrix.distances(self.root)
        shallowest = min(depth[e[0]] for e in candidates)
        shallow = {e[0] for e in candidates if depth[e[0]] == shallowest}
        nearest = self.matrix.nearest(self.here, shallow)
        return self.pick([e for e in candidates if e[0] in nearest])
