"""The patrol mission's loop functions (Kobayashi, Higuchi & Ueno, Kobayashi et al., Sect. IV-B):
the experimenter's targets for the base station, and the mission's measurements.

The experimenter never reads or writes a controller's attributes. Targets reach the base
station as :class:`~algorithms.maintenance.roles.Target` messages over an infrastructure
link (:class:`~mjswarm.core.radio.Uplink` at :data:`CONTROL`: "the simulator informs the
base station", one control tick to deliver); the base station reports the local leader's
arrival as a :class:`~algorithms.maintenance.roles.TargetReached` event. Because a
message takes a tick, the experimenter keeps the base station one target ahead: the
first target is the base station's at construction, the second is sent before the first
tick, and each report of target ``k`` is answered with target ``k + 2``, so the base
station switches to ``k + 1`` in the tick after it heard the arrival, with no wait. What
the experimenter knows of the robots: the role each shows (the world's ``signals``), each
one's connections ``A_i`` (its :class:`~algorithms.maintenance.roles.Connections` events)
and, after the run, its :meth:`~algorithms.robot.Controller.telemetry`.
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Callable, Mapping, Sequence

import networkx as nx
import numpy as np

from algorithms.maintenance.gabriel import refresh_connections
from algorithms.maintenance.roles import (
    FLOCK,
    Connections,
    Role,
    RoleParams,
    Target,
    TargetReached,
)
from mjswarm.core.radio import Uplink
from mjswarm.worlds.loop import Loop, LoopFunctions, Scene

#: The address of the experimenter's link to the base station (robot 0).
CONTROL = "mission control"


def draw_target(rng: np.random.Generator, robots: int, seq: int) -> Target:
    """The ``seq``-th target, drawn in the target square ``[0, 1.8 sqrt(N)]^2`` (m)."""
    return Target(seq, tuple(rng.uniform(0.0, 1.8 * math.sqrt(robots), 2)))


def network_graph(links: Sequence[frozenset], xy: np.ndarray, d_c: float) -> nx.Graph:
    """Mutual connections (``j in links[i]`` and ``i in links[j]``) no longer than
    ``d_c`` (m), on ground-truth positions ``xy`` (m)."""
    g = nx.Graph()
    g.add_nodes_from(range(len(links)))
    for i, mine in enumerate(links):
        for j in mine:
            if j > i and i in links[j] and np.linalg.norm(xy[i] - xy[j]) <= d_c:
                g.add_edge(i, j)
    return g


def runs(flags: list[bool]) -> list[int]:
    """Lengths of the maximal runs of True in ``flags``."""
    found, length = [], 0
    for f in flags:
        if f:
            length += 1
        elif length:
            found.append(length)
            length = 0
    return found + ([length] if length else [])


class PatrolMission(LoopFunctions):
    """The mission's loop functions: targets for the base station, and the measurements
    of :mod:`mjswarm.experiments.patrol` (ground truth, never seen by the robots).

    Args:
        rng: draws the next targets (:func:`draw_target`).
        roles: each robot's initial role (the deployment), shown from the start.
        links: the robots' initial connections ``A_i``, by robot.
        first: the base station's first target (it is built with it).
    """

    def __init__(self, rng: np.random.Generator, params: RoleParams, roles: Sequence[Role],
                 links: Mapping[int, frozenset], first: Target, sample_every: int,
                 keep_history: bool, progress: Callable[[int], None] | None) -> None:
        self.robots, self.rng, self.params = len(roles), rng, params
        self.sample_every, self.keep_history, self.progress = sample_every, keep_history, progress
        self.target = first  # the base station's now
        self.uplink = Uplink(CONTROL)
        self._sent: deque[Target] = deque()  # sent, not yet the base station's
        self.targets = 0
        self.shadow = {"angle_tests": 0, "seconds": 0.0}
        self.cut: list[bool] = []
        self.leader_cut: list[bool] = []
        self.lam: list[float] = []
        self.lam_alg2: list[float] = []
        self.lam_base: list[float] = []
        self.history: dict[str, list] = {"positions": [], "roles": [], "edges": []}
        self._flock_base = nx.Graph()
        self._acted_from = np.zeros((self.robots, 2))  # true positions at the tick's start
        self._roles = list(roles)
        self.links = [frozenset(links.get(i, ())) for i in range(self.robots)]

    def scene(self, loop: Loop) -> Scene:
        """Pictures show the base station's target, the network's links (mutual
        connections no longer than d_c) and each robot's role."""
        xy = loop.world.true_positions()
        graph = network_graph(self.links, xy, self.params.d_c)
        return Scene([self.target.x], "target (of the leader)",
                     [(xy[a], xy[b]) for a, b in graph.edges],
                     [r.value for r in loop.world.signals])

    def initialize(self, loop: Loop) -> None:
        """Show the initial roles, open the link to the base station, send it the second
        target."""
        for i, role in enumerate(self._roles):
            loop.world.show(i, role)  # the experimenter assigns the initial roles
        loop.world.uplinks[CONTROL] = self.uplink
        self._send(draw_target(self.rng, self.robots, 1))

    def _send(self, target: Target) -> None:
        self.uplink.reply(0, target)
        self._sent.append(target)

    def before_step(self, loop: Loop) -> None:
        """The every-step AAT baseline, run in the shadow on the robots each robot
        detects (within d_s, showing a flock role)."""
        t, truth = loop.ticks, loop.world.true_positions().copy()
        self._acted_from = truth
        self._flock_base = nx.Graph()
        roles = loop.world.signals
        for i in range(self.robots):
            if roles[i] not in FLOCK:
                continue
            seen = np.flatnonzero(np.linalg.norm(truth - truth[i], axis=1) <= self.params.d_s)
            candidates = {int(k): truth[k] for k in seen if k != i and roles[k] in FLOCK}
            t0 = time.perf_counter()
            base = refresh_connections(truth[i], (), candidates, range_m=self.params.d_c,
                                       eta_c=self.params.eta_c, force_full=True)
            self.shadow["seconds"] += time.perf_counter() - t0
            self.shadow["angle_tests"] += base.angle_tests
            if t % self.sample_every == 0:
                self._flock_base.add_node(i)
                self._flock_base.add_edges_from((i, k) for k in base.connections)

    def after_step(self, loop: Loop) -> None:
        """Network metrics on the positions the robots acted from, then the next target."""
        reached = False
        for i, event in loop.reports:
            if isinstance(event, Connections):
                self.links[i] = event.robots
            elif isinstance(event, TargetReached):
                reached = True
        roles = loop.world.signals
        self._measure(loop.ticks - 1, roles)
        if reached:
            self.targets += 1
            self.target = self._sent.popleft()
            self._send(draw_target(self.rng, self.robots, self.target.seq + 1))
            loop.event(f"target {self.targets} reached; next at "
                       f"({self.target.x[0]:.2f}, {self.target.x[1]:.2f}) m")
        for i, role in enumerate(roles):
            if role is not self._roles[i]:
                loop.event(f"R{i + 1}: {self._roles[i].value} -> {role.value}", i)
                self._roles[i] = role
        if self.progress is not None:
            self.progress(1)

    def _measure(self, t: int, roles: Sequence[Role]) -> None:
        """Tick ``t``'s network: cuts from the base station, and every ``sample_every``
        ticks the algebraic connectivities (and the history)."""
        truth = self._acted_from
        g = network_graph(self.links, truth, self.params.d_c)
        reach = nx.node_connected_component(g, 0)
        self.cut.append(len(reach) < self.robots)
        leaders = [i for i, r in enumerate(roles) if r is Role.LOCAL_LEADER]
        self.leader_cut.append(not leaders or leaders[0] not in reach)
        if t % self.sample_every == 0:
            self.lam.append(nx.algebraic_connectivity(g, method="tracemin_lu"))
            flock = [i for i, r in enumerate(roles) if r in FLOCK]
            for h, out_list in ((g.subgraph(flock), self.lam_alg2),
                                (self._flock_base, self.lam_base)):
                out_list.append(nx.algebraic_connectivity(h, method="tracemin_lu")
                                if h.number_of_nodes() > 1 else 0.0)
            if self.keep_history:
                self.history["positions"].append(truth.tolist())
                self.history["roles"].append([r.value for r in roles])
                self.history["edges"].append(sorted(g.edges()))
