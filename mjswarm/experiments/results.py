"""What an exploration run measures, in every world: Nagavarapu et al.'s metrics.

``makespan`` is the time of the declaration (Nagavarapu et al.'s "number of edge traversals" to
complete; embodied runs count the edges of the busiest robot instead);
``total_traversals`` and ``traversals_per_robot`` count the edge traversals finished by
then; ``map_edges`` is the declaring robot's map translated from beacon ids to arena
vertex ids (the experiment knows where each beacon was dropped); ``map_correct`` says
whether it equals the true edge set.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass


@dataclass
class ExplorationResult:
    """One run's measurements (robots numbered from 1 as R1, R2, ... in Nagavarapu et al.)."""

    arena: str
    strategy: str
    robots: int
    root: str
    edge_time: str
    seed: int | None
    completed: bool
    makespan: float | None
    total_traversals: int
    traversals_per_robot: list[int]
    declared_by: int | None
    declared_at: str | None
    map_edges: list[tuple[str, str]]
    map_correct: bool
    paths: list[list[str]]

    def to_dict(self) -> dict:
        """JSON-ready dict (tuples become lists)."""
        d = asdict(self)
        d["map_edges"] = [list(e) for e in self.map_edges]
        return d


def outcome(strategy: str, declared: tuple[float, int, str] | None,
            declared_map: Iterable[tuple[str, str]], makespan: float | None,
            paths: list[list[str]], beacon_vertex: Mapping[str, str],
            true_edges: set[tuple[str, str]], **run) -> dict:
    """The :class:`ExplorationResult` fields every world computes the same way, given the
    strategy's name, the declaration ``(time, robot index, vertex)`` or None, the
    declaring robot's map (pairs of beacon ids; empty when nobody declared, but for a team
    cut off from its root), the makespan, each robot's path, where
    each beacon was dropped, the true edges (sorted pairs) and the run's own fields
    (``arena``, ``root``, ``edge_time``, ``seed``). The map is translated from beacon ids
    to arena vertices."""
    per_robot = [len(p) - 1 for p in paths]
    pairs = ((beacon_vertex[a], beacon_vertex[b]) for a, b in declared_map)
    map_edges = sorted((u, v) if u <= v else (v, u) for u, v in pairs)
    return dict(
        run,
        strategy=strategy,
        robots=len(paths),
        completed=declared is not None,
        makespan=makespan,
        total_traversals=sum(per_robot),
        traversals_per_robot=per_robot,
        declared_by=None if declared is None else declared[1] + 1,
        declared_at=None if declared is None else declared[2],
        map_edges=map_edges,
        map_correct=declared is not None and set(map_edges) == true_edges,
        paths=paths,
    )
