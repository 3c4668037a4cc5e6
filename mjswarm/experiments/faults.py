"""Fault injection for embodied exploration (``mjswarm explore --fault``).

Forms (times in simulated seconds; robots numbered from 1, as in every output):

``robot:I@T``
    Robot I fails at T: it stops where it is and stays there as an obstacle, its radio
    goes silent, and it releases every vertex it holds (:mod:`mjswarm.experiments.stations`). The
    edge it had selected stays *out* in the beacons it marked; Nagavarapu et al.'s priority (4)
    keeps out edges as the last candidates (``Eo``), so another robot takes it once the
    unexplored edges run out: a dead robot's claim never needs to expire for the
    exploration to finish. A body left in a vertex area closes that vertex
    (:mod:`mjswarm.experiments.stations`): the team completes the part it can still
    reach and the result names the edges it could not (``unreachable_edges``). A body on
    a lane is passed on the opposite lane (:mod:`algorithms.exploration.entry`, step 6).
    A body that closes the root leaves the robots of the depot unlaunched and those out
    cut off (as a body can cut the last live robots off an open root); each of these
    finishes the part it can still reach, and the run ends ``completed reachable
    part`` once all have (the rule in
    :func:`~mjswarm.experiments.metrics.team_cut_off`).
``beacon:V@T``
    The beacon at vertex V is wiped at T (its contents and id are gone). The next robot
    there drops a new beacon under a new id; robots that knew the old one keep both
    names, so the maps may then hold a phantom vertex: the result's ``map_correct`` tells.
``radio-blackout@T1-T2``
    Every radio message sent from T1 up to T2 is lost (needs ``--radio-range``).

Sensor noise and wheel slip are options of their own (``--line-noise``, ``--ir-noise``,
``--wheel-slip``), passed to :class:`mjswarm.core.simulation.Simulation`.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from mjswarm.arena import ArenaSpec
from mjswarm.errors import MjswarmError
from mjswarm.worlds.loop import Loop, LoopFunctions

FORMS = ("robot:I@T", "beacon:V@T", "radio-blackout@T1-T2")
_NUMBER = r"(\d+(?:\.\d*)?|\.\d+)"


@dataclass(frozen=True)
class RobotFailure:
    """Robot ``robot`` (0-based) fails at ``at_s``: the world switches it off."""

    robot: int
    at_s: float

    def check(self, n_robots: int, spec: ArenaSpec, radio: bool) -> None:
        if not 0 <= self.robot < n_robots:
            raise MjswarmError(f"fault {self}: there are robots 1..{n_robots}")

    def apply(self, world) -> list:
        world.power_off(self.robot)
        return []

    @property
    def reason(self) -> str:
        """Why the robot stopped, as the run's metrics say it."""
        return f"failed (fault {self})"

    def __str__(self) -> str:
        return f"robot:{self.robot + 1}@{self.at_s:g}"


@dataclass(frozen=True)
class BeaconWipe:
    """The beacon at ``vertex`` is wiped at ``at_s``."""

    vertex: str
    at_s: float

    def check(self, n_robots: int, spec: ArenaSpec, radio: bool) -> None:
        if self.vertex not in spec.vertices:
            raise MjswarmError(f"fault {self}: {self.vertex!r} is not a vertex of {spec.name}")

    def apply(self, world) -> list:
        world.wipe_beacon(self.vertex)
        return []

    def __str__(self) -> str:
        return f"beacon:{self.vertex}@{self.at_s:g}"


@dataclass(frozen=True)
class RadioBlackout:
    """No radio message gets through from ``at_s`` until ``end_s``."""

    at_s: float
    end_s: float

    def check(self, n_robots: int, spec: ArenaSpec, radio: bool) -> None:
        if self.end_s <= self.at_s:
            raise MjswarmError(f"fault {self}: the blackout must end after it starts")
        if not radio:
            raise MjswarmError(f"fault {self} needs robots with radios (--radio-range)")

    def apply(self, world) -> list:
        world.radio.blackout = True
        return [_BlackoutEnd(self.end_s)]

    def __str__(self) -> str:
        return f"radio-blackout@{self.at_s:g}-{self.end_s:g}"


@dataclass(frozen=True)
class _BlackoutEnd:
    """The end of a :class:`RadioBlackout` (scheduled by it)."""

    at_s: float

    def apply(self, world) -> list:
        world.radio.blackout = False
        return []

    def __str__(self) -> str:
        return f"radio back at {self.at_s:g}"


Fault = RobotFailure | BeaconWipe | RadioBlackout

_PATTERNS = (
    (re.compile(rf"robot:(\d+)@{_NUMBER}"),
     lambda m: RobotFailure(int(m[1]) - 1, float(m[2]))),
    (re.compile(rf"beacon:([A-Za-z0-9_]+)@{_NUMBER}"),
     lambda m: BeaconWipe(m[1], float(m[2]))),
    (re.compile(rf"radio-blackout@{_NUMBER}-{_NUMBER}"),
     lambda m: RadioBlackout(float(m[1]), float(m[2]))),
)


def check_fault(fault: Fault, n_robots: int, spec: ArenaSpec, radio: bool,
                end_s: float) -> None:
    """Refuse, in one line, a fault that does not fit a run of ``n_robots`` on ``spec``
    (``radio``: robots carry radios) ending at ``end_s``: one that can never fire or
    whose target is not there. A fault whose time the run does not reach because the
    run ended earlier is reported as not fired in the result instead."""
    if fault.at_s >= end_s:
        raise MjswarmError(f"fault {fault} can never fire: the run ends at {end_s:g} s "
                           "(--max-time)")
    fault.check(n_robots, spec, radio)


def is_user_fault(fault) -> bool:
    """Whether ``fault`` was asked for (not one a fault scheduled, as a blackout's end)."""
    return not isinstance(fault, _BlackoutEnd)


def parse_fault(text: str) -> Fault:
    """One ``--fault`` value; :class:`MjswarmError` naming the forms if it is none of them."""
    for pattern, build in _PATTERNS:
        match = pattern.fullmatch(text.strip())
        if match:
            fault = build(match)
            if isinstance(fault, RobotFailure) and fault.robot < 0:
                raise MjswarmError(f"fault '{text}': robots are numbered from 1")
            return fault
    raise MjswarmError(f"bad fault '{text}': expected one of {', '.join(FORMS)} "
                       "(times in simulated seconds)")


class Faults(LoopFunctions):
    """Injects ``faults`` into ``world`` at the control tick nearest to each one's time;
    a fault acts through the world only (a robot switched off, a beacon wiped, the radio
    blacked out), never inside a controller. :meth:`log` says which fired, and when.
    ``switched_off``: the other loop functions' handlers of a robot switched off,
    ``handler(robot, reason)``, called in order as the fault fires."""

    def __init__(self, world, faults,
                 switched_off: Sequence[Callable[[int, str], None]] = ()) -> None:
        self.world = world
        self.pending = sorted(faults, key=lambda f: f.at_s)
        self.fired: list[dict] = []
        self.switched_off = tuple(switched_off)

    def before_step(self, loop: Loop) -> None:
        world = self.world
        now = world.time_s + world.control_dt_s / 2.0
        while self.pending and self.pending[0].at_s <= now:
            fault = self.pending.pop(0)
            self.pending = sorted([*self.pending, *fault.apply(world)], key=lambda f: f.at_s)
            if isinstance(fault, RobotFailure):
                for handler in self.switched_off:
                    handler(fault.robot, fault.reason)
            self.fired.append({"fault": str(fault), "fired": True,
                               "at_s": round(world.time_s, 2)})
            loop.event(f"fault: {fault}")

    def log(self) -> list[dict]:
        """Every fault asked for: fired (when), or not fired."""
        return [*self.fired, *({"fault": str(f), "fired": False, "at_s": None}
                               for f in self.pending if is_user_fault(f))]
