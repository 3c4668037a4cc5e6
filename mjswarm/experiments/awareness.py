"""Connectivity awareness on moving embodied robots: the ground truth the
robots' beliefs are checked against (the radio's line of sight is
:func:`mjswarm.core.radio.sight_blocker`).

With ``--radio-range R`` an embodied run gives every robot a radio (:class:`mjswarm.core.radio.
Radio`: range ``R``, one control tick of latency, links blocked by walls through
:attr:`mjswarm.core.simulation.Simulation.sight`, vectorised over pairs) and a connectivity
table of internally disjoint access paths to the reference robot R1 (Le et al.,
:class:`algorithms.connectivity.tables.ConnectivityTable`, kept by each
:class:`~algorithms.exploration.explorer.Explorer`). Each robot's *belief* is its table's
answer to "does any single robot's loss cut me off the reference?": ``biconnected`` when
it has two internally disjoint access paths (``is_doubly_connected``), ``not`` otherwise;
the *truth* is :func:`truth`.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable

import networkx as nx

from mjswarm.worlds.loop import Loop, LoopFunctions

BICONNECTED, NOT = "biconnected", "not"


def truth(graph: nx.Graph, reference: Hashable, robots: Iterable[Hashable]) -> dict:
    """Ground truth of each robot's belief question, from the radio graph: ``biconnected``
    when it shares a biconnected component of three robots or more with ``reference``,
    else ``not`` (also for robots off the air)."""
    blocks = [c for c in nx.biconnected_components(graph) if reference in c and len(c) >= 3]
    return {i: BICONNECTED if any(i in c for c in blocks) else NOT for i in robots}


class BeliefSampling(LoopFunctions):
    """Connectivity awareness (tables): five times a second (every ``every`` ticks),
    the truth of the radio graph at the start of the tick against each robot's belief
    (its telemetry's ``biconnected``) after the tick, for R2..RK (R1 is the reference)."""

    def __init__(self, world, every: int = 10) -> None:
        self.world, self.every = world, every
        self.agree = self.samples = 0
        self._truth: dict | None = None

    def before_step(self, loop: Loop) -> None:
        if loop.ticks % self.every == 0 and loop.ticks:
            self._truth = truth(self.world.radio.graph(), 0, range(1, self.world.n))

    def after_step(self, loop: Loop) -> None:
        if self._truth is None:
            return
        truths, self._truth = self._truth, None
        controllers = loop.controllers
        beliefs = {i: BICONNECTED if controllers[i].telemetry().get("biconnected") else NOT
                   for i in truths}
        self.samples += len(truths)
        self.agree += sum(beliefs[i] == truths[i] for i in truths)

    @property
    def agreement(self) -> float | None:
        """The share of sampled beliefs that equalled the truth (None: none sampled)."""
        return self.agree / self.samples if self.samples else None


class TetherTruth(LoopFunctions):
    """Connected exploration's ground truth, every tick with a robot on the floor: ticks
    in which some radio node had no route to the base (``cut_ticks``), or the radio graph
    with the base was not biconnected (``fragile_ticks``)."""

    def __init__(self, world) -> None:
        self.world = world
        self.ticks = self.cut_ticks = self.fragile_ticks = 0

    def after_step(self, loop: Loop) -> None:
        if self.world.present.any():
            graph = self.world.radio.graph()
            self.ticks += 1
            self.cut_ticks += not nx.is_connected(graph)
            self.fragile_ticks += not nx.is_biconnected(graph)

    def shares(self) -> tuple[float | None, float | None]:
        """The shares of those ticks that were connected, and biconnected."""
        if not self.ticks:
            return None, None
        return 1.0 - self.cut_ticks / self.ticks, 1.0 - self.fragile_ticks / self.ticks
