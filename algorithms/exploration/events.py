"""What exploring robots report to the experimenter (``Command.events``): immutable values,
read by loop functions only, never by another robot."""

from __future__ import annotations

from typing import NamedTuple


class Declared(NamedTuple):
    """The robot declared the exploration complete (Theorem 1) at the vertex it stands
    on; ``map_edges`` is its map, as pairs of beacon ids."""

    map_edges: tuple[tuple[str, str], ...]
