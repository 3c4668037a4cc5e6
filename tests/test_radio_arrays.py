"""The radio's delivery by arrays equals delivery copy by copy (a reference radio):
the same messages in every inbox in the same order, the same counters and the same drops
for the same seed, on random teams, links, sends, removals, blackouts and drops. And
payloads are immutable values."""

from __future__ import annotations

import dataclasses
import enum
from typing import NamedTuple

import numpy as np
import pytest

from algorithms.robot import Message
from mjswarm.core.radio import Radio, Uplink, check_immutable
from mjswarm.errors import MjswarmError


class CopyRadio(Radio):
    """The reference: recipients as names fixed at sending, delivered copy by copy."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self._ref_outbox: list = []
        self._ref_inbox = {r: [] for r in self.robots}
        self.ref_received = dict.fromkeys(self.robots, 0)

    def send(self, sender, payload, to=None) -> None:
        if sender not in self._present:
            raise MjswarmError("not in the team")
        self.sent[sender] += 1
        recipients = self._ordered[sender] if to is None else (
            (to,) if to in self._neighbors[sender] else ())
        self._ref_outbox.append((Message(payload, to, sender), recipients))

    @property
    def pending(self) -> int:
        return len(self._ref_outbox)

    def receive(self, robot):
        inbox, self._ref_inbox[robot] = self._ref_inbox[robot], []
        return inbox

    def remove(self, robot) -> None:
        super().remove(robot)
        self._ref_outbox = [m for m in self._ref_outbox if m[0].sender != robot]
        self._ref_inbox[robot].clear()

    def _deliver(self) -> None:
        outbox, self._ref_outbox = self._ref_outbox, []
        self.last_batch = len(outbox)
        lossless = not self.blackout and not self.drop_prob
        for message, recipients in outbox:
            for r in recipients:
                if r not in self._present:
                    continue
                if not lossless and (self.blackout or self._rng.random() < self.drop_prob):
                    self.dropped += 1
                    continue
                self._ref_inbox[r].append(message)
                self.ref_received[r] += 1


def _drive(radio: Radio, seed: int, ticks: int, names: list) -> list:
    """A random run; returns everything observable, tick by tick."""
    rng = np.random.default_rng(seed)
    log = []
    xy = rng.uniform(0, 3, (len(names), 2))
    for tick in range(ticks):
        xy += rng.normal(0, 0.2, xy.shape)
        radio.blackout = rng.random() < 0.1
        radio.step(dict(zip(names, xy)) if radio.range_m is not None else None)
        if rng.random() < 0.1 and len(radio.present) > 2:
            radio.remove(names[rng.integers(len(names))])
        if rng.random() < 0.1:
            radio.restore(names[rng.integers(len(names))])
        for r in names:
            if r in radio.present and rng.random() < 0.8:  # some do not read this tick
                log.append((tick, r, [tuple(m) for m in radio.receive(r)]))
        for r in list(radio.present):
            for _ in range(rng.integers(0, 3)):
                to = names[rng.integers(len(names))] if rng.random() < 0.3 else None
                radio.send(r, ("hello", r, tick, int(rng.integers(100))), to)
        if rng.random() < 0.2 and radio.range_m is not None:  # links move within the tick
            xy[rng.integers(len(names))] += 1.0
            radio.move(dict(zip(names, xy)) if len(radio.present) == len(names) else xy)
        log.append((tick, radio.last_batch, radio.dropped, radio.pending, dict(radio.sent)))
    return log


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("drop", [0.0, 0.3])
def test_array_delivery_equals_copy_by_copy(seed, drop):
    names = list(range(12)) if seed % 2 else [f"r{i}" for i in range(9)] + ["base"]
    array = Radio(names, range_m=1.2, drop_prob=drop, rng=seed)
    copy = CopyRadio(names, range_m=1.2, drop_prob=drop, rng=seed)
    assert _drive(array, seed, 60, names) == _drive(copy, seed, 60, names)
    assert array.received == copy.ref_received
    assert array.dropped == copy.dropped and array.sent == copy.sent
    assert sum(array.received.values()) > 100


def test_array_delivery_equals_copy_by_copy_with_explicit_edges():
    names = list(range(6))
    edges = [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5), (5, 0), (0, 3)]
    array, copy = (kind(names, edges=edges, drop_prob=0.2, rng=3) for kind in (Radio, CopyRadio))
    for radio in (array, copy):
        for tick in range(30):
            radio.step()
            for r in names:
                radio.send(r, (r, tick))
            if tick == 10:
                radio.set_edges(edges[:4])  # links change between sending and delivery
    assert [array.receive(r) for r in names] == [copy.receive(r) for r in names]
    assert array.received == copy.ref_received and array.dropped == copy.dropped


class Point(NamedTuple):
    x: float
    y: float


@dataclasses.dataclass(frozen=True)
class Frozen:
    where: tuple
    label: str


@dataclasses.dataclass
class Loose:
    where: tuple


class Colour(enum.Enum):
    RED = 1


@pytest.mark.parametrize("payload", [
    None, 3, 2.5, "heartbeat", b"x", True, np.float64(1.5), np.int64(2), Colour.RED,
    (1, (2, "a"), frozenset({3, (4, 5)})), Point(1.0, 2.0), Frozen((Point(0, 1),), "a"),
    Message(("a", 1), None, 3),
])
def test_immutable_payloads_pass(payload):
    check_immutable(payload)
    radio = Radio([0, 1], edges=[(0, 1)])
    radio.send(0, payload)
    radio.step()
    assert radio.receive(1)[0].payload is payload


@pytest.mark.parametrize("payload, name", [
    ([1, 2], "list"), ({"a": 1}, "dict"), ({1}, "set"), (bytearray(b"x"), "bytearray"),
    (np.zeros(2), "ndarray"), (Loose((1,)), "Loose"), ((1, (2, [3])), "list"),
    (Point(1.0, [2.0]), "list"), (Frozen(({},), "a"), "dict"), (frozenset({(1, object())}), "object"),
    (object(), "object"),
])
def test_mutable_payloads_are_refused(payload, name):
    radio = Radio([0, 1], edges=[(0, 1)])
    with pytest.raises(MjswarmError, match=f"immutable value.*not {name}"):
        radio.send(0, payload)
    assert radio.sent[0] == 0 and radio.pending == 0
    with pytest.raises(MjswarmError, match="station message must be an immutable value"):
        Uplink("station").send(0, payload)
    with pytest.raises(MjswarmError, match="station message must be an immutable value"):
        Uplink("station").reply(0, payload)
