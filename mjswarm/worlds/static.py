"""Robots that stand still and only talk: the world of the static connectivity harness
(:mod:`mjswarm.experiments.connectivity.harness`)."""

from __future__ import annotations

from collections.abc import Hashable

import numpy as np

from algorithms.robot import Command, Observation
from mjswarm.core.radio import Radio
from mjswarm.worlds.loop import World


class StaticWorld(World):
    """Robots that stand still and only talk: the harness's world. Robot ids are the
    radio's (any hashables); one control tick is one time unit, the papers' c."""

    def __init__(self, radio: Radio, start: int = 0) -> None:
        self.radio = radio
        self.ids = radio.robots
        self.n = len(self.ids)
        self.present = np.ones(self.n, bool)
        self.control_dt_s = 1.0
        self.uplinks = {}
        self._now = start

    @property
    def time_s(self) -> float:
        return float(self._now)

    def true_poses(self) -> np.ndarray:
        return np.zeros((self.n, 3))

    def active(self) -> list[Hashable]:
        return list(self.radio.present)

    def on_floor(self, i: Hashable) -> bool:
        return i in self.radio.present

    def robots_on_floor(self) -> int:
        return len(self.radio.present)

    def commanded_speeds(self) -> np.ndarray:
        return np.zeros(self.n)

    def observe(self, i: Hashable) -> Observation:
        inbox, neighbors = self._inbox(i)
        return Observation(i, self.time_s, inbox=inbox, neighbors=neighbors)

    def act(self, i: Hashable, command: Command) -> None:
        self._send(i, command.messages)

    def step(self) -> None:
        self.radio.step()
        self._now += 1
