"""Graph exploration minds: Nagavarapu et al.'s incidence-matrix multi-robot DFS and the baselines
it is compared with (MR-DFS, BFS, LRV, flooding), all behind one interface
(:class:`~algorithms.exploration.base.Strategy`).
"""

from algorithms.exploration.base import DONE, IDLE, Beacon, Decision, Strategy, go
from algorithms.exploration.bfs import BFS
from algorithms.exploration.flooding import Flooding
from algorithms.exploration.incidence_dfs import IncidenceDFS
from algorithms.exploration.lrv import LRV
from algorithms.exploration.mr_dfs import MRDFS

#: Strategy classes by CLI name.
STRATEGIES: dict[str, type[Strategy]] = {
    cls.name: cls for cls in (IncidenceDFS, MRDFS, BFS, LRV, Flooding)
}

__all__ = [
    "BFS", "DONE", "IDLE", "LRV", "MRDFS", "STRATEGIES", "Beacon", "Decision", "Flooding",
    "IncidenceDFS", "Strategy", "go",
]
