"""The batched robot type: a team of robots of one kind, sensed and commanded as arrays.

A :class:`BatchController` steps every robot of a team in one call (VMAS's agents axis,
ARGoS's sense-all / control-all phases without a Python step per robot): the world hands
it one :class:`Readings`, a structure of arrays with a row per robot stepped this tick,
and applies the one :class:`BatchCommand` it answers with. Reflexes (line following,
odometry, Nagavarapu et al.'s collision rule over pair arrays) are array operations; per-robot
decisions stay event-driven inside the team.

Readings hold what the rows of :class:`~algorithms.robot.Observation` hold (the same
units), nothing more: a team never sees ground truth. Every array's first axis is the
robot row (bearings and inboxes: pairs and copies that name their row), so a later tier
can add a leading axis of worlds. :meth:`Readings.observation` is one robot's
:class:`~algorithms.robot.Observation` view and :meth:`Readings.from_observations` the
other way, the adapters between the two robot types (a world without a batched surface
builds a team's readings from per-robot observations).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Hashable, Sequence
from typing import Any, NamedTuple

import numpy as np

from algorithms.robot import Message, Observation


class Readings(NamedTuple):
    """What every robot of a team senses in one control tick, row ``r`` for robot
    ``robots[r]`` (units as in :class:`~algorithms.robot.Observation`; NaN where a robot
    has no such sensor or nothing is in range).

    Attributes:
        robots: the robots' ids, shape (K,), int.
        time_s: the tick's time (s).
        line_m: line rangefinders (left, centre, right), m, shape (K, 3).
        ir_m: IR rangefinders (left, front, right), m, shape (K, 3).
        encoder_rad: wheel encoders (left, right), rad, shape (K, 2).
        wheel_speed_rad_s: wheel speeds (left, right), rad/s, shape (K, 2).
        battery_v: battery voltage, V, shape (K,).
        bearing_row: the bearing sensor's pairs, shape (P,): the observing row, sorted by
            row, then id.
        bearing_id: the id the sensor reports for each pair, shape (P,).
        bearing_rad: the bearing of each pair (rad, robot frame), shape (P,).
        inbox: the messages received this tick, each once; ``inbox_copy`` (C,) indexes
            them, row by row in delivery order, row ``r``'s copies being
            ``inbox_copy[inbox_bounds[r]:inbox_bounds[r + 1]]`` (``inbox_bounds``: (K + 1,)).
    """

    robots: np.ndarray
    time_s: float
    line_m: np.ndarray
    ir_m: np.ndarray
    encoder_rad: np.ndarray
    wheel_speed_rad_s: np.ndarray
    battery_v: np.ndarray
    bearing_row: np.ndarray
    bearing_id: np.ndarray
    bearing_rad: np.ndarray
    inbox: Sequence[Message]
    inbox_copy: np.ndarray
    inbox_bounds: np.ndarray

    def inbox_counts(self) -> np.ndarray:
        """Messages received per row this tick, shape (K,)."""
        return np.diff(self.inbox_bounds)

    def observation(self, row: int) -> Observation:
        """Robot ``robots[row]``'s :class:`~algorithms.robot.Observation` (for a per-robot
        controller, or to compare the two robot types on the same readings)."""
        lo, hi = np.searchsorted(self.bearing_row, [row, row + 1]).tolist()
        b = self.inbox_bounds
        return Observation(
            self.robots[row].item(), self.time_s, self.line_m[row].tolist(),
            self.ir_m[row].tolist(), self.encoder_rad[row].tolist(),
            self.wheel_speed_rad_s[row].tolist(), self.battery_v[row].item(),
            bearings=dict(zip(self.bearing_id[lo:hi].tolist(), self.bearing_rad[lo:hi].tolist())),
            inbox=[self.inbox[c] for c in self.inbox_copy[b[row]:b[row + 1]].tolist()])

    @classmethod
    def from_observations(cls, observations: Sequence[Observation]) -> Readings:
        """A team's readings from its robots' observations (rows in their order)."""
        def column(field: str, width: int) -> np.ndarray:
            rows = [getattr(o, field) for o in observations]
            return np.array([[np.nan] * width if r is None else r for r in rows],
                            float).reshape(len(rows), width)

        pairs = [(r, p, b) for r, o in enumerate(observations) for p, b in sorted(o.bearings.items())]
        row, seen, beta = (np.array(x) for x in zip(*pairs)) if pairs else ((), (), ())
        inbox = [m for o in observations for m in o.inbox]
        return cls(
            np.array([o.robot for o in observations]),
            observations[0].time_s if observations else 0.0,
            column("line_m", 3), column("ir_m", 3), column("encoder_rad", 2),
            column("wheel_speed_rad_s", 2), column("battery_v", 1).ravel(),
            np.asarray(row, np.intp), np.asarray(seen, np.intp), np.asarray(beta, float),
            inbox, np.arange(len(inbox)),
            np.cumsum([0] + [len(o.inbox) for o in observations]))


class BatchCommand(NamedTuple):
    """What every robot of a team does in one control tick, row by row as its
    :class:`Readings`.

    Attributes:
        v_m_s: unicycle commands' forward speeds (m/s), shape (K,).
        omega_rad_s: unicycle commands' turn rates (rad/s), shape (K,).
        broadcast: the rows that broadcast ``payload`` this tick (one-hop, one
            transmission each), bool shape (K,), or None for none.
        payload: what they broadcast (an immutable value).
    """

    v_m_s: np.ndarray
    omega_rad_s: np.ndarray
    broadcast: np.ndarray | None = None
    payload: Any = None

    def command(self, row: int) -> tuple[float, float, tuple[Message, ...]]:
        """Row ``row``'s ``(v m/s, omega rad/s, messages)``, as a per-robot
        :class:`~algorithms.robot.Command` carries them."""
        talks = self.broadcast is not None and bool(self.broadcast[row])
        return (self.v_m_s[row].item(), self.omega_rad_s[row].item(),
                (Message(self.payload),) if talks else ())


class BatchController(ABC):
    """The mind of a team of robots of one kind: :meth:`reset` when robots enter a world,
    then :meth:`step_all` once per control tick with every stepped robot's readings."""

    def reset(self, robots: Sequence[Hashable]) -> None:  # noqa: B027 - a hook, as Controller.reset
        """Called with the robots (re)placed in a world, before their first step."""

    @abstractmethod
    def step_all(self, readings: Readings) -> BatchCommand:
        """Answer one tick's readings with the team's commands."""
