"""A connectivity mind as a robot controller.

The minds of :mod:`.stamps` and :mod:`.tables` are message-passing state machines,
``tick(now, inbox, neighbors) -> list[Message]``; a :class:`Participant` runs one as a
:class:`~algorithms.robot.Controller`. Its clock is the tick number
``round(time_s / tick_s)``: the papers' synchronous rounds, one per control tick (c).
A participant does not move. When its mind reaches a verdict (its ``connected`` is no
longer None) the participant reports it once, as a :class:`Verdict` event.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable
from typing import NamedTuple, Protocol

from algorithms.robot import Command, Controller, Message, Observation


class MessagePassing(Protocol):
    def tick(self, now: int, inbox: Iterable[Message],
             neighbors: Iterable[Hashable]) -> list[Message]: ...


class Verdict(NamedTuple):
    """A mind's decision, reported once: whether the team is connected and biconnected,
    and its articulation points (sorted robot ids; None where the method finds none)."""

    connected: bool
    biconnected: bool
    articulation_points: tuple | None


class Participant(Controller):
    """Runs ``mind`` once per control tick of ``tick_s`` seconds, standing still, and
    reports the mind's :class:`Verdict` in the tick it decides."""

    def __init__(self, mind: MessagePassing, tick_s: float = 1.0) -> None:
        self.mind = mind
        self.tick_s = tick_s
        self._told = False

    def step(self, observation: Observation) -> Command:
        mind = self.mind
        out = mind.tick(round(observation.time_s / self.tick_s), observation.inbox,
                        observation.neighbors)
        if self._told or getattr(mind, "connected", None) is None:
            return Command(messages=tuple(out))
        self._told = True
        points = getattr(mind, "articulation_points", None)
        verdict = Verdict(mind.connected, mind.biconnected,
                          None if points is None else tuple(sorted(points)))
        return Command(messages=tuple(out), events=(verdict,))
