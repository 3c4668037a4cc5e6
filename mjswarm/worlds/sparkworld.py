"""Spark V robots in MuJoCo as a :class:`~mjswarm.worlds.loop.World`.

:class:`SparkWorld` wraps a :class:`~mjswarm.core.simulation.Simulation` (an arena, the
bench's rows, any world from :func:`mjswarm.core.world.world_spec`). Each tick a robot
observes its own rangefinders, encoders, wheel speeds and battery (the simulation's
sensor record), the bearings its :class:`~mjswarm.core.bearing.BearingSensor` reports, its
radio, and the beacon the loop functions handed it for the tick (:meth:`SparkWorld.hand_beacons`);
its ``(v, omega)`` command goes to the wheels through the model's motors. The radio's
links need line of sight both ways (:func:`mjswarm.core.radio.sight_blocker`).

Every robot is on the floor unless a loop function says otherwise (``present``: robots
waiting in a depot off the arena are neither stepped nor on the air).

**Beacons** (``beacons``, a store keyed by vertex) belong to the world: loop functions
decide in their ``before_step`` which vertex's beacon each robot may read in the tick and
hand it to the world (:meth:`SparkWorld.hand_beacons`), and the robot gets a
:class:`~algorithms.exploration.base.BeaconHandle` that works until the world steps.
A fault wipes one with :meth:`SparkWorld.wipe_beacon`. **Power**: a robot switched off
(:meth:`SparkWorld.power_off`, a fault handed in by a loop function) stands where it is,
off the air, and is no longer stepped. The world never calls a loop function.
**Fixed radio nodes** (a base station at ``fixed``, robots
``docked`` at it) are stepped by the loop before the robots (``nodes``): they observe
their radio only and answer with messages.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from algorithms.batch import BatchCommand, Readings
from algorithms.exploration.base import BeaconHandle
from algorithms.robot import NOTHING, Command, Detection, Observation
from mjswarm.core.bearing import BearingSensor
from mjswarm.core.radio import Blocker
from mjswarm.errors import MjswarmError
from mjswarm.worlds.loop import World
from mjswarm.core.simulation import Simulation


class SparkWorld(World):
    """Args:
        sim: the MuJoCo world.
        bearing: the robots' bearing sensor (None: robots have none).
        present: which robots are on the floor (default all).
        beacons: the beacon store, by vertex (None: no beacons).
        ranging: robots carry a radio-ranging sensor (as ultra-wideband radios do): the
            range and bearing of every radio neighbour, fixed nodes included, noise-free,
            as ``Observation.detections``.
        fading: with ranging, the links that fade (a :data:`~mjswarm.core.radio.Blocker`
            over node pairs, positions read from :attr:`positions`; e.g. those passing
            within :data:`~mjswarm.core.radio.FADE_MARGIN_M` of a wall): the ranging
            gets no fix through them, though they still carry messages. None: none fade.
    """

    def __init__(self, sim: Simulation, bearing: BearingSensor | None = None,
                 present: np.ndarray | None = None,
                 ranging: bool = False,
                 beacons: dict | None = None,
                 fading: Blocker | None = None) -> None:
        self.sim = sim
        self.n = sim.n
        self.present = np.ones(self.n, bool) if present is None else np.array(present, bool)
        self.control_dt_s = sim.control_dt_s
        self.bearing = bearing
        self.beacons = beacons
        #: the vertex whose beacon each robot may read in this tick, by robot
        #: (:meth:`hand_beacons`); a robot not in it reads none
        self._beacon_of: Mapping[int, Any] = NOTHING
        self.powered = np.ones(self.n, bool)
        self._handles: list[BeaconHandle] = []  # handed out this tick
        self.uplinks = {}
        self.fixed = {}
        self.docked = {}
        self.ranging = ranging
        self.fading = fading
        #: every radio node's position (m) by address, read when asked: robots' centres,
        #: fixed nodes' and docked robots' places
        self.positions = NodePositions(self)
        self._v = [0.0] * self.n  # commands of this tick, as floats (cheaper than numpy items)
        self._w = [0.0] * self.n
        self._version = -1
        self._now_s = 0.0
        self._columns: tuple = ()  # the active robots' sensor records as lists, this state
        self._row: dict | None = None  # robot -> its row in ``_columns`` (None: row = robot)
        self._pairs: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None  # k, p, beta_kp
        self._bearings: list[dict] | None = None  # the pairs as one dict per robot, when asked

    @property
    def time_s(self) -> float:
        return self.sim.time_s

    def true_poses(self) -> np.ndarray:
        return self.sim.poses()

    def contact_events(self) -> list[tuple[float, int, int]]:
        return self.sim.collisions.events

    def active(self) -> list[int]:
        """The robots on the floor and switched on."""
        return self._active_rows().tolist()

    def _active_rows(self) -> np.ndarray:
        """:meth:`active` as an index array."""
        return np.flatnonzero(self.present & self.powered)

    @property
    def nodes(self) -> list:
        """The fixed radio nodes the loop steps before the robots: the base station(s),
        then the docked robots that are switched on."""
        if not self.fixed and not self.docked:
            return []
        return [*self.fixed, *(i for i in self.docked if self.powered[i])]

    def observe(self, i) -> Observation:
        if i in self.fixed or i in self.docked:
            inbox, neighbors = self._inbox(i)
            return Observation(i, self.sim.time_s, inbox=inbox, neighbors=neighbors)
        r = self._sense()
        if not self._columns:  # one conversion of the active robots' records per state
            rows = self._active_rows()
            whole = len(rows) == self.n
            self._row = None if whole else dict(zip(rows.tolist(), range(len(rows))))
            self._columns = self._as_lists(r if whole else r[rows])
        at, columns = (i if self._row is None else self._row.get(i)), self._columns
        if at is None:  # not on the floor or switched off, and asked anyway: its record alone
            at, columns = 0, self._as_lists(r[i:i + 1])
        line, ir, encoder, wheel_speed, battery = columns
        inbox, neighbors = self._inbox(i)
        bearings = self.bearing_readings()[i] if self._pairs is not None else NOTHING
        return Observation(
            i, self._now_s, line[at], ir[at], encoder[at], wheel_speed[at], battery[at], None,
            bearings, self._ranges(i, neighbors) if self.ranging else NOTHING, inbox,
            neighbors, self._beacon(i))

    @staticmethod
    def _as_lists(records: np.ndarray) -> tuple[list, ...]:
        """Sensor records as Python lists, field by field (cheaper per robot than numpy
        items): line, IR, encoders, wheel speeds, battery."""
        return (records["line"].tolist(), records["ir"].tolist(), records["encoder"].tolist(),
                records["wheel_speed"].tolist(), records["battery"].tolist())

    def _sense(self) -> np.ndarray:
        """The simulation's sensor record now, and the bearing sensor's pairs read once
        per state (what :meth:`observe` and :meth:`observe_all` both serve)."""
        if self._version != self.sim.state_version:
            self._pairs = self.bearing.read_pairs() if self.bearing is not None else None
            self._bearings = None
            self._columns = ()
            self._version = self.sim.state_version
            self._now_s = self.sim.time_s
        return self.sim.readings()

    def observe_all(self, robots) -> Readings:
        """Every robot of ``robots``' readings at once, with no Python step per robot: the
        simulation's sensor record, the bearing sensor's pairs, the radio's inboxes (a
        team has no ranging, beacons or station links: those robots step one by one)."""
        if self.ranging or self.beacons is not None or self.uplinks:
            raise MjswarmError("a batched team has no ranging, beacons or station links")
        k = np.asarray(robots, np.intp)
        r = self._sense()[k]
        row_of = np.full(self.n, -1, np.intp)
        row_of[k] = np.arange(len(k))
        seer, seen, beta = self._pairs if self._pairs is not None else (k[:0],) * 2 + (np.empty(0),)
        row = row_of[seer]
        order = np.flatnonzero(row >= 0)
        order = order[np.lexsort((seen[order], row[order]))]
        inbox = (self.radio.receive_all(robots) if self.radio is not None
                 else ([], np.empty(0, np.intp), np.zeros(len(k) + 1, np.intp)))
        return Readings(k, self._now_s, r["line"], r["ir"], r["encoder"], r["wheel_speed"],
                        r["battery"], row[order], seen[order], beta[order], *inbox)

    def act_all(self, robots, commands: BatchCommand) -> None:
        """Apply a team's commands at once: the motion set-points, then its broadcasts."""
        k = np.asarray(robots, np.intp)
        v, w = np.array(self._v), np.array(self._w)
        v[k], w[k] = commands.v_m_s, commands.omega_rad_s
        self._v, self._w = v.tolist(), w.tolist()
        if commands.broadcast is not None:
            if self.radio is None:
                raise MjswarmError("a team broadcast but the world has no radio")
            self.radio.send_all(k[commands.broadcast].tolist(), commands.payload)

    def hand_beacons(self, vertices: Mapping[int, Any]) -> None:
        """Which vertex's beacon (a key of ``beacons``) each robot may read in this tick,
        by robot; robots not in ``vertices`` read none. Loop functions hand it in their
        ``before_step`` (the stations: the vertex whose centre a robot stands on, when
        they let it read there); it holds until the world steps."""
        self._beacon_of = vertices

    def _beacon(self, i: int) -> BeaconHandle | None:
        """A handle on the beacon robot ``i`` may read now, good until the world steps."""
        vertex = self._beacon_of.get(i)
        if vertex is None:
            return None
        handle = BeaconHandle(self.beacons[vertex])
        self._handles.append(handle)
        return handle

    def wipe_beacon(self, vertex) -> None:
        """The beacon at ``vertex`` loses its contents and id (a fault)."""
        self.beacons[vertex] = type(self.beacons[vertex])()

    def power_off(self, i: int) -> None:
        """Switch robot ``i`` off (a fault): it stands where it is (its body stays), off
        the air, and is never stepped again."""
        self.powered[i] = False
        self._v[i] = self._w[i] = 0.0
        self.set_on_air(i, False)

    def _ranges(self, i: int, neighbors) -> dict:
        """Robot ``i``'s ranging of its radio neighbours whose links do not fade: range
        (m) and bearing (rad)."""
        x, y, yaw = self.sim.poses()[i]
        if self.fading is not None and len(neighbors):
            faded = self.fading(np.array([(i, j) for j in neighbors], object))
            neighbors = [j for j, fades in zip(neighbors, faded) if not fades]
        out = {}
        for j in neighbors:
            jx, jy = self.positions[j]
            bearing = math.remainder(math.atan2(jy - y, jx - x) - yaw, 2 * math.pi)
            out[j] = Detection(math.hypot(jx - x, jy - y), bearing)
        return out

    def commanded_speeds(self) -> np.ndarray:
        return np.array(self._v)

    def bearing_readings(self) -> list[dict[int, float]]:
        """What every robot's bearing sensor reported at the last observed state (for
        recordings; empty without a bearing sensor)."""
        if self._pairs is None:
            return [{} for _ in range(self.n)]
        if self._bearings is None:
            self._bearings = self.bearing.as_dicts(*self._pairs)
        return self._bearings

    def act(self, i, command: Command) -> None:
        if i in self.fixed or i in self.docked:
            self._send(i, command.messages)  # a fixed node: its radio only
            return
        self._v[i], self._w[i] = command.v_m_s, command.omega_rad_s
        if command.messages:
            self._send(i, command.messages)

    def step(self) -> None:
        if self._handles:  # the tick is over: its beacon handles no longer work
            for handle in self._handles:
                handle.expire()
            self._handles = []
        self._beacon_of = NOTHING
        self.sim.set_velocity(np.array(self._v), np.array(self._w))
        self.sim.step()
        self._radio_step()

    def place(self, i: int, pose) -> None:
        """Put robot ``i`` on the floor at ``pose`` (:class:`~mjswarm.core.world.Pose2D`), at
        rest, and on the air (the experimenter's hand)."""
        self.sim.place_robot(i, pose)
        self.present[i] = True
        self._v[i] = self._w[i] = 0.0
        self.set_on_air(i, True)
        self.relink()


class NodePositions(Mapping):
    """Every radio node of a :class:`SparkWorld` by address: its position (m) when read
    (a fixed node's place, a docked robot's, a robot's centre)."""

    def __init__(self, world: SparkWorld) -> None:
        self._world = world

    def __getitem__(self, j) -> tuple[float, float]:
        world = self._world
        if j in world.fixed:
            return world.fixed[j]
        if j in world.docked:
            return world.docked[j]
        x, y, _ = world.sim.poses()[j]
        return float(x), float(y)

    def __iter__(self):
        world = self._world
        return iter([*world.fixed, *world.docked, *range(world.n)])

    def __len__(self) -> int:
        world = self._world
        return len(world.fixed) + len(world.docked) + world.n
