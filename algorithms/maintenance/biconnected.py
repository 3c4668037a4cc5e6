"""Ahmadi & Stone: adding and removing robots while the team stays biconnected.

Each robot is responsible for a circular region and holds at its centre. Two robots are
neighbours when their centres are at most ``link_m`` apart (the experiment runner derives
``link_m`` from cr; see :mod:`mjswarm.experiments.coverage`). One :class:`BiconnectedRobot`
per robot, driven once per control tick like the connectivity minds
(``tick(now, inbox, neighbors, pose) -> (messages, planar velocity)``).

Messages (one-hop broadcasts through :class:`mjswarm.core.radio.Radio` unless said otherwise):

* ``Region(robot, centre)``: a robot's region centre; flooded (relayed once per new value).
  Every robot keeps a table of the centres (the paper's "approximation of other robots'
  regions gained through communication").
* ``PosRequest()`` / ``Table(centres)``: the new robot asks, the robots that hear it answer
  to it alone with their whole table.
* ``Leave(robot, centre)``: sent by a robot about to leave (the paper's "explicit message
  from the robot which is about to quit"), heard by its neighbours.
* ``Move(key, pos, d, removed)``: flooded once per ``key`` (the leader's id and the tick it
  was sent: unique as long as each robot's own clock runs forward); every robot moves its own centre
  and every centre in its table ``d`` metres towards ``pos`` (:func:`move_towards`).
* ``Check(key, inner)``: one run of the distributed biconnectivity check
  (:class:`algorithms.connectivity.BiconnectivityCheck`, Algorithms 1-3), ``key`` telling runs
  apart; a robot joins a run on its first message.

Adding (section "Adding Robots"): the new robot sends a position request, chooses, among
centres that make it the neighbour of at least two robots, the one maximising the sum of
the distances to the two closest centres (:func:`choose_region`), drives towards nr1, asks
again once within ``link_m / 2`` of nr1 (nr1's answer overrides the others), chooses again
among centres that are neighbours of both nr1 and nr2, drives there and floods its Region.
With ``placement="min-intersection"`` it instead picks the candidate whose disc adds the
most area to the union of the known regions (the paper's centrally computed comparison).

Removing (section "Removing Robots"): the ex-neighbours hear Leave; the lowest id among
r's neighbours (computed from its table) leads. It raises d from 0 in steps of ``d_step_m``
until r's ex-neighbours, moved d towards r's centre, are biconnected (:func:`biconnected`,
Theorem 1), floods ``Move(pos, d)``, waits for the robots to get there, then runs the
distributed check; while the check says "not biconnected" it floods ``Move(pos, d')`` with
the constant ``d_extra_m`` and checks again.

Choices where the paper is silent (all in :class:`Params`):

* Geometric decisions use ``link_m - margin_m`` so that tracking errors of the embodied
  robots cannot break a planned link; membership of r's neighbourhood uses ``link_m``
  between hold points (below; the centres for points), where the robots really are, so
  the leader is a robot that heard r's Leave.
* The leader waits ``d / v_max + settle_s`` after a Move before it starts the check
  (a robot knows the team's top speed; no arrival messages).
* For a team of two the check's "connected" verdict is taken as success (the stamps check
  calls K2 not biconnected; nothing better than K2 exists for two robots).
* The new robot decides two ticks after a request (replies take one tick each way).
* Candidate centres are discretised (:func:`candidate_centres`); the first of equal
  candidates wins.

Bodies (the paper's robots are points; ``Params.clearance_m > 0`` for MuJoCo robots, 0 for
points, which then behave exactly as without this paragraph):

* a robot in the team holds at its *hold point* (:func:`regions.hold_points` of its table),
  its region centre unless another centre is closer than ``clearance_m``;
* the others' hold points in its table are the only positions a robot knows besides
  its own sensed pose. A moving robot plans a path around all of them
  (:func:`regions.path_around`, at ``clearance_m``) whenever its target or its table
  changes, and follows it at full speed to the last waypoint. Robots in the team stand
  still while a robot joins, so the joining robot sees every body; during a MOVE the
  others' hold points are where they are going, not where they are (robots crossing
  paths in a MOVE are not avoided).
"""

from __future__ import annotations

import math
from collections.abc import Hashable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

from algorithms.connectivity import BiconnectivityCheck
from algorithms.maintenance.regions import (
    biconnected,
    candidate_centres,
    hold_points,
    move_towards,
    neighbour_graph,
    path_around,
    two_closest_sum,
    union_area,
)

from algorithms.robot import Command, Controller, Message, Observation

PLACEMENTS = ("heuristic", "min-intersection")
Point = tuple[float, float]


class Region(NamedTuple):
    robot: Hashable
    centre: Point


class PosRequest(NamedTuple):
    pass


class Table(NamedTuple):
    """A robot's table of region centres, as ``(robot, centre)`` pairs in its order
    (a tuple: one message object reaches every receiver, so it must not change)."""

    centres: tuple


class Leave(NamedTuple):
    robot: Hashable
    centre: Point


class Dismiss(NamedTuple):
    """The experimenter's order to leave the floor (from the station that runs the
    episodes): the robot answers with its ``Leave`` broadcast and nothing else."""


class Move(NamedTuple):
    key: tuple
    pos: Point
    d: float
    removed: Hashable


class Check(NamedTuple):
    key: tuple
    inner: Any


class _Inner(NamedTuple):
    """A check message unwrapped for :class:`BiconnectivityCheck` (sender, payload)."""

    sender: Hashable
    payload: Any


@dataclass(frozen=True)
class Params:
    """Parameters shared by the team (metres, seconds, m/s)."""

    link_m: float                 #: centres at most this far apart are neighbours
    region_radius_m: float        #: radius of every region (min-intersection placement)
    v_max: float                  #: top speed (the robot's, from its model)
    max_robots: int = 10          #: N of Assumption 1 (the check waits 3N ticks)
    placement: str = "heuristic"  #: one of PLACEMENTS
    margin_m: float = 0.03        #: planned links are at most link_m - margin_m long
    d_step_m: float = 0.05        #: the leader's step when raising d
    d_extra_m: float = 0.1        #: the constant d' after a failed check
    tick_s: float = 0.1           #: one control tick (the papers' c)
    gain: float = 2.0             #: proportional gain towards a target (1/s)
    tolerance_m: float = 0.01     #: arrived when this close to the target
    settle_s: float = 4.0         #: extra wait after a Move before checking
    clearance_m: float = 0.0      #: centre-to-centre distance bodies keep (0: points)

    @property
    def plan_m(self) -> float:
        return self.link_m - self.margin_m


def choose_region(centres: Mapping[Hashable, Point], params: Params,
                  must_neighbour: Sequence[Hashable] = ()) -> tuple[Point, list]:
    """The new robot's region centre and its nr1, nr2 (closest centres, nearest first).

    Candidates are those of :func:`candidate_centres` (neighbour of >= 2 robots), further
    restricted to neighbours of every robot in ``must_neighbour`` when some are. Heuristic:
    maximise :func:`two_closest_sum`; min-intersection: maximise the union area gained.
    """
    ids = list(centres)
    pts = [centres[i] for i in ids]
    candidates = candidate_centres(pts, params.plan_m)
    eps = 1e-9 * max(1.0, params.link_m)
    restricted = [p for p in candidates
                  if all(math.dist(p, centres[k]) <= params.plan_m + eps for k in must_neighbour)]
    candidates = restricted or candidates
    if params.placement == "heuristic":
        best = max(candidates, key=lambda p: two_closest_sum(p, pts))
    else:
        best = max(candidates, key=lambda p: union_area(pts + [p], params.region_radius_m))
    nearest = sorted(ids, key=lambda i: math.dist(best, centres[i]))[:2]
    return best, nearest


def least_d(ex_neighbours: Mapping[Hashable, Point], pos: Point, params: Params) -> float:
    """The leader's d: the first multiple of ``d_step_m`` after which the ex-neighbours,
    moved d towards ``pos``, are biconnected (Theorem 4). Every one of them is at most
    ``link_m`` from ``pos``, so d = link_m (all at ``pos``) always works."""
    d = 0.0
    while d < params.link_m:
        moved = {k: move_towards(c, pos, d) for k, c in ex_neighbours.items()}
        if biconnected(neighbour_graph(moved, params.plan_m)):
            return d
        d += params.d_step_m
    return params.link_m


class BiconnectedRobot(Controller):
    """One robot of Ahmadi & Stone's maintenance: holds its region, joins, leads after a removal.

    As a :class:`~algorithms.robot.Controller` (:meth:`step`) it reads its positioning
    sensor and radio and answers with a planar velocity and its messages; its clock is
    the tick number ``round(time_s / params.tick_s)`` (the team's common clock).

    Args:
        robot_id: unique, ordered id (Assumption 3).
        params: team parameters.
        centre: the region centre of a robot already in the team; None for a robot that
            is joining (it starts with the position request).
    """

    def __init__(self, robot_id: Hashable, params: Params, centre: Point | None = None) -> None:
        if params.placement not in PLACEMENTS:
            raise ValueError(f"unknown placement {params.placement!r}")
        self.id = robot_id
        self.params = params
        self._start = centre
        self.reset()

    def reset(self) -> None:
        """Start afresh: in the team at the region given to the constructor, or joining
        (a robot put back on the floor joins again)."""
        robot_id, centre = self.id, self._start
        self.centre: Point | None = centre
        #: the region centres this robot knows, its own included once it holds one
        self.table: dict[Hashable, Point] = {} if centre is None else {robot_id: centre}
        #: joining stage: None (in the team), "ask", "to-nr1", "ask-again", "to-region"
        self.stage: str | None = "ask" if centre is None else None
        self._asked_at: int | None = None
        self._replies: list[tuple[Hashable, dict]] = []
        self._target: Point | None = None
        self._nr: list = []
        self._moves_seen: set = set()
        self._checks: dict[tuple, BiconnectivityCheck] = {}
        self._check_key: tuple | None = None
        self._old_checks: set[tuple] = set()
        # leadership after a removal: (removed id, its centre); when to start the next check
        self._lead: tuple[Hashable, Point] | None = None
        self._check_at: int | None = None
        #: Move messages this robot originated and distributed checks it initiated
        self.moves_led = 0
        self.checks_led = 0
        self._held: tuple[tuple, dict[Hashable, Point]] = ((), {})
        self._path: tuple[tuple | None, list[Point]] = (None, [])  # (key, waypoints)

    # -- what it reports ---------------------------------------------------------------
    @property
    def busy(self) -> bool:
        """Joining, or leading a repair that has not ended."""
        return self.stage is not None or self._lead is not None

    @property
    def hold(self) -> Point | None:
        """Where this robot holds (m): its centre, or its hold point when bodies are
        closer than ``clearance_m`` (:func:`regions.hold_points`); None while joining."""
        if self.centre is None or self.params.clearance_m <= 0.0:
            return self.centre
        return self._hold_points().get(self.id, self.centre)

    def _hold_points(self) -> dict[Hashable, Point]:
        """Hold points of every robot in the table (cached per table content)."""
        key = tuple(self.table.items())
        if self._held[0] != key:
            self._held = (key, hold_points(self.table, self.params.clearance_m))
        return self._held[1]

    # -- one control tick ---------------------------------------------------------------
    def step(self, observation: Observation) -> Command:
        """One control tick from the robot's positioning sensor and radio; dismissed
        (:class:`Dismiss` in the inbox), the robot only broadcasts its ``Leave``."""
        if any(type(m.payload) is Dismiss for m in observation.inbox):
            return Command(messages=(Message(Leave(self.id, self.centre)),))
        out, velocity = self.tick(round(observation.time_s / self.params.tick_s),
                                  observation.inbox, observation.neighbors, observation.pose)
        return Command(velocity_m_s=tuple(velocity), messages=tuple(out))

    def telemetry(self) -> dict[str, float]:
        """Busy (joining or leading a repair), regions it knows, MOVE floods and
        distributed checks it led, the region it guards: its centre (m) and radius (m),
        and where it holds (m; these absent while it has no region)."""
        out = {"busy": float(self.busy), "known_regions": len(self.table),
               "moves_led": self.moves_led, "checks_led": self.checks_led}
        if self.centre is not None:
            hold = self.hold
            out |= {"region_x_m": float(self.centre[0]), "region_y_m": float(self.centre[1]),
                    "region_radius_m": self.params.region_radius_m,
                    "hold_x_m": float(hold[0]), "hold_y_m": float(hold[1])}
        return out

    def tick(self, now: int, inbox: Iterable[Message], neighbors: Iterable[Hashable],
             pose: Sequence[float]) -> tuple[list[Message], Point]:
        """Handle this tick's messages; answer with messages and a planar velocity (m/s)."""
        out: list[Message] = []
        check_inbox: dict[tuple, list[_Inner]] = {}
        for m in inbox:
            p = m.payload
            if isinstance(p, Region):
                if self.table.get(p.robot) != p.centre and p.robot != self.id:
                    self.table[p.robot] = p.centre
                    out.append(Message(p))
            elif isinstance(p, PosRequest):
                if self.stage is None:
                    out.append(Message(Table(tuple(self.table.items())), to=m.sender))
            elif isinstance(p, Table):
                self._replies.append((m.sender, dict(p.centres)))
            elif isinstance(p, Leave):
                self._on_leave(p, now, out)
            elif isinstance(p, Move):
                self._on_move(p, out)
            elif isinstance(p, Check):
                check_inbox.setdefault(p.key, []).append(_Inner(m.sender, p.inner))
        self._run_checks(now, check_inbox, neighbors, out)
        if self._lead is not None:
            self._lead_step(now, out)
        if self.stage is not None:
            self._join_step(now, pose, out)
        target = self.hold if self.stage is None else self._target
        return out, self._velocity(pose, target)

    # -- adding ---------------------------------------------------------------------------
    def _join_step(self, now: int, pose: Sequence[float], out: list[Message]) -> None:
        here = (float(pose[0]), float(pose[1]))
        if self.stage in ("ask", "ask-again") and self._asked_at is None:
            self._asked_at, self._replies = now, []
            out.append(Message(PosRequest()))
            return
        if self.stage in ("ask", "ask-again") and now >= self._asked_at + 2:
            table: dict[Hashable, Point] = {}
            for _, centres in self._replies:
                table.update(centres)
            if self.stage == "ask-again":  # nr1's own answer is the freshest
                table.update(next((c for s, c in self._replies if s == self._nr[0]), {}))
            self.table = {k: tuple(v) for k, v in table.items() if k != self.id}
            self._asked_at = None
            if not self.table:  # the first robot: its region is where it stands
                self._target, self.stage = here, "to-region"
            elif self.stage == "ask":
                self._target, self._nr = choose_region(self.table, self.params)
                self.stage = "to-nr1"
            else:
                must = [k for k in self._nr if k in self.table]
                self._target, _ = choose_region(self.table, self.params, must)
                self.stage = "to-region"
        if self.stage == "to-nr1":
            nr1 = self.table[self._nr[0]]
            if math.dist(here, nr1) <= self.params.link_m / 2:
                self._target, self.stage = here, "ask-again"
            else:
                self._target = nr1
        elif self.stage == "to-region" and math.dist(here, self._target) <= self.params.tolerance_m:
            self.centre = self._target
            self.table[self.id] = self.centre
            self.stage = None
            out.append(Message(Region(self.id, self.centre)))

    # -- removing -------------------------------------------------------------------------
    def _on_leave(self, p: Leave, now: int, out: list[Message]) -> None:
        held = self._hold_points()
        gone = held.get(p.robot, p.centre)
        self.table.pop(p.robot, None)
        if self.stage is not None:
            return
        ex = {k: c for k, c in self.table.items()
              if math.dist(held.get(k, c), gone) <= self.params.link_m + 1e-9}
        if ex and min(ex) == self.id:
            self._lead = (p.robot, p.centre)
            self._flood_move(least_d(ex, p.centre, self.params), now, out)

    def _flood_move(self, d: float, now: int, out: list[Message]) -> None:
        removed, pos = self._lead
        self.moves_led += 1
        self._on_move(Move((self.id, now), pos, d, removed), out)
        self._check_at = now + math.ceil((d / self.params.v_max + self.params.settle_s)
                                         / self.params.tick_s)

    def _on_move(self, p: Move, out: list[Message]) -> None:
        if p.key in self._moves_seen:
            return
        self._moves_seen.add(p.key)
        out.append(Message(p))
        self.table.pop(p.removed, None)
        self.table = {k: move_towards(c, p.pos, p.d) for k, c in self.table.items()}
        if self.centre is not None:
            self.centre = self.table[self.id]

    def _lead_step(self, now: int, out: list[Message]) -> None:
        if self._check_at is not None:
            if now < self._check_at:
                return
            self._check_at = None
            self.checks_led += 1
            if self._check_key is not None:
                self._old_checks.add(self._check_key)
            self._check_key = (self.id, now)
            self._checks = {self._check_key: BiconnectivityCheck(
                self.id, len(self.table), max_robots=self.params.max_robots, initiator=True)}
            self._tick_check(self._check_key, now, [], (), out)
        check = self._checks[self._check_key]
        if check.result is None:
            return
        if check.biconnected if len(self.table) > 2 else check.connected:
            self._lead = None
        else:
            self._flood_move(self.params.d_extra_m, now, out)

    def _run_checks(self, now: int, inbox: dict[tuple, list[_Inner]],
                    neighbors: Iterable[Hashable], out: list[Message]) -> None:
        for key in inbox:
            if key != self._check_key and key not in self._old_checks:  # a new run
                if self._check_key is not None:
                    self._old_checks.add(self._check_key)
                self._check_key = key
                self._checks = {key: BiconnectivityCheck(
                    self.id, len(self.table), max_robots=self.params.max_robots)}
        if self._check_key in self._checks:
            self._tick_check(self._check_key, now, inbox.get(self._check_key, []),
                             neighbors, out)

    def _tick_check(self, key: tuple, now: int, inbox: list[_Inner],
                    neighbors: Iterable[Hashable], out: list[Message]) -> None:
        out += [Message(Check(key, m.payload), m.to)
                for m in self._checks[key].tick(now, inbox, neighbors)]

    # -- motion ---------------------------------------------------------------------------
    def _velocity(self, pose: Sequence[float], target: Point | None) -> Point:
        """Towards ``target`` at ``gain * distance`` capped at ``v_max``; with bodies, via
        the waypoints of :meth:`_waypoint`, at ``v_max`` to all but the last."""
        if target is None:
            return 0.0, 0.0
        cruise = False
        if self.params.clearance_m > 0.0:
            target, cruise = self._waypoint(pose, target)
        dx, dy = target[0] - pose[0], target[1] - pose[1]
        dist = math.hypot(dx, dy)
        if dist <= self.params.tolerance_m / 2 and not cruise:
            return 0.0, 0.0
        speed = self.params.v_max if cruise else min(self.params.v_max, self.params.gain * dist)
        return dx / dist * speed, dy / dist * speed

    def _waypoint(self, pose: Sequence[float], target: Point) -> tuple[Point, bool]:
        """The next waypoint of a path around the others' hold points (planned again
        whenever the target or the table changes), and whether more follow it."""
        key = (target, tuple(self.table.items()))
        if self._path[0] != key:
            others = [p for k, p in self._hold_points().items() if k != self.id]
            self._path = (key, path_around(pose, target, others, self.params.clearance_m))
        waypoints = self._path[1]
        while len(waypoints) > 1 and math.dist(pose[:2], waypoints[0]) <= 2 * self.params.tolerance_m:
            waypoints.pop(0)
        return waypoints[0], len(waypoints) > 1
