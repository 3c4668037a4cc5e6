"""The graph world with a radio: Nagavarapu et al.'s graph, with positions, time in ticks, a base
at the root and a radio; a :class:`~mjswarm.worlds.loop.World` of the one loop.

Time runs in ticks of ``1 / TICKS_PER_UNIT`` time units. A robot crosses an edge in its
duration (one time unit, or proportional to its length: ``edge_time`` as in
:class:`~mjswarm.worlds.graphworld.GraphWorld`) at constant speed along the straight
segment between the vertices' positions (m), unless it stops or turns back. Radio links
join robots, and the base, within ``radio_range_m`` of each other
(:class:`~mjswarm.core.radio.Radio`: one tick of latency, every message counted).

A tick has two phases, and the loop steps each as one loop tick:

1. **move**: every robot reads the messages delivered at the end of the last tick and
   senses (:class:`~algorithms.robot.LegSense`) its leg and, from the places of the last
   tick's end, its radio neighbours; a robot at a vertex whose time has come (it arrived
   in the last tick, or its idling is over) gets a vertex call (the vertex's beacon and
   :class:`~algorithms.robot.VertexSense`); then every robot answers: a vertex call with
   ``edge_rad`` (leave along that edge) or nothing (idle one time unit), and a robot on
   an edge (or just leaving) with the sign of ``v_m_s``: on along the edge (> 0), back
   (< 0) or stay (0). The steps are taken together: what a robot senses does not depend
   on who acted before it in the tick (the beacon of a vertex aside, by design);
2. **answer**: every robot senses its neighbours from the new places and may speak
   (Nagavarapu et al.'s tether asks for adoption and beats after a move); the fixed nodes (the
   base, a robot docked at it) do not step. At the end the radio delivers.

Messages go on the air in the order of Nagavarapu et al.'s Fig. 9 run: in each phase the robots'
(in descending index, the order they step in), then the base's and the docked robot's.

The base stands at the root as the fixed node ``BASE``; with ``dock``, robot 0 is docked
at it (rule 1 of :mod:`algorithms.exploration.tether`): off the floor, on the air at the
root, stepped by the loop as a fixed node.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from algorithms.exploration import Beacon
from algorithms.exploration.base import BeaconHandle
from algorithms.exploration.tether import BASE
from algorithms.robot import NOTHING, Command, LegSense, Observation, VertexSense
from mjswarm.arena.geometry import Wall
from mjswarm.core.radio import Blocker, Radio
from mjswarm.errors import MjswarmError
from mjswarm.worlds.graphworld import GraphWorld
from mjswarm.worlds.loop import World
from mjswarm.worlds.wall_sight import wall_blocker

#: Control ticks per time unit (one edge in the unit-time graph world).
TICKS_PER_UNIT = 10
#: Share of an edge under which a robot counts as at its end (rounding of the steps).
AT_END = 1e-9
#: The two phases of a tick (module docstring).
MOVE, ANSWER = "move", "answer"


class RadioGraphWorld(World):
    """``graph``'s vertices and edges, with a base at the root and a radio of range
    ``radio_range_m`` (m); :meth:`reset` starts a run (one world serves many runs). With
    ``walls`` (the arena's corridor walls) a link needs line of sight past them, the
    base's antenna ``mast_m`` above the root (:mod:`~mjswarm.worlds.wall_sight`: the
    question the MuJoCo robots' radio answers); without, range alone decides."""

    #: one tick (time units): the loop steps it in two phases
    control_dt_s = 1 / TICKS_PER_UNIT

    def __init__(self, graph: GraphWorld, radio_range_m: float,
                 walls: Sequence[Wall] | None = None, mast_m: float = 0.0) -> None:
        if not (math.isfinite(radio_range_m) and radio_range_m > 0):
            raise MjswarmError(f"radio range must be a positive number of metres, got {radio_range_m}")
        self.graph = graph
        self.range_m = radio_range_m
        #: the arena's walls, which block links (:mod:`~mjswarm.worlds.wall_sight`), and
        #: the base's antenna height (m); None: links by range alone (the open model)
        self.walls, self.mast_m = walls, mast_m
        self.pos = {v: np.array(p, float) for v, p in graph.pos.items()}
        #: edge (v, u) -> its vector from v to u (m), and the share of it a tick covers
        self._vector = {(v, u): (graph.pos[u][0] - graph.pos[v][0],
                                 graph.pos[u][1] - graph.pos[v][1])
                        for v, u in graph.duration}
        self._share = {e: 1.0 / (d * TICKS_PER_UNIT) for e, d in graph.duration.items()}
        #: the step a robot takes in a tick on each edge (m), and from each vertex, the
        #: longest of its edges' (its next edge is its strategy's)
        self._step_m = {e: self._share[e] * math.hypot(*self._vector[e]) for e in self._share}
        self._vertex_step_m = {v: max((m for (a, _), m in self._step_m.items() if a == v),
                                      default=0.0) for v in graph.pos}
        self.uplinks = {}
        self.reset(0)

    def reset(self, n_robots: int, *, base: bool = True, dock: bool = False) -> None:
        """Start a run: ``n_robots`` robots on the root at tick 1, a base at the root on
        the air with ``base``, robot 0 docked at it with ``dock``; every beacon new."""
        g, root = self.graph, self.graph.root
        if dock and not (base and n_robots):
            raise MjswarmError("a robot docks at a base: the world needs both")
        self.n = n_robots
        self.present = np.ones(n_robots, bool)
        self.fixed = {BASE: self.graph.pos[root]} if base else {}
        self.docked = {0: self.graph.pos[root]} if dock else {}
        self.present[list(self.docked)] = False
        self.beacons = {v: Beacon() for v in g.graph}
        self.at: list[str | None] = [root] * n_robots  # vertex, or None on an edge
        self.edge: list[tuple[str, str] | None] = [None] * n_robots
        self.progress = [0.0] * n_robots  # share of the edge behind the robot
        self.xy = np.array([self.pos[root]] * n_robots).reshape(-1, 2)
        #: the same as tuples, by robot id, and the fixed nodes' (m)
        self._xy = {**{i: g.pos[root] for i in range(n_robots)}, **self.fixed}
        self.arrived_by: list[float | None] = [None] * n_robots
        self.wake = [0] * n_robots  # tick at which a robot at a vertex is called
        #: robots that reached the far end of their edge in the last move phase
        self.arrived: list[int] = []
        self.tick, self.phase = 1, MOVE
        self._order = [i for i in range(n_robots - 1, -1, -1) if self.present[i]]
        self._handles: list[BeaconHandle] = []
        self._robot_out: list = []
        self._node_out: list = []
        self.radio = None
        self._masts = dict.fromkeys([*self.fixed, *self.docked], self.mast_m)
        blocked = None if self.walls is None else wall_blocker(self.walls, self._xy,
                                                               self._masts)
        #: by step (m): the links that fade within that step of a wall (:meth:`_around`)
        self._fading: dict[float, Blocker] = {}
        self.attach_radio(Radio([*range(n_robots), *self.fixed], range_m=self.range_m,
                                blocked=blocked))

    # -- the World surface ---------------------------------------------------------------
    @property
    def time_s(self) -> float:
        """The current tick's time (time units)."""
        return self.tick / TICKS_PER_UNIT

    def active(self) -> list[int]:
        """The robots on the floor, in descending index (Nagavarapu et al.'s order)."""
        return self._order

    @property
    def nodes(self) -> list:
        """The base, then the docked robot: stepped in the move phase only."""
        return [*self.fixed, *self.docked] if self.phase == MOVE else []

    def true_poses(self) -> np.ndarray:
        """Where each robot is (m; heading 0)."""
        return np.column_stack([self.xy, np.zeros(self.n)])

    def commanded_speeds(self) -> np.ndarray:
        return np.zeros(self.n)

    def observe(self, i) -> Observation:
        if i in self.fixed or i in self.docked:
            inbox = self.radio.receive(i) if self.phase == MOVE else []
            return Observation(i, self.time_s, inbox=inbox)
        around = self._around(i)
        v, answering = self.at[i], self.phase == ANSWER
        inbox = () if answering else self.radio.receive(i)
        if v is None or answering or self.wake[i] > self.tick:  # on an edge, or not called
            steps = None if v is not None else self._steps(self.edge[i], self.progress[i])
            return Observation(i, self.time_s, inbox=inbox, leg=LegSense(
                self.progress[i], steps, NOTHING, around, answering))
        handle = BeaconHandle(self.beacons[v])
        self._handles.append(handle)
        exits = {a: self._steps((v, self.graph.towards[(v, a)]), 0.0)
                 for a in self.graph.angles[v]}
        return Observation(i, self.time_s, inbox=inbox, beacon=handle,
                           vertex=VertexSense(self.graph.angles[v], self.arrived_by[i]),
                           leg=LegSense(0.0, None, exits, around, False))

    def act(self, i, command: Command) -> None:
        """Keep the messages for the end of the phase; in the move phase, leave a vertex
        (``edge_rad``), idle, and take the step the sign of ``v_m_s`` says."""
        if i in self.fixed or i in self.docked:
            self._node_out.append((i, command.messages))
            return
        self._robot_out.append((i, command.messages))
        if self.phase == ANSWER:
            return
        v = self.at[i]
        if v is not None and self.wake[i] <= self.tick:  # a vertex call's answer
            if command.edge_rad is None:
                self.arrived_by[i], self.wake[i] = None, self.tick + TICKS_PER_UNIT
                return
            u = self.graph.nearest_exit(v, command.edge_rad)[0]
            self.at[i], self.edge[i], self.progress[i] = None, (v, u), 0.0
            self.arrived_by[i] = self.graph.angle_of[(u, v)]
        if self.edge[i] is not None and command.v_m_s != 0:
            self._walk(i, 1 if command.v_m_s > 0 else -1)

    def step(self) -> None:
        """End of a phase: the messages go on the air; after the moves the radio relinks,
        after the answers it delivers and the next tick begins."""
        for handle in self._handles:
            handle.expire()
        self._handles = []
        for out in (self._robot_out, self._node_out):
            for i, messages in out:
                for m in messages:
                    self.radio.send(i, m.payload, m.to)
            out.clear()
        if self.phase == MOVE:
            self.radio.move(self._air_positions())
            self.phase = ANSWER
        else:
            self.radio.step()
            self.tick, self.phase, self.arrived = self.tick + 1, MOVE, []

    # -- motion ----------------------------------------------------------------------------
    def _steps(self, e: tuple[str, str], progress: float):
        """One tick's displacement (m) on along edge ``e`` and back, ``progress`` of it
        behind the robot."""
        return self._step(e, progress, 1)[1], self._step(e, progress, -1)[1]

    def _step(self, e: tuple[str, str], progress: float,
              sense: int) -> tuple[float, tuple[float, float]]:
        """One tick's walk on edge ``e`` on along it (``sense`` +1) or back (-1): the
        share of the edge covered, and the displacement (m)."""
        share = min(self._share[e], 1.0 - progress if sense > 0 else progress)
        dx, dy = self._vector[e]
        return share, (sense * share * dx, sense * share * dy)

    def _walk(self, i: int, sense: int) -> None:
        """Robot ``i`` takes its step; at either end of the edge it stands on the vertex
        (called at the next tick)."""
        v, u = e = self.edge[i]
        self.progress[i] = p = self.progress[i] + sense * self._step(e, self.progress[i], sense)[0]
        if sense > 0 and p >= 1.0 - AT_END:
            self.at[i], self.edge[i], self.wake[i] = u, None, self.tick + 1
            self.arrived.append(i)
        elif sense < 0 and p <= AT_END:
            self.at[i], self.edge[i], self.wake[i] = v, None, self.tick + 1
            self.arrived_by[i] = self.graph.angle_of[(v, u)]
        (x, y), (dx, dy) = self.graph.pos[v], self._vector[e]
        self._xy[i] = xy = (x + p * dx, y + p * dy)
        self.xy[i] = xy

    def _around(self, i: int) -> dict:
        """Robot ``i``'s range-and-bearing sensing of its radio neighbours (m, relative).
        With walls, a neighbour whose link fades (its line passes within one of the
        robot's steps of a wall, in plan and in height: the step on its edge, or the
        longest from its vertex) gets no fix, as on the MuJoCo robots
        (:data:`~mjswarm.core.radio.FADE_MARGIN_M`): a point that treats it as lost backs
        off before its next step could take the link. Points step a tenth of an edge in a
        tick, so on long edges the margin is wide and the points cautious."""
        (x, y), xy = self._xy[i], self._xy
        neighbours = self.radio.neighbors(i)
        if self.walls is not None and len(neighbours):
            step = (self._vertex_step_m[self.at[i]] if self.at[i] is not None
                    else self._step_m[self.edge[i]])
            if step not in self._fading:
                self._fading[step] = wall_blocker(self.walls, self._xy, self._masts, step)
            faded = self._fading[step](np.array([(i, r) for r in neighbours], object))
            neighbours = [r for r, fades in zip(neighbours, faded) if not fades]
        return {r: (xy[r][0] - x, xy[r][1] - y) for r in neighbours}
