"""Role switching for continuous connectivity (Kobayashi, Higuchi & Ueno, Kobayashi et al.).

Each robot is a :class:`RoleSwitchingRobot` that sees only its own position, the robots it
detects within d_s (:class:`Detected`: position and role) and its inbox, and returns its
target velocity ``u_i`` and the messages it sends. Roles (Sect. III-B): base station
(fixed at the origin), repeaters (a chain from the base station), one local leader (led
to the targets) and explorers (flocking around the local leader).

* Algorithm 1 (:meth:`RoleSwitchingRobot._switch_role`): the local leader becomes a
  repeater when ``d_{i,p_i} > eta_a d_c`` and hands its role to the child with the most
  connections; it becomes an explorer when ``d_{i,p_i} < eta_b d_c`` and hands its role to
  its parent.
* Motion laws Eq. 1-7 (:meth:`RoleSwitchingRobot._motion`), capped at ``v_max``.
* Connection management by Algorithm 2 (:mod:`.gabriel`) for the local leader and
  explorers.
* Recovery of disconnected explorers (end of Sect. III-D): head for the origin, ask a
  repeater or the base station found on the way where its child is, head there.

Units: the paper's length unit is one metre and its timestep one control step; all
lengths here are metres and velocities metres per step (the runner divides by the step
duration). The paper's caps are 0.03 unit/step and 0.15 rad/step; with a 0.15 s step,
0.03 m/step is the Spark V's 0.2 m/s.

Choices where the paper is silent (all parameters are in :class:`RoleParams`):

* The gains ``k_1..k_8``, ``d_n``, ``eta_a``, ``eta_b`` and the arrival radius are not
  given; the defaults were tuned on the point world (see :class:`RoleParams`).
* Messages: every robot sends its :class:`State` to each robot in ``A_i`` every step
  (one message per connection, so a robot receives about ``|A_i|``, as Sect. III-B
  counts). The local leader's ``(x_LL, u_LL)`` with a timestamp, the current target and
  the last arrival ride on these states; a robot keeps the newest, which is the paper's
  forwarding with expiry (:attr:`RoleParams.leader_expiry_steps`). An explorer whose
  newest leader information is older than that is *disconnected*.
* Positions of other robots come from detection (current), their ``u_j`` and ``|A_j|``
  from their last state (one step old). Detection also tells the role (the paper's
  recovery needs to recognise repeaters and the base station).
* Targets (Sect. IV-B: "the simulator informs the base station"): the base station
  starts with its first target and is sent the next ones as :class:`Target` messages by
  the experimenter; it keeps them in order and, as soon as it hears that the local leader
  reached its current target, reports :class:`TargetReached` and takes the next (the
  experimenter keeps one ahead, so the switch does not wait for a message).
* What the experimenter learns of a robot comes from its events (``Command.events``:
  :class:`TargetReached`, :class:`Connections` whenever ``A_i`` changes), the role it shows
  (``Command.signal``) and :meth:`RoleSwitchingRobot.telemetry`, never its attributes.
* Role requests (:class:`Lead`) and (dis)connection requests are messages to one robot.
  A local leader that must become a repeater but has no explorer within reach to hand
  over to keeps its role and stops (``u_i = 0``) until one joins. Line 5 is armed only
  once the local leader has been at least ``eta_b d_c`` from its parent: a child that
  has just been handed the role close to its new parent would otherwise hand it straight
  back. A local leader whose
  parent is the base station never becomes an explorer (the base station keeps its role).
* An explorer that has just handed the leadership to its parent keeps the link to it for
  that step, so the hand-over itself does not disconnect the network.
* ``|A_i| < eta_c`` in Algorithm 2 counts the AAT connections (the local leader's parent
  link is not one). Disconnected explorers run the full test every step ("re-join
  immediately").
"""

from __future__ import annotations

import enum
import math
import time
from collections import deque
from collections.abc import Hashable, Iterable, Mapping
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from algorithms.maintenance.gabriel import refresh_connections
from algorithms.robot import Command, Controller, Message, Observation


class Role(str, enum.Enum):
    BASE_STATION = "base station"
    REPEATER = "repeater"
    LOCAL_LEADER = "local leader"
    EXPLORER = "explorer"


#: roles that take part in Algorithm 2's network
FLOCK = (Role.LOCAL_LEADER, Role.EXPLORER)


@dataclass(frozen=True)
class RoleParams:
    """Parameters of Kobayashi et al. in metres and steps (1 paper unit = 1 m).

    ``d_c``, ``d_s`` = 3 and ``eta_c`` = 3 are the paper's (Sect. IV-A); ``v_max`` is its
    0.03 unit/step cap. The rest are ours: margins ``eta_a``, ``eta_b`` of Algorithm 1,
    gains ``k1..k8`` (1/step) of Eq. 1-7, neutral distance ``d_n`` (m) of Eq. 6, the
    target arrival radius (m) and the leader-information expiry (steps).
    """

    d_c: float = 3.0
    d_s: float = 3.0
    eta_a: float = 0.8
    eta_b: float = 0.2
    eta_c: int = 3
    k1: float = 0.05
    k2: float = 0.05
    k3: float = 0.02
    k4: float = 0.02
    k5: float = 0.5
    k6: float = 0.02
    k7: float = 0.5
    k8: float = 0.01
    d_n: float = 1.0
    v_max: float = 0.03
    arrival_radius: float = 0.3
    leader_expiry_steps: int = 10


class Detected(NamedTuple):
    """A robot seen within d_s: its position (m) and role."""

    x: np.ndarray
    role: Role


class LeaderInfo(NamedTuple):
    """The local leader's position and input at step ``stamp`` (Eq. 7's x_LL, u_LL)."""

    stamp: int
    x: tuple[float, float]
    u: tuple[float, float]


class Target(NamedTuple):
    """The ``seq``-th patrol target (m), issued by the base station."""

    seq: int
    x: tuple[float, float]


class State(NamedTuple):
    """The per-step status message a robot sends to each robot in ``A_i``."""

    role: Role
    x: tuple[float, float]
    u: tuple[float, float]
    degree: int
    child: Hashable | None
    leader: LeaderInfo | None
    target: Target | None
    arrived: int


class TargetReached(NamedTuple):
    """Event of the base station (``Command.events``): it heard that the local leader
    reached target ``seq`` (Sect. IV-B's cue for the next target)."""

    seq: int


class Connections(NamedTuple):
    """Event of any robot (``Command.events``): its connections ``A_i`` now, reported in
    the tick they change (and in its first tick); the experimenter's network metric."""

    robots: frozenset


class Lead(NamedTuple):
    """Algorithm 1's request "become the local leader" (``parent=None``: keep yours)."""

    parent: Hashable | None


class Connect(NamedTuple):
    """Algorithm 2's explicit connection request."""


class Disconnect(NamedTuple):
    """Algorithm 2's explicit disconnection request."""


class Query(NamedTuple):
    """A disconnected explorer asks a repeater or the base station where its child is."""


class ChildAt(NamedTuple):
    """The answer to :class:`Query`: the child's last known position (m)."""

    x: tuple[float, float]


def _clip(u: np.ndarray, v_max: float) -> np.ndarray:
    speed = float(np.linalg.norm(u))
    return u * (v_max / speed) if speed > v_max else u


def _unit(v: np.ndarray) -> np.ndarray:
    norm = float(np.linalg.norm(v))
    return v / norm if norm > 1e-12 else np.zeros(2)


class RoleSwitchingRobot(Controller):
    """One robot's controller for Kobayashi et al..

    As a :class:`~algorithms.robot.Controller` (:meth:`step`) it reads its position from
    its positioning sensor, the robots within d_s from its range-and-bearing sensor (the
    role each shows is the signal it sets, :attr:`role`) and its radio inbox, and answers
    with the planar velocity ``u_i / step_s`` and its messages; :meth:`tick` is the
    paper's timestep on those inputs.

    Args:
        ident: the robot's id.
        role: its initial role.
        params: :class:`RoleParams`.
        parent: initial parent id (repeaters, local leader, base station).
        child: initial child id (repeaters, local leader, base station).
        connections: its initial connections ``A_i`` (the deployment's base station -
            local leader link).
        target: the base station's first :class:`Target` (the next ones come as messages).
        every_step_aat: run the Acute Angle Test on every candidate every step (the
            baseline) instead of Algorithm 2.
        step_s: the duration of one timestep (s), the control period.

    Counters ``angle_tests``, ``circle_tests`` and ``aat_seconds`` (wall time, s)
    accumulate the cost of the AAT; :meth:`telemetry` reports them.
    """

    def __init__(self, ident: Hashable, role: Role, params: RoleParams, *,
                 parent: Hashable | None = None, child: Hashable | None = None,
                 connections: Iterable[Hashable] = (), target: Target | None = None,
                 every_step_aat: bool = False, step_s: float = 0.15) -> None:
        self.id, self.role, self.params = ident, role, params
        self.step_s = step_s
        self.parent, self.child = parent, child
        self.every_step_aat = every_step_aat
        self.connections: set = set(connections)
        self.leader: LeaderInfo | None = None
        self.target = target
        self.arrived = -1
        self._targets: deque[Target] = deque()  # the base station's next targets
        self._events: list = []  # this tick's events
        self._reported: frozenset | None = None  # A_i as last reported
        self.u = np.zeros(2)
        self.angle_tests = 0
        self.circle_tests = 0
        self.aat_seconds = 0.0
        self._known: dict[Hashable, State] = {}
        self._previous_role: Role | None = None
        self._pending_leader: Hashable | None = None
        self._guide: np.ndarray | None = None
        self._holding = False
        self._collect_armed = False

    # -- public --------------------------------------------------------------------------
    def disconnected(self, now: int) -> bool:
        """An explorer without leader information fresher than the expiry (Sect. III-D)."""
        stamp = self.leader.stamp if self.leader is not None else 0
        return self.role is Role.EXPLORER and now - stamp > self.params.leader_expiry_steps

    def step(self, observation: Observation) -> Command:
        """One timestep from the robot's own sensors and radio (the class docstring)."""
        x, y, yaw = observation.pose
        detected = {k: Detected(np.array([x + d.range_m * math.cos(yaw + d.bearing_rad),
                                          y + d.range_m * math.sin(yaw + d.bearing_rad)]),
                                d.signal)
                    for k, d in observation.detections.items()}
        now = round(observation.time_s / self.step_s)
        u, out = self.tick(now, np.array([x, y]), detected,
                           [(m.sender, m.payload) for m in observation.inbox])
        return Command(velocity_m_s=tuple((u / self.step_s).tolist()),
                       messages=tuple(Message(payload, to) for to, payload in out),
                       signal=self.role, events=tuple(self._events))

    def telemetry(self) -> dict[str, float | str]:
        """Its role (the :class:`Role`'s name), the number of robots it is connected to
        (|A_i|) and the AAT's cost so far: angle and circle tests, and the wall time they
        took (s)."""
        return {"role": self.role.value, "connections": len(self.connections),
                "angle_tests": self.angle_tests, "circle_tests": self.circle_tests,
                "aat_s": self.aat_seconds}

    def tick(self, now: int, x: np.ndarray, detected: Mapping[Hashable, Detected],
             inbox: list[tuple[Hashable, object]]) -> tuple[np.ndarray, list[tuple]]:
        """One timestep: returns ``(u_i, [(recipient, message), ...])``; ``u_i`` in m/step."""
        x = np.asarray(x, float)
        out: list[tuple] = []
        self._events = []
        for sender, message in inbox:
            self._receive(sender, message, detected, out)
        self._link_layer(x, detected)
        if self.role is Role.LOCAL_LEADER:
            self._switch_role(x, detected, out)
        if self.role in FLOCK:
            self._refresh(now, x, detected, out)
        self.u = _clip(self._motion(now, x, detected, out), self.params.v_max)
        if self.role is Role.LOCAL_LEADER:
            self.leader = LeaderInfo(now, tuple(x), tuple(self.u))
            if self.target is not None and np.linalg.norm(
                    np.asarray(self.target.x) - x) < self.params.arrival_radius:
                self.arrived = max(self.arrived, self.target.seq)
        state = State(self.role, tuple(x), tuple(self.u), len(self.connections), self.child,
                      self.leader, self.target, self.arrived)
        out.extend((j, state) for j in sorted(self.connections))
        self._previous_role = self.role
        if self.role is Role.BASE_STATION:
            self._next_target()
        if self.connections != self._reported:
            self._reported = frozenset(self.connections)
            self._events.append(Connections(self._reported))
        return self.u, out

    def _next_target(self) -> None:
        """The base station, after its state went out: once it has heard that the local
        leader reached its target (Sect. IV-B), report it and take the next target it
        was sent (none until one comes)."""
        if self.target is not None and self.arrived >= self.target.seq:
            self._events.append(TargetReached(self.target.seq))
            self.target = None
        if self.target is None and self._targets:
            self.target = self._targets.popleft()

    # -- messages ------------------------------------------------------------------------
    def _receive(self, sender, message, detected, out) -> None:
        if isinstance(message, State):
            self._known[sender] = message
            if message.leader is not None and (
                    self.leader is None or message.leader.stamp > self.leader.stamp):
                self.leader = message.leader
            if message.target is not None and self.role is not Role.BASE_STATION and (
                    self.target is None or message.target.seq > self.target.seq):
                self.target = message.target  # the base station's come from the experimenter
            self.arrived = max(self.arrived, message.arrived)
        elif isinstance(message, Target):
            if self.role is Role.BASE_STATION:
                self._targets.append(message)
        elif isinstance(message, Lead):
            self.role, self._collect_armed = Role.LOCAL_LEADER, False
            self.parent = message.parent if message.parent is not None else self.parent
            self.child = None
            self.connections.add(self.parent)
        elif isinstance(message, Connect):
            seen = detected.get(sender)
            if self.role in FLOCK and seen is not None and seen.role in FLOCK:
                self.connections.add(sender)
        elif isinstance(message, Disconnect):
            if sender != self.parent:
                self.connections.discard(sender)
        elif isinstance(message, Query):
            where = self._position_of(self.child, detected)
            if where is not None:
                out.append((sender, ChildAt(tuple(where))))
        elif isinstance(message, ChildAt):
            self._guide = np.asarray(message.x, float)

    def _position_of(self, j, detected) -> np.ndarray | None:
        if j in detected:
            return detected[j].x
        if j in self._known:
            return np.asarray(self._known[j].x, float)
        return None

    # -- links ---------------------------------------------------------------------------
    def _link_layer(self, x, detected) -> None:
        """Drop links out of range d_c, and links the roles forbid (Sect. III-B)."""
        def reachable(j):
            return j in detected and np.linalg.norm(detected[j].x - x) <= self.params.d_c

        if self.role in (Role.BASE_STATION, Role.REPEATER):
            self.connections = {j for j in (self.parent, self.child)
                                if j is not None and reachable(j)}
            return
        keep = {self.parent} if self.role is Role.LOCAL_LEADER else {self._pending_leader}
        self.connections = {j for j in self.connections if reachable(j) and (
            j in keep or detected[j].role in FLOCK)}
        self._pending_leader = None

    def _refresh(self, now, x, detected, out) -> None:
        """Algorithm 2 on the local leader and explorers this robot detects."""
        candidates = {j: d.x for j, d in detected.items() if d.role in FLOCK}
        fixed = {j for j in self.connections if j not in candidates}  # parent / hand-over
        started = time.perf_counter()
        result = refresh_connections(
            x, self.connections - fixed, candidates, range_m=self.params.d_c,
            eta_c=self.params.eta_c,
            force_full=(self.every_step_aat or self._previous_role is not self.role
                        or self.disconnected(now)))
        self.aat_seconds += time.perf_counter() - started
        self.angle_tests += result.angle_tests
        self.circle_tests += result.circle_tests
        new = set(result.connections) | fixed
        out.extend((j, Connect()) for j in sorted(new - self.connections))
        out.extend((j, Disconnect()) for j in sorted(self.connections - new - fixed))
        self.connections = new

    # -- Algorithm 1 ---------------------------------------------------------------------
    def _switch_role(self, x, detected, out) -> None:
        """Algorithm 1, run by the local leader."""
        p = self.params
        where = self._position_of(self.parent, detected)
        self._holding = False
        if where is None:
            return
        distance = float(np.linalg.norm(where - x))
        if distance > p.eta_a * p.d_c:
            children = [j for j in self.connections if j != self.parent and j in detected
                        and detected[j].role is Role.EXPLORER
                        and np.linalg.norm(detected[j].x - x) < p.d_c]
            if not children:
                self._holding = True
                return
            degree = {j: self._known[j].degree if j in self._known else 0 for j in children}
            child = max(sorted(children), key=degree.__getitem__)  # ties: lowest id
            self.role, self.child = Role.REPEATER, child
            self.connections = {self.parent, child}
            out.append((child, Lead(self.id)))
        elif distance >= p.eta_b * p.d_c:
            self._collect_armed = True
        elif self._collect_armed and self.parent in detected \
                and detected[self.parent].role is Role.REPEATER:
            out.append((self.parent, Lead(None)))
            self._pending_leader = self.parent
            self.role, self.parent = Role.EXPLORER, None

    # -- Eq. 1-7 -------------------------------------------------------------------------
    def _motion(self, now, x, detected, out) -> np.ndarray:
        p = self.params
        if self.role is Role.BASE_STATION:
            return np.zeros(2)
        if self.role is Role.REPEATER:
            x_p = self._position_of(self.parent, detected)
            x_c = self._position_of(self.child, detected)
            if x_p is None:
                return np.zeros(2)
            if x_c is None:  # child lost: hold the Eq. 2 spacing to the parent only
                return p.k2 * ((x_p - x) - p.eta_a * p.d_c * _unit(x_p - x))
            child_role = detected[self.child].role if self.child in detected else None
            if child_role is Role.LOCAL_LEADER:  # Eq. 1
                return p.k1 * ((x_p - x) + (x_c - x))
            return (p.k2 * ((x_p - x) - p.eta_a * p.d_c * _unit(x_p - x))  # Eq. 2
                    + p.k3 * ((x_p - x) + (x_c - x)))
        if self.role is Role.LOCAL_LEADER:  # Eq. 3
            if self._holding or self.target is None:
                return np.zeros(2)
            return p.k4 * (np.asarray(self.target.x) - x)
        if self.disconnected(now):
            return self._recover(x, detected, out)
        self._guide = None
        neighbours = [j for j in self.connections if j in detected]
        u_m = np.zeros(2)  # Eq. 5
        if neighbours:
            u_m = p.k5 / len(neighbours) * sum(
                (np.asarray(self._known[j].u) for j in neighbours if j in self._known),
                np.zeros(2))
        u_d = np.zeros(2)  # Eq. 6
        for j in neighbours:
            offset = detected[j].x - x
            u_d += p.k6 * (offset - p.d_n * _unit(offset))
        u_l = np.zeros(2)  # Eq. 7
        if self.leader is not None:
            u_l = p.k7 * np.asarray(self.leader.u) + p.k8 * (np.asarray(self.leader.x) - x)
        return u_m + u_d + u_l  # Eq. 4

    def _recover(self, x, detected, out) -> np.ndarray:
        """Disconnected explorer: towards the origin, or towards the child of the repeater
        or base station last asked; ask the nearest one in range every step."""
        chain = [(np.linalg.norm(d.x - x), j) for j, d in detected.items()
                 if d.role in (Role.REPEATER, Role.BASE_STATION)
                 and np.linalg.norm(d.x - x) <= self.params.d_c]
        if chain:
            out.append((min(chain)[1], Query()))
        goal = self._guide if self._guide is not None else np.zeros(2)
        if np.linalg.norm(goal - x) < self.params.arrival_radius:
            self._guide = None
            return np.zeros(2)
        return self.params.v_max * _unit(goal - x)
