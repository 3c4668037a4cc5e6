"""A connectivity mind as a robot controller.

The minds of :mod:`.stamps` and :mod:`.tables` are message-passing state machines,
``tick(now, inbox, neighbors) -> list[Message]``; a :class:`Participant` runs one as a
:class:`~algorithms.robot.Controller`. Its clock is the tick number
``round(time_s / tick_s)``: the papers' synchronous rounds, one per control tick (c).
A participant does not move.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable
from typing import Protocol

from algorithms.robot import Command, Controller, Message, Observation


class MessagePassing(Protocol):
    def tick(self, now: int, inbox: Iterable[Message],
             neighbors: Iterable[Hashable]) -> list[Message]: ...


class Participant(Controller):
    """Runs ``mind`` once per control tick of ``tick_s`` seconds, standing still."""

    def __init__(self, mind: MessagePassing, tick_s: float = 1.0) -> None:
        self.mind = mind
        self.tick_s = tick_s

    def step(self, observation: Observation) -> Command:
        now = round(observation.time_s / self.tick_s)
        out = self.mind.tick(now, observation.inbox, observation.neighbors)
        return Command(messages=tuple(out))
