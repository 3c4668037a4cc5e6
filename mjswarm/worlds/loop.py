"""One loop runs any world with any controllers, and loop functions own the experiment.

The split is ARGoS's (controllers vs loop functions) with dm_control composer's
lifecycle hooks. A :class:`World` is the robots' surroundings at some fidelity (MuJoCo
dynamics on an arena or an open floor, kinematic points): it turns the world state into
each robot's :class:`~algorithms.robot.Observation`, applies each
:class:`~algorithms.robot.Command` and advances one control tick, radio included. A
:class:`LoopFunctions` object is the experimenter: it launches and removes robots,
keeps the vertex stations, injects faults, measures and records. Only loop functions see
ground truth (:meth:`World.true_poses`, contacts); controllers see observations.

One control tick (:meth:`Loop.step`) runs in phases, as ARGoS's space does (sense and
control every robot, then act for all, then the physics), and loop functions hook in
between phases, never between two robots::

    for f in functions: f.before_step(loop)
    robots = world.active()                      # robots on the floor, in id order
    for i in robots entering the floor: controllers[i].reset()
    robots = world.nodes + robots                # fixed radio nodes (a base) first
    observations = [world.observe(i) for i in robots]              # sense all
    for i, o in ...: controllers[i].perceive(o)                    # (bookkeeping)
    commands = [controllers[i].step(o) for i, o in ...]            # control all
    for i, c in zip(robots, commands): world.act(i, c)             # act all
    loop.reports = [(i, event) for i, c in ... for event in c.events]
    world.step()                               # physics, then the radio delivers
    for f in functions: f.after_step(loop)     # loop.stepped: the robots of this tick
    stop = any(f.should_stop(loop) for f in functions)

A batched team (``Loop(..., team=...)``, :class:`~algorithms.batch.BatchController`) runs
in the same phases: ``world.observe_all(robots)`` beside the nodes' observations, one
``team.step_all(readings)`` after their steps, one ``world.act_all(robots, commands)``
after their acts.

Every observation of a tick is of one world state: acting changes nothing a later robot
of the same tick observes (motion and messages take effect in ``world.step()``). A
beacon is the exception by design: it is the vertex's store, and robots that stand on
one vertex in one tick read and write it one after another, in the order they step.

Messages sent in a tick are delivered at the end of that tick's ``world.step()`` and read
in the next tick's observations: the radio's one tick of latency (Ahmadi & Stone Assumption 4).
"""

from __future__ import annotations

import gc
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any, NamedTuple

import numpy as np

from algorithms.batch import BatchCommand, BatchController, Readings
from algorithms.robot import NOTHING, Command, Controller, Message, Observation
from mjswarm.errors import MjswarmError
from mjswarm.core.radio import Radio

#: The sender of the orders an experimenter hands a robot (:meth:`Loop.last_words`).
STATION = "station"


class World(ABC):
    """The surface a :class:`Loop` drives: ``observe``, ``act``, ``step``, and ground truth
    for loop functions, metrics and recordings only.

    Robots are ids ``0 .. n - 1``; ``present[i]`` says whether robot ``i`` is on the
    floor (absent robots wait in a depot, off the air and unseen). A world may carry a
    :class:`~mjswarm.core.radio.Radio` (``radio``); it relinks the radio from the true
    positions of present robots after every step.
    """

    n: int
    present: np.ndarray
    radio: Radio | None = None
    #: infrastructure links by address (:class:`~mjswarm.core.radio.Uplink`); set per world
    uplinks: dict
    #: control period (s)
    control_dt_s: float
    #: radio nodes that never move, by address: position (m) (a base station); the radio
    #: knows them after the robots, in this order
    fixed: Mapping = NOTHING
    #: robots off the floor whose radio is on the air at a fixed point, by id: position
    #: (m) (a robot docked at a base station, rule 1 of :mod:`algorithms.exploration.tether`)
    docked: Mapping = NOTHING
    #: how many times a robot left the floor (the loop resets a robot that comes back,
    #: even when it comes back before the next tick)
    departures: int = 0
    #: radio nodes off the floor that the loop steps every tick before the robots (a base
    #: station, a docked robot): their controllers observe and act as robots do, and are
    #: never reset by the loop (they never enter the floor)
    nodes: Sequence = ()

    @property
    @abstractmethod
    def time_s(self) -> float:
        """Simulated time (s)."""

    @abstractmethod
    def true_poses(self) -> np.ndarray:
        """Ground truth, shape (N, 3): x, y (m), yaw (rad). Not for controllers."""

    @abstractmethod
    def observe(self, i: int) -> Observation:
        """Robot ``i``'s observation of this tick."""

    @abstractmethod
    def act(self, i: int, command: Command) -> None:
        """Apply robot ``i``'s command: its motion set-point, messages and signal."""

    @abstractmethod
    def step(self) -> None:
        """Advance one control tick (physics, then the radio)."""

    def observe_all(self, robots: Sequence[int]) -> Readings:
        """The readings of this tick of every robot of ``robots``, one row each, for a
        batched team (:class:`~algorithms.batch.BatchController`); by default from their
        observations, robot by robot (a world with arrays of its own overrides this)."""
        return Readings.from_observations([self.observe(i) for i in robots])

    def act_all(self, robots: Sequence[int], commands: BatchCommand) -> None:
        """Apply a batched team's commands, row by row as ``robots``; by default robot by
        robot through :meth:`act`."""
        for row, i in enumerate(robots):
            v, omega, messages = commands.command(row)
            self.act(i, Command(v, omega, None, messages))

    @abstractmethod
    def commanded_speeds(self) -> np.ndarray:
        """Each robot's commanded forward speed (m/s) in the last tick, shape (N,)."""

    def active(self) -> list[int]:
        """The robots the loop steps this tick: those on the floor."""
        return np.flatnonzero(self.present).tolist()

    def on_floor(self, i) -> bool:
        """Whether robot ``i`` is on the floor (a robot that leaves it and comes back
        starts a new episode: the loop resets its controller)."""
        return bool(self.present[i])

    def robots_on_floor(self) -> int:
        """How many robots are on the floor."""
        return int(np.count_nonzero(self.present))

    @property
    def contacts(self) -> int | None:
        """Robot-robot contact events so far (None: a world without bodies)."""
        events = self.contact_events()
        return None if events is None else len(events)

    def contact_events(self) -> list[tuple[float, int, int]] | None:
        """Every robot-robot contact event so far: (time s, robot i, robot j), i < j
        (None: a world without bodies)."""
        return None

    # -- the radio, shared by every world ----------------------------------------------
    def attach_radio(self, radio: Radio) -> None:
        """Give every robot this radio (ids ``0 .. n - 1``, then the :attr:`fixed` nodes);
        absent robots are off the air."""
        if tuple(radio.robots) != tuple(range(self.n)) + tuple(self.fixed):
            raise MjswarmError("the radio must know exactly the robots 0 .. n - 1, then the "
                               "world's fixed nodes")
        self.radio = radio
        for i in range(self.n):
            if not self.present[i] and i not in self.docked:
                radio.remove(i)
        self.relink()

    def set_on_air(self, i: int, on: bool) -> None:
        """Robot ``i`` joins (``on``) or leaves the radio (what it had not read is lost)."""
        if self.radio is not None:
            if on:
                self.radio.restore(i)
            else:
                self.radio.remove(i)

    def relink(self) -> None:
        """Move the radio's links to where the robots are now."""
        if self.radio is not None and self.radio.range_m is not None:
            self.radio.move(self._air_positions())

    def _air_positions(self) -> np.ndarray:
        """Where the radio's nodes are (m): the robots 0 .. n - 1 (docked ones where they
        are docked), then the fixed nodes."""
        xy = self.true_poses()[:, :2]
        if self.docked:
            xy = xy.copy()
            xy[list(self.docked)] = list(self.docked.values())
        return np.vstack([xy, list(self.fixed.values())]) if self.fixed else xy

    def _radio_step(self) -> None:
        """End of a tick: deliver this tick's messages, relink from the new positions."""
        if self.radio is not None:
            self.radio.step(self._air_positions() if self.radio.range_m is not None else None)
        for link in self.uplinks.values():
            link.step()

    def _inbox(self, i: int) -> tuple[Sequence[Message], frozenset]:
        """Robot ``i``'s messages (radio, then infrastructure) and radio neighbours."""
        inbox, neighbors = ([], frozenset()) if self.radio is None else (
            self.radio.receive(i), self.radio.neighbors(i))
        if self.uplinks:
            for link in self.uplinks.values():
                inbox += link.receive_for(i)
        return inbox, neighbors

    def _send(self, i: int, messages: Sequence[Message]) -> None:
        if self.radio is not None and not self.uplinks:  # the common case, without checks
            for m in messages:
                self.radio.send(i, m.payload, m.to)
            return
        for m in messages:
            if m.to in self.uplinks:
                self.uplinks[m.to].send(i, m.payload)
            elif self.radio is None:
                raise MjswarmError(f"robot {i} sent a message but the world has no radio")
            else:
                self.radio.send(i, m.payload, m.to)


class Scene(NamedTuple):
    """What a loop function shows on pictures of the run (ground truth, for outputs):
    points to mark (m) and what they are, radio links to draw (pairs of points, m), and a
    word per robot (its role, say), or None."""

    marks: Sequence[tuple[float, float]] = ()
    marks_label: str = ""
    links: Sequence[tuple[tuple[float, float], tuple[float, float]]] = ()
    notes: Sequence[str] | None = None


class LoopFunctions:
    """Hooks the loop calls; override the ones an experiment needs (all optional).

    Besides the hooks of a tick, loop functions talk to each other through the loop, so
    that an experiment never needs to know what records or films it: :meth:`Loop.event`
    hands an experiment's event (a line of text, about a robot or the run) to every loop
    function's :meth:`on_event`, and pictures ask every loop function for its
    :meth:`scene`.
    """

    def initialize(self, loop: Loop) -> None:
        """Before the first tick: place robots, set up stations, radios, recorders."""

    def before_step(self, loop: Loop) -> None:
        """Start of a tick, before any robot acts (launches, faults, station grants)."""

    def after_step(self, loop: Loop) -> None:
        """After the world stepped (measurements, recording)."""

    def should_stop(self, loop: Loop) -> bool:
        """Whether the run is over."""
        return False

    def on_event(self, loop: Loop, text: str, robot: int | None) -> None:
        """Another loop function's event (see :meth:`Loop.event`), e.g. to record it."""

    def scene(self, loop: Loop) -> Scene | None:
        """What to show on a picture of the run now (None: nothing)."""
        return None

    def result(self, loop: Loop) -> Any:
        """What the run measured (the experiment's result object)."""
        return None


class Loop:
    """Runs ``controllers`` (by robot id) in ``world`` with ``functions``' hooks.

    ``stepped`` lists the robots stepped in the last tick, in order, and ``reports`` what
    they reported (``(robot, event)`` pairs from their commands' ``events``, in order):
    what loop functions learn of a robot's mind, never its attributes. A robot's
    controller is reset (:meth:`Controller.reset`) when the robot enters the floor:
    before its first step, and again after each time it was off the floor.

    A ``team`` (:class:`~algorithms.batch.BatchController`) drives every robot of the
    world as arrays, in the same phases: its robots are sensed in one call
    (:meth:`World.observe_all`) with the per-robot observations of the fixed nodes,
    decided in one call after the nodes' controllers, and acted on in one call
    (:meth:`World.act_all`) after them; ``controllers`` then holds the nodes' only, and
    the team is reset with the robots that enter the floor.
    """

    def __init__(self, world: World, controllers: Mapping[int, Controller],
                 functions: Iterable[LoopFunctions] = (),
                 team: BatchController | None = None) -> None:
        self.world = world
        self.team = team
        self.controllers: dict[int, Controller] = dict(controllers)
        self.functions: list[LoopFunctions] = []
        self.ticks = 0
        self.stepped: list = []
        self.reports: list[tuple[Any, Any]] = []
        #: whether any controller (a robot's or a fixed node's) has a perceive() of its own
        self._perceive = any(type(c).perceive is not Controller.perceive
                             for c in self.controllers.values())
        self._on_floor: set = set()  # robots reset since they last entered the floor
        self._departures = world.departures  # the world's count when _on_floor was taken
        self._stop = False
        #: how the robots are controlled (a team, or one controller each) and reset
        self._control = self._control_each if team is None else self._control_team
        self._reset = self._reset_each if team is None else team.reset
        for f in functions:
            self.add(f)

    def add(self, function: LoopFunctions) -> None:
        """Hook in one more loop function (a recording, a video); it is initialized now."""
        self.functions.append(function)
        function.initialize(self)

    def stop(self) -> None:
        """End the run after the current tick (from a hook)."""
        self._stop = True

    def event(self, text: str, robot: int | None = None) -> None:
        """An experiment's event (``robot``: the one it is about, or None for the run):
        every loop function hears it (:meth:`LoopFunctions.on_event`)."""
        for f in self.functions:
            f.on_event(self, text, robot)

    def last_words(self, i: int, order: Any) -> None:
        """Robot ``i``'s last tick, between two ticks of the run: it steps alone on an
        observation whose inbox holds only ``order`` (an experimenter's message, such as
        a dismissal from a station), its messages go on the air and the radio delivers
        them at once. The caller takes the robot off the floor next."""
        world = self.world
        command = self.controllers[i].step(
            Observation(i, world.time_s, inbox=(Message(order, i, STATION),)))
        world._send(i, command.messages)
        world.radio.step()

    def scenes(self) -> list[Scene]:
        """What the loop functions show on a picture of the run now."""
        return [s for f in self.functions if (s := f.scene(self)) is not None]

    def step(self) -> None:
        """One control tick (module docstring)."""
        world = self.world
        for f in self.functions:
            f.before_step(self)
        robots = world.active()
        self._enter(robots)
        self.stepped, self.reports = self._control(robots)
        world.step()
        self.ticks += 1
        for f in self.functions:
            f.after_step(self)
        for f in self.functions:
            if f.should_stop(self):
                self._stop = True
                break

    def _control_each(self, robots: list) -> tuple[list, list]:
        """Sense, control and act for the fixed nodes and ``robots``, one by one; the
        robots stepped and their reports."""
        nodes = self.world.nodes
        if nodes:
            robots = [*nodes, *robots]
        observe = self.world.observe
        observations = [observe(i) for i in robots]
        return robots, self._act(robots, self._decide(robots, observations))

    def _control_team(self, members: list) -> tuple[list, list]:
        """The same phases with a batched team: the nodes one by one, the team's
        ``members`` as arrays after them in each phase."""
        world, team = self.world, self.team
        nodes = list(world.nodes)
        observe = world.observe
        observations = [observe(i) for i in nodes]
        readings = world.observe_all(members)
        commands = self._decide(nodes, observations)
        team_commands = team.step_all(readings)
        reports = self._act(nodes, commands)
        world.act_all(members, team_commands)
        return [*nodes, *members], reports

    def _decide(self, robots: list, observations: list[Observation]) -> list[Command]:
        """Control: each robot's controller perceives (if any has a perceive() of its
        own), then each steps."""
        controllers = self.controllers
        if self._perceive:
            for i, o in zip(robots, observations):
                controllers[i].perceive(o)
        return [controllers[i].step(o) for i, o in zip(robots, observations)]

    def _act(self, robots: list, commands: list[Command]) -> list[tuple[Any, Any]]:
        """Act: apply each command; the ``(robot, event)`` pairs they report, in order."""
        act, reports = self.world.act, []
        for i, command in zip(robots, commands):
            act(i, command)
            if command.events:
                reports += [(i, event) for event in command.events]
        return reports

    def _enter(self, robots: list) -> None:
        """Reset the controllers of robots that entered the floor since the last tick
        (before their first step, and after each time they were off the floor)."""
        on_floor, world = self._on_floor, self.world
        if (len(on_floor) != world.robots_on_floor()
                or self._departures != world.departures):  # someone left the floor
            self._departures = world.departures
            self._on_floor = on_floor = {i for i in on_floor if world.on_floor(i)}
        if on_floor.issuperset(robots):
            return
        entering = [i for i in robots if i not in on_floor]
        on_floor.update(entering)
        self._reset(entering)

    def _reset_each(self, entering: list) -> None:
        for i in entering:
            self.controllers[i].reset()

    def run(self, max_ticks: int | None = None,
            on_tick: Callable[[Loop], None] | None = None) -> list[Any]:
        """Step until a loop function stops the run (or ``max_ticks``); the results of
        every loop function, in order. A later call runs on from where it stopped.

        While it runs, the objects that existed when it started (the world, its model,
        the controllers: some 10^5 of them with hundreds of robots) are frozen out of
        Python's cyclic garbage collector (:func:`gc.freeze`), and thawed at the end:
        otherwise each full collection rescans all of them, which cost 0.6 ms per tick at
        300 robots (``mjswarm bench``). Nothing is frozen when the caller froze already."""
        self._stop = False
        freeze = gc.get_freeze_count() == 0
        if freeze:
            gc.freeze()
        try:
            while not self._stop and (max_ticks is None or self.ticks < max_ticks):
                self.step()
                if on_tick is not None:
                    on_tick(self)
        finally:
            if freeze:
                gc.unfreeze()
        return [f.result(self) for f in self.functions]

    @property
    def stopped(self) -> bool:
        return self._stop

