"""Exploration that stays connected: the tether every robot keeps to the base.

Nagavarapu et al. explore without communication limits; Kobayashi et al., Ahmadi & Stone
and Le et al. keep a team connected but do not explore. Here each robot explores with
Nagavarapu et al.'s strategy while it keeps a radio route to the base station at the
root. The strategy decides where to go; the tether only gates and delays moves. Every
rule below is ours (the papers give none for this combination):

1. **Tether.** Every robot has a *parent*: the base or a robot within radio range. The
   parent relation is a tree rooted at the base. For ``biconnected`` every robot but the
   first has two distinct parents, and the first *docks* at the base: it keeps the base
   as its one parent, never explores, and answers on the radio as the base does
   (:func:`docked`). The parent relation is then acyclic, so ordered from the base every
   robot joins the ones before it by two links, and a graph grown from an edge (base and
   first robot) by vertices joined to two earlier ones is biconnected: one robot failing
   never cuts anyone off (Le et al.'s two access paths). Rules 2-4 hold for every parent.
   The first robot stands at the root in the graph world; a body cannot (the root's
   area holds one robot, and every launch and every return passes through it), so on
   the MuJoCo robots it stays off the floor, its antenna on the base's mast: the same
   radio node as in the graph world, at the cost of one robot in both.
2. **Holding** (Kobayashi et al.'s repeater role). A robot with children does not move: it relays.
   Its children are the robots whose last beat named it as parent, and those it adopted
   in the last ``ADOPT_GRACE_TICKS`` ticks (their first beat naming it is on its way).
   One exception (ours, for bodies): when every child's last beat says the world holds
   it (it waits for a vertex area or a lane, not for its leash), the parent may step,
   as long as every child stays within the leash too (:meth:`Tether.holds`). A child
   held on a vertex centre may be waiting for the very vertex its parent stands on, and
   then neither would ever move (``fig9``, five robots at 2.5 m: a parent on a vertex
   granted its next one, its child on the vertex beyond asking for the parent's). A
   held child does not move, and once it may, it checks its own step against where its
   parent is then; on bodies a tick's move (at most 4 mm) is well inside the tether's
   margin. Points share vertices and never report being held, so in the graph world
   the rule is the plain one.
3. **Leash.** A robot that does not hold (rule 2) takes a step only if, after the step,
   its parents (and the children it may step for) are within range ``R - margin -
   reserve`` of it, or no farther than before (a body may coast a little past the leash;
   it may always come back). A step of a walk back may use
   the reserve as well (0 in the graph world; on bodies the width of a U-turn, which
   sidesteps across the lane and may take a robot at the end of its leash farther). It
   knows where its radio neighbours are relative to itself (a range-and-bearing sensor,
   as Kobayashi et al.'s robots have) and what its own step will be. Parents hold (or step
   only within the leash of children the world holds still) and the base never moves, so
   every tree link survives every tick, and nobody is ever cut off from the base.
4. **Adoption, make before break.** A robot without children whose step the leash forbids
   asks one still neighbour (or the base) that would allow the step to adopt it: the
   fewest tree hops from the base first, then the nearest. So does one that sees a still
   neighbour fewer hops from the base than its parent is (so that relays are released),
   and one whose parent has gone from its ranging (a wall came between them: the leash
   knows ranges, not walls) asks any still neighbour in range; a robot with children
   may ask the base itself, which descends from nobody. A robot that the world holds
   (rule 2) asks any still neighbour in range to replace a parent whose beat says its
   leash stopped it: that parent, left without children, may then adopt it and step on
   (on bodies a robot stopped at a corridor's mouth, its child waiting on the centre
   behind it, would otherwise hold for the child that waits for it).
   The asked robot adds it to its children at once, which makes it hold, and answers
   ``Adopted``. The asker does not move while its request is out and switches parent only
   when the answer comes and the new parent is still in range. While its own request is
   out a robot refuses requests, so simultaneous requests cannot close a cycle. A robot
   without children has no descendants and the base is nobody's, so no other request can
   close one either.
5. **Stall.** Every beat carries the latest time at which its sender
   knows that an exploring robot reached a vertex (so that its strategy decided anew), and
   the most edges it knows any robot's map to hold. The team is connected, so both reach
   everybody. A robot that knows of no such arrival for ``STALL_TIME_UNITS`` plus
   ``STALL_UNITS_PER_EDGE`` time units per known edge declares a stall (the event
   :class:`~algorithms.exploration.events.Infeasible`, the team's own verdict): a relay's
   round trip (rule 6, :mod:`algorithms.exploration.relay`) crosses each known edge at
   most twice each way, so past that time nobody is on the way to unblock anybody, no
   beacon changes, and no strategy changes its mind. It is a stall of this team, not a
   proof about the arena: the experiments weigh it against the robots the arena needs
   (:mod:`mjswarm.experiments.reach`: infeasible only with fewer).

This module is the robot side: pure Python, no simulator.
:mod:`mjswarm.experiments.radio_exploration`
runs it in a graph world with a radio and checks the tree against ground truth every
tick.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Hashable, Mapping, Sequence
from typing import NamedTuple

from algorithms.robot import Command, Controller, Message, Observation

#: Ticks a fresh adoption holds the parent before the child's beats must name it
#: (request, answer and the first beat naming the parent: one tick each, plus one).
ADOPT_GRACE_TICKS = 4
#: Time units without an exploring arrival anywhere after which a robot declares a stall
#: (rule 5), plus ``STALL_UNITS_PER_EDGE`` per edge of the largest known map.
STALL_TIME_UNITS = 25.0  # longer than rule 6's waits in a row (retreat, reserve, patience)
STALL_UNITS_PER_EDGE = 4.0
#: Name of the base station on the radio.
BASE = "base"


class Beat(NamedTuple):
    """Sent by every robot every tick: its parents, its hops from the base, whether it
    stood still in its last tick, the last tick at which it knows an exploring robot
    reached a vertex, the most edges it knows a robot's map to hold (rule 5), whether
    the world held it in its last tick (it wanted to move and waits for a vertex area
    or a lane: rule 2's exception), and whether its leash forbade its step in its last
    tick (rule 4: a child the world holds lets such a parent go)."""

    parents: tuple
    depth: int
    still: bool
    last_progress: int
    known_edges: int
    held: bool = False
    stuck: bool = False


class Adopt(NamedTuple):
    """A request to the robot it is addressed to: be my parent."""


class Adopted(NamedTuple):
    """The answer to :class:`Adopt`: the new parent's hops from the base."""

    depth: int


class Tether:
    """One robot's tether (module docstring).

    Args:
        me: this robot's radio id.
        range_m: the radio range R (m).
        parents: its parents at the start (one for ``connected``; two for
            ``biconnected``, see :func:`initial_parents`); it keeps as many.
        margin_m: the leash keeps the parents within ``R - margin_m``.
        ticks_per_unit: control ticks per time unit (for the stall rule).
        reserve_m: of that leash, what only a walk back may use (rule 3): a body
            turning back on its lane sidesteps across it, and one at the end of its
            leash must still be able to (0 for points).
    """

    def __init__(self, me: Hashable, range_m: float, parents: tuple = (BASE,),
                 margin_m: float = 0.0, ticks_per_unit: int = 10,
                 reserve_m: float = 0.0) -> None:
        self.me = me
        self.leash_m = range_m - margin_m - reserve_m
        self.reserve_m = reserve_m
        self.ticks_per_unit = ticks_per_unit
        self.parents: tuple = tuple(parents)
        self.depth = 1
        self.adopted: dict[Hashable, int] = {}  # child -> tick of adoption
        self.children: set[Hashable] = set()
        #: (asked robot, tick asked, the parent it would replace)
        self.request: tuple[Hashable, int, Hashable] | None = None
        self.heard: dict[Hashable, Beat] = {}
        self.last_progress = 0  # tick
        self.known_edges = 0

    # -------------------------------------------------------------- one tick
    def hear(self, tick: int, inbox: Sequence[Message],
             around: Mapping[Hashable, Sequence[float]], willing: bool = True) -> list[Message]:
        """Rules 1, 2 and the answering side of 4: read this tick's messages; ``around``:
        where the radio neighbours are, relative to this robot (m); ``willing``: whether
        it may adopt now (a robot that just set off refuses: the asker tries again)."""
        out: list[Message] = []
        self.heard = {}
        answer: tuple[Hashable, int] | None = None
        for m in inbox:
            p = m.payload
            if isinstance(p, Beat):
                self.heard[m.sender] = p
                self.last_progress = max(self.last_progress, p.last_progress)
                self.known_edges = max(self.known_edges, p.known_edges)
            elif isinstance(p, Adopt) and self.request is None and willing:
                self.adopted[m.sender] = tick
                out.append(Message(Adopted(self.depth), to=m.sender))
            elif isinstance(p, Adopted) and self.request is not None and m.sender == self.request[0]:
                answer = (m.sender, p.depth)
        if answer is not None:
            replaced = self.request[2]
            self.request = None
            if answer[0] not in self.parents and self._within((0.0, 0.0), around.get(answer[0])):
                self.parents = tuple(answer[0] if q == replaced else q for q in self.parents)
        elif self.request is not None and tick - self.request[1] > 2:
            self.request = None  # no answer: the request or its answer did not arrive
        depths = [self.heard[q].depth for q in self.parents if q in self.heard]
        if len(depths) == len(self.parents):
            self.depth = max(depths) + 1
        self.adopted = {c: t for c, t in self.adopted.items() if tick - t <= ADOPT_GRACE_TICKS}
        self.children = set(self.adopted) | {c for c, b in self.heard.items()
                                             if self.me in b.parents}
        return out

    def may_step(self, step: Sequence[float], around: Mapping[Hashable, Sequence[float]],
                 back: bool = False) -> bool:
        """Rule 3: whether to take ``step`` (m, this robot's displacement) given where its
        radio neighbours are relative to it (m); ``back``: a step of a walk back, which
        may use the reserve. A step that brings no parent (nor child it steps for) farther
        is always allowed: a body that coasted past the leash (or read one tick old
        ranges) may come back."""
        if self.holds() or self.request is not None:
            return False
        slack = self.reserve_m if back else 0.0
        return all(self._within(step, around.get(q), slack) or _nearer(step, around.get(q))
                   for q in (*self.parents, *self.children))

    def holds(self) -> bool:
        """Rule 2: whether it must stand still for its children: it has one that the
        world does not hold (or whose beat has not yet come)."""
        return any(c not in self.heard or not self.heard[c].held for c in self.children)

    def ask(self, tick: int, step: Sequence[float] | None,
            around: Mapping[Hashable, Sequence[float]], cut: Collection = (),
            held: bool = False) -> list[Message]:
        """Rule 4, asking side: after a tick in which this robot wanted to take ``step``
        (None: it wanted to stay) and did not, or could do with a parent nearer the base.
        With two parents it replaces one at a time: the first that forbids the step, else
        the one farthest from the base (in hops). ``cut``: parents whose link the step
        would lose for another reason than range (a wall, as the robot found). A parent
        missing from ``around`` (its link lost, or fading: a wall came between) blocks
        whatever the step, even staying: any still neighbour in range may replace it.
        ``held``: the world held it in this tick; then a parent whose beat says its leash
        stopped it may be replaced by any still neighbour in range, so that the parent,
        left without children, may adopt it or call a relay."""
        if self.request is not None:
            return []
        deepest = max(self.parents, key=lambda q: self._depth_of(q))
        if self.children:  # a relay may hop straight to the base: it is nobody's descendant
            if BASE not in self.parents and BASE in self.heard and self._within((0.0, 0.0), around.get(BASE)):
                return self._request(BASE, tick, deepest)
            return []
        blocking = [q for q in self.parents if q not in around or step is not None
                    and (q in cut or not self._within(step, around[q]))]
        stopped = [q for q in self.parents if held and q in self.heard and self.heard[q].stuck]
        best = None
        for r, beat in self.heard.items():
            if r in self.parents or not beat.still or r not in around:
                continue
            if blocking and self._within(step or (0.0, 0.0), around[r]):
                replaced = blocking[0]
            elif stopped and self._within((0.0, 0.0), around[r]):
                replaced = stopped[0]
            elif (beat.depth < self._depth_of(deepest) and self._within((0.0, 0.0), around[r])
                  and (step is None or deepest in blocking or self._within(step, around[r]))):
                replaced = deepest  # never a parent that allows the step for one that forbids it
            else:
                continue
            key = (beat.depth, math.hypot(*around[r]))
            if best is None or key < best[0]:
                best = (key, r, replaced)
        if best is None:
            return []
        return self._request(best[1], tick, best[2])

    def beat(self, tick: int, moved: bool, progressed: bool, known_edges: int,
             held: bool = False, stuck: bool = False) -> Message:
        """Rule 5's gossip, and what the others need of rules 2 and 4: ``progressed``
        when this robot reached a vertex while exploring in this tick, ``known_edges``
        the edges of its map, ``held`` when the world held it in this tick, ``stuck``
        when its leash forbade its step in this tick."""
        if progressed:
            self.last_progress = tick
        self.known_edges = max(self.known_edges, known_edges)
        return Message(Beat(self.parents, self.depth, not moved, self.last_progress,
                            self.known_edges, held, stuck))

    def stalled(self, tick: int) -> bool:
        """Rule 5: no exploring arrival known anywhere for the patience it states."""
        patience = STALL_TIME_UNITS + STALL_UNITS_PER_EDGE * self.known_edges
        return tick - self.last_progress >= math.ceil(patience * self.ticks_per_unit)

    # -------------------------------------------------------------- internals
    def _request(self, asked: Hashable, tick: int, replaced: Hashable) -> list[Message]:
        self.request = (asked, tick, replaced)
        return [Message(Adopt(), to=asked)]

    def _depth_of(self, q: Hashable) -> float:
        return 0 if q == BASE else self.heard[q].depth if q in self.heard else math.inf

    def _within(self, step: Sequence[float], offset: Sequence[float] | None,
                slack: float = 0.0) -> bool:
        """Whether a robot at ``offset`` (m, relative to here) is within the leash (plus
        ``slack``, m) after ``step``."""
        if offset is None:
            return False
        return math.hypot(offset[0] - step[0], offset[1] - step[1]) <= self.leash_m + slack


def _nearer(step: Sequence[float], offset: Sequence[float] | None) -> bool:
    """Whether ``step`` (m) brings a neighbour at ``offset`` (m, None: unheard) no farther."""
    if offset is None:
        return False
    return math.hypot(offset[0] - step[0], offset[1] - step[1]) <= math.hypot(*offset)


def initial_parents(robot: int, need: int, first: int = 0) -> tuple:
    """Parents on the root at the start: with ``need`` 1, the base; with 2, the base and
    the ``first`` robot, which docks at the base (rule 1 for ``biconnected``:
    :func:`docked`; ``robot`` must not be ``first``)."""
    if need == 1:
        return (BASE,)
    if robot == first:
        raise ValueError(f"robot {robot} docks at the base: it keeps no tether")
    return (BASE, first)


def docked(flooder) -> "BaseStation":
    """The first robot of a ``biconnected`` team, docked at the base (rule 1): the base's
    partner, one hop from it, still for good; it adopts every robot that asks, floods on
    and gossips as the base does."""
    return BaseStation(flooder, parents=(BASE,))


class BaseStation:
    """The base at the root: never moves, adopts every robot that asks, forwards flooded
    messages once (``flooder``), and gossips what rule 5 needs. With ``parents`` (the
    base), the robot docked at it (:func:`docked`)."""

    def __init__(self, flooder, parents: tuple = ()) -> None:
        self.flooder = flooder
        self.parents = tuple(parents)
        self.depth = 1 if parents else 0
        self.last_progress = 0
        self.known_edges = 0

    def step(self, inbox: Sequence[Message]) -> list[Message]:
        out = []
        for m in inbox:
            p = m.payload
            if isinstance(p, Beat):
                self.last_progress = max(self.last_progress, p.last_progress)
                self.known_edges = max(self.known_edges, p.known_edges)
            elif isinstance(p, Adopt):
                out.append(Message(Adopted(self.depth), to=m.sender))
            elif self.flooder.fresh(p):
                out.append(Message(p))
        out.append(Message(Beat(self.parents, self.depth, True, self.last_progress,
                                self.known_edges)))
        return out


class FixedNode(Controller):
    """A :class:`BaseStation` (the base, or the robot docked at it) as the controller of a
    fixed radio node that the loop steps with the robots: it reads its radio and answers
    with messages, nothing else."""

    def __init__(self, station: BaseStation) -> None:
        self.station = station

    def step(self, observation: Observation) -> Command:
        return Command(messages=tuple(self.station.step(observation.inbox)))
