"""The robot type: what one robot senses, what it does, and the controller in between.

Every robot in every world is a :class:`Controller` (ARGoS's ``CCI_Controller``: Init /
ControlStep / Reset): once per control tick the world hands it an :class:`Observation`
and applies the :class:`Command` it answers with. An observation holds only what a real
robot could have in that tick:

* its own sensors: the Spark V's three down-looking line rangefinders and three IR
  rangefinders (m, NaN = nothing in range), wheel encoders (rad) and speeds (rad/s) and
  battery voltage (V); on the open floor its positioning sensor's pose (the papers
  assume robots know their positions: UWB or motion capture), with its noise;
* what its exteroceptive sensors report of other robots: bearings (rad, robot frame)
  from the bearing sensor, and range-and-bearing detections with the signal each robot
  shows (an LED colour, or the data byte of a range-and-bearing board as on ARGoS's
  e-puck), keyed by the id the sensor reports;
* the radio messages it received and its current radio neighbours (link-layer
  knowledge, Le et al.'s MANET layer);
* the beacon handle of the vertex whose centre it stands on, else None;
* in the graph worlds, where robots have no bodies, what a scan of that vertex would
  measure (:class:`VertexSense`), and in the radio graph world what its odometer and
  range-and-bearing radio tell it of its leg and its neighbours (:class:`LegSense`).

It never holds another robot's pose, the arena graph or the contact list:
``tests/test_robot_type.py`` pins the field list. One :class:`Message` type carries
every message of the project, robot to robot and robot to vertex station.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Hashable, Mapping, Sequence
from types import MappingProxyType
from typing import Any, NamedTuple


class Message(NamedTuple):
    """One message: its payload, its addressee (None: a one-hop broadcast) and its
    sender (filled in by the radio on delivery; None on an outgoing message)."""

    payload: Any
    to: Hashable | None = None
    sender: Hashable | None = None


class Detection(NamedTuple):
    """One robot seen by a range-and-bearing sensor: range (m), bearing (rad, in the
    observer's frame, counter-clockwise from its heading) and the signal it shows."""

    range_m: float
    bearing_rad: float
    signal: Hashable | None = None


class VertexSense(NamedTuple):
    """What a robot of a graph world senses of the vertex it stands on (a perfect scan):
    the incidence angles of its edges (rad, counter-clockwise from the common +x, in
    (0, 2*pi], Nagavarapu et al. section 2) and the angle, here, of the edge it arrived by (None:
    it has not moved since its last call, as at the start or after idling)."""

    angles_rad: tuple[float, ...]
    arrived_by_rad: float | None


class LegSense(NamedTuple):
    """What a robot of the radio graph world senses of its motion and of its radio
    neighbours in one tick (perfect sensors: it has no body, and no heading).

    The world moves a robot along an edge at the edge's own speed (one edge per its
    duration), so what a step will be is the robot's motion model, which it knows as a
    real robot knows its speed; the tether (:mod:`algorithms.exploration.tether`, rule 3)
    judges a step by it before the robot takes it.

    Attributes:
        progress: the share of the edge it walks that is behind it (its odometry in the
            world's measure; 0 at the start of a leg, 1 at its end).
        steps_m: on an edge, one tick's displacement on along it and back (m, x and y);
            None when it stands at a vertex.
        exits_m: at a vertex call, the same pair for the first tick along each edge
            there, by incidence angle (rad); empty otherwise.
        around_m: each radio neighbour's displacement from it (m, x and y).
        answering: whether this is the tick's answer phase: every robot has moved, and
            it may speak from its new place (the world's docstring).
    """

    progress: float
    steps_m: tuple[tuple[float, float], tuple[float, float]] | None
    exits_m: Mapping[float, tuple[tuple[float, float], tuple[float, float]]]
    around_m: Mapping[Hashable, tuple[float, float]]
    answering: bool


#: An empty, read-only mapping (the default of the observation's mappings).
NOTHING: Mapping = MappingProxyType({})


class Observation(NamedTuple):
    """What one robot senses in one control tick (see the module docstring).

    Attributes:
        robot: the robot's own id.
        time_s: its clock (s).
        line_m: line rangefinders (left, centre, right), m, NaN = nothing within range;
            None where the robot has none (as every sensor below).
        ir_m: IR rangefinders (left, front, right), m, NaN = nothing within range.
        encoder_rad: wheel encoders (left, right), rad.
        wheel_speed_rad_s: wheel speeds (left, right), rad/s.
        battery_v: battery voltage, V.
        pose: positioning-sensor reading (x m, y m, yaw rad) on the open floor, else None.
        bearings: bearing (rad) to each robot the bearing sensor sees, by reported id.
        detections: range-and-bearing detections, by reported id.
        inbox: messages received this tick, in delivery order.
        neighbors: ids the radio hears this tick.
        beacon: the beacon of the vertex whose centre the robot stands on, else None.
        vertex: in a graph world, at a vertex call, what it senses of the vertex.
        leg: in the radio graph world, what it senses of its leg and its neighbours.
    """

    robot: Hashable
    time_s: float
    line_m: Sequence[float] | None = None
    ir_m: Sequence[float] | None = None
    encoder_rad: Sequence[float] | None = None
    wheel_speed_rad_s: Sequence[float] | None = None
    battery_v: float | None = None
    pose: tuple[float, float, float] | None = None
    bearings: Mapping[Hashable, float] = NOTHING
    detections: Mapping[Hashable, Detection] = NOTHING
    inbox: Sequence[Message] = ()
    neighbors: frozenset = frozenset()
    beacon: Any = None
    vertex: VertexSense | None = None
    leg: LegSense | None = None


class Command(NamedTuple):
    """What one robot does in one control tick.

    Attributes:
        v_m_s: unicycle command, forward speed (m/s).
        omega_rad_s: unicycle command, turn rate (rad/s).
        velocity_m_s: a planar velocity (m/s, world frame) instead; the open floor's
            tracker (:func:`algorithms.motion.track_velocity`) turns it into ``(v, omega)``
            from the robot's sensed heading.
        messages: what it transmits (one-hop broadcasts, or addressed ones).
        signal: what it shows to other robots' range-and-bearing sensors from now on
            (None: keep showing the previous signal).
        edge_rad: in a graph world, leave the vertex along the edge at this incidence
            angle (rad); None: stay (the world calls again one time unit later).
        events: what the robot reports this tick, for the experimenter only (its log, as
            a real robot's is read after a run): immutable values of types the
            controller defines, never delivered to another robot.
    """

    v_m_s: float = 0.0
    omega_rad_s: float = 0.0
    velocity_m_s: tuple[float, float] | None = None
    messages: tuple[Message, ...] = ()
    signal: Hashable | None = None
    edge_rad: float | None = None
    events: tuple = ()


#: The command of a robot that stands still and says nothing.
STOP = Command()


class Controller(ABC):
    """One robot's mind: :meth:`reset` when it is put into a world, then :meth:`step`
    once per control tick (after every robot of the tick has :meth:`perceive`-d)."""

    def reset(self) -> None:  # noqa: B027 - a hook: most controllers keep no episode state
        """Called when the robot is (re)placed in a world, before its first step."""

    def perceive(self, observation: Observation) -> None:  # noqa: B027 - a hook
        """Called for every robot of a tick before any of them steps: bookkeeping that
        must reach what robots share (the beacon they stand on) before any robot of the
        tick decides (Brass et al.'s model of simultaneous arrivals for MR-DFS)."""

    @abstractmethod
    def step(self, observation: Observation) -> Command:
        """Answer one tick's observation with a command."""

    def telemetry(self) -> Mapping[str, float | str]:
        """What describes its state now, for recordings (none by default): named numbers
        (drawn as time series) and named states (strings, drawn as state lanes)."""
        return NOTHING
