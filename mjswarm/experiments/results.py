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


def traversed_edges(paths) -> set[tuple[str, str]]:
    """The edges (sorted vertex pairs) that paths of vertices (one per robot) traversed."""
    return {tuple(sorted(e)) for p in paths for e in zip(p, p[1:])}


class Paths:
    """Each robot's path of vertices from the root, and the team's declaration of
    completion: what every world accounts the same way, while each world keeps its own
    timing (when a path gains a vertex, which declaration of a tick it hears).

    ``paths[i]`` is robot ``i``'s path; ``declared`` is ``(time, robot index, vertex)``
    or None, ``declared_map`` the declaring robot's map (pairs of beacon ids). ``keep``
    says which of two declarations of one tick counts: ``"first"`` (the graph worlds) or
    ``"last"`` (the embodied world: the robot that steps last in the tick).
    """

    def __init__(self, n: int, root: str, keep: str = "first") -> None:
        if keep not in ("first", "last"):
            raise ValueError(f"keep must be 'first' or 'last', not {keep!r}")
        self.paths = [[root] for _ in range(n)]
        self.declared: tuple[float, int, str] | None = None
        self.declared_map: tuple[tuple[str, str], ...] = ()
        self._last = keep == "last"

    def arrive(self, i: int, vertex: str) -> None:
        """Robot ``i``'s path gains ``vertex``."""
        self.paths[i].append(vertex)

    def declare(self, now: float, i: int, vertex: str,
                map_edges: tuple[tuple[str, str], ...]) -> None:
        """Robot ``i`` declared completion at ``vertex`` at time ``now`` with its map
        ``map_edges``; a later declaration counts only under ``keep="last"``."""
        if self.declared is None or self._last:
            self.declared, self.declared_map = (now, i, vertex), map_edges

    def counted(self, under_way=()) -> list[list[str]]:
        """A copy of the paths without the last vertex of each robot of ``under_way``
        (its traversal still under way at the declaration does not count)."""
        paths = [list(p) for p in self.paths]
        for i in under_way:
            paths[i].pop()
        return paths

    def outcome(self, strategy: str, makespan: float | None, beacon_vertex: Mapping[str, str],
                true_edges: set[tuple[str, str]], paths: list[list[str]] | None = None,
                **run) -> dict:
        """:func:`outcome` of these paths (or of ``paths``) and this declaration."""
        return outcome(strategy, self.declared, self.declared_map, makespan,
                       self.paths if paths is None else paths, beacon_vertex, true_edges,
                       **run)


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
