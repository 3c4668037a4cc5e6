"""The static team: robot positions (and optionally explicit links and walls) from a file.

File format (JSON)::

    {"positions": {"r1": [0.0, 0.0], "r2": [1.2, 0.5], ...},   # metres
     "edges": [["r1", "r2"], ...],                             # optional explicit links
     "walls": [[[x1, y1], [x2, y2]], ...],                     # optional, metres
     "name": "...", "description": "..."}                      # optional, ignored

With ``edges`` the radio graph is exactly those links and no range may be given (a range
would silently mean something else); without them a range d_c is required and two robots
are linked when they are at most d_c apart and no wall crosses the segment between them.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import networkx as nx

from mjswarm.errors import MjswarmError
from mjswarm.core.radio import Radio, walls_blocker

Point = tuple[float, float]
_KEYS = {"positions", "edges", "walls", "name", "description"}


@dataclass(frozen=True)
class Team:
    """Robots at fixed positions (metres), optional explicit links and wall segments."""

    positions: dict[str, Point]
    edges: tuple[tuple[str, str], ...] | None = None
    walls: tuple[tuple[Point, Point], ...] = ()
    source: str = "<dict>"

    @property
    def ids(self) -> tuple[str, ...]:
        """Robot ids in file order."""
        return tuple(self.positions)

    def radio(self, range_m: float | None = None, **radio_options: Any) -> Radio:
        """A :class:`Radio` over this team, its links set from the positions or edges.

        ``range_m`` (metres) is required without explicit edges and refused with them;
        ``radio_options`` go to :class:`Radio` (``drop_prob``, ``rng``).
        """
        if self.edges is not None:
            if range_m is not None:
                raise MjswarmError(
                    f"{self.source}: the file gives explicit edges; drop the range"
                )
            return Radio(self.ids, edges=self.edges, **radio_options)
        if range_m is None:
            raise MjswarmError(f"{self.source}: no edges in the file, so a range is needed")
        if not (math.isfinite(range_m) and range_m > 0):
            raise MjswarmError(f"range must be a positive number of metres, got {range_m}")
        blocked = walls_blocker(self.walls, self.positions) if self.walls else None
        radio = Radio(self.ids, range_m=range_m, blocked=blocked, **radio_options)
        radio.move(self.positions)
        return radio

    def graph(self, range_m: float | None = None) -> nx.Graph:
        """The radio graph (ground truth for tests and comparisons)."""
        return self.radio(range_m).graph()


def _error(source: str, problem: str) -> MjswarmError:
    return MjswarmError(f"{source}: {problem}")


def _point(value: Any, source: str, what: str) -> Point:
    if (
        not isinstance(value, list)
        or len(value) != 2
        or not all(isinstance(c, (int, float)) and not isinstance(c, bool) for c in value)
        or not all(math.isfinite(c) for c in value)
    ):
        raise _error(source, f"{what} must be [x, y] with two finite numbers, got {value!r}")
    return float(value[0]), float(value[1])


def parse_team(data: Any, source: str = "<dict>") -> Team:
    """Validate a decoded team file; every problem is one :class:`MjswarmError` line."""
    if not isinstance(data, dict):
        raise _error(source, "expected a JSON object with a 'positions' key")
    unknown = sorted(set(data) - _KEYS)
    if unknown:
        raise _error(source, f"unknown key {unknown[0]!r} (expected {', '.join(sorted(_KEYS))})")
    positions = data.get("positions")
    if not isinstance(positions, dict) or not positions:
        raise _error(source, "'positions' must be a non-empty object {id: [x, y]}")
    points = {str(k): _point(v, source, f"position of {k!r}") for k, v in positions.items()}
    edges = None
    if "edges" in data:
        if not isinstance(data["edges"], list):
            raise _error(source, "'edges' must be a list of [id, id] pairs")
        seen: set[frozenset] = set()
        edges = []
        for e in data["edges"]:
            if not isinstance(e, list) or len(e) != 2 or not all(isinstance(x, str) for x in e):
                raise _error(source, f"edge {e!r} must be a pair of robot ids")
            unknown_ids = [x for x in e if x not in points]
            if unknown_ids:
                raise _error(source, f"edge {e!r} names unknown robot {unknown_ids[0]!r}")
            if e[0] == e[1]:
                raise _error(source, f"edge {e!r} joins a robot to itself")
            if frozenset(e) in seen:
                raise _error(source, f"duplicate edge {e!r}")
            seen.add(frozenset(e))
            edges.append((e[0], e[1]))
        edges = tuple(edges)
    walls_data = data.get("walls", [])
    if not isinstance(walls_data, list):
        raise _error(source, "'walls' must be a list of [[x1, y1], [x2, y2]] segments")
    walls = []
    for w in walls_data:
        if not isinstance(w, list) or len(w) != 2:
            raise _error(source, f"wall {w!r} must be [[x1, y1], [x2, y2]]")
        walls.append((_point(w[0], source, "wall end"), _point(w[1], source, "wall end")))
    return Team(positions=points, edges=edges, walls=tuple(walls), source=source)


def _no_duplicate_keys(source: str):
    def hook(pairs: list[tuple[str, Any]]) -> dict:
        keys = [k for k, _ in pairs]
        for k in keys:
            if keys.count(k) > 1:
                raise _error(source, f"duplicate key {k!r} in the JSON (robot ids must be unique)")
        return dict(pairs)

    return hook


def load_team(path: str | Path) -> Team:
    """Read and validate a team file (see the module docstring for the format)."""
    source = str(path)
    try:
        text = Path(path).read_text()
    except OSError as exc:
        raise _error(source, f"cannot read ({exc.strerror})") from None
    try:
        data = json.loads(text, object_pairs_hook=_no_duplicate_keys(source))
    except json.JSONDecodeError as exc:
        raise _error(source, f"not valid JSON ({exc.msg} at line {exc.lineno})") from None
    return parse_team(data, source)
