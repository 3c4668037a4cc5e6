"""The message interface shared by the connectivity algorithms.

A robot's mind is driven once per control tick (one tick is the papers' bound c on a
one-hop relay, seed 002 Assumption 4; "a step" in seed 004) by
``tick(now, inbox, neighbors) -> list[Outgoing]``:

* ``now``: the tick number (int);
* ``inbox``: what the radio delivered this tick, items with ``.sender`` and ``.payload``;
* ``neighbors``: the ids the robot hears this tick. Both papers take neighbour discovery
  from the network layer (seed 004 relies on a MANET protocol); it costs no messages here.

It answers with the messages to transmit; the world or harness hands them to the radio,
which delivers them one tick later.
"""

from __future__ import annotations

from collections.abc import Hashable
from typing import Any, NamedTuple, Protocol


class Received(Protocol):
    """One delivered message, as the radio hands it over."""

    @property
    def sender(self) -> Hashable: ...

    @property
    def payload(self) -> Any: ...


class Outgoing(NamedTuple):
    """A message to transmit: a one-hop broadcast, or kept only by robot ``to``."""

    payload: Any
    to: Hashable | None = None
