"""Connectivity awareness on moving embodied robots (issue 6, part 4).

With ``--radio-range R`` an embodied run gives every robot a radio (:class:`mjswarm.radio.
Radio`: range ``R``, one control tick of latency, links blocked by walls through
:attr:`mjswarm.simulation.Simulation.sight`, vectorised over pairs) and a connectivity table of internally disjoint
access paths to the reference robot R1 (seed 004, :class:`algorithms.connectivity.tables.
ConnectivityTable`), updated every control tick as links appear (table exchange) and break
(Link-Broken) while the robots move.

Each robot's *belief* is its table's answer to "does any single robot's loss cut me off
the reference?": ``biconnected`` when it has two internally disjoint access paths
(``is_doubly_connected``), ``not`` otherwise. The *truth* (ground truth, for metrics and
recordings only) is whether it shares a biconnected component (three robots or more)
with the reference in the current radio graph. Robots not yet on the arena (the depot)
are off the air.
"""

from __future__ import annotations

import networkx as nx
import numpy as np

from algorithms.connectivity.tables import ConnectivityTable
from mjswarm.radio import Blocker, Radio
from mjswarm.simulation import Simulation

#: where robots that are not on the arena are, for the radio (m): out of everyone's range
OFF_AIR = 1.0e6

BICONNECTED, NOT = "biconnected", "not"


class TableAwareness:
    """Radio plus one connectivity table per robot, stepped with the simulation.

    Args:
        sim: the world (robot ``i`` is radio id ``i``).
        range_m: communication range d_c (m).
        reference: the reference robot of the tables (default R1, index 0).
        line_of_sight: walls block links (``mj_ray``).
    """

    def __init__(self, sim: Simulation, range_m: float, reference: int = 0,
                 line_of_sight: bool = True) -> None:
        self.sim = sim
        self.reference = reference
        self.radio = Radio(range(sim.n), range_m=range_m,
                           blocked=sight_blocker(sim) if line_of_sight else None)
        self.tables = {i: ConnectivityTable(i, reference) for i in range(sim.n)}
        self.now = 0
        self.agree = 0
        self.samples = 0

    def step(self, on_air: np.ndarray) -> None:
        """One control tick: move the links, deliver, let every table react."""
        poses = self.sim.poses()
        positions = {i: (poses[i, :2] if on_air[i] else (OFF_AIR * (i + 1), OFF_AIR))
                     for i in range(self.sim.n)}
        self.radio.step(positions)
        for i, table in self.tables.items():
            for out in table.tick(self.now, self.radio.receive(i), self.radio.neighbors(i)):
                self.radio.send(i, out.payload, out.to)
        self.now += 1

    def beliefs(self) -> dict[int, str]:
        """Each robot's belief (see module docstring)."""
        return {i: BICONNECTED if t.is_doubly_connected() else NOT
                for i, t in self.tables.items() if i != self.reference}

    def truth(self) -> dict[int, str]:
        """Ground truth for the same question, from the radio graph."""
        graph = self.radio.graph()
        blocks = [c for c in nx.biconnected_components(graph)
                  if self.reference in c and len(c) >= 3]
        return {i: BICONNECTED if any(i in c for c in blocks) else NOT
                for i in self.tables if i != self.reference}

    def sample(self) -> tuple[dict[int, str], dict[int, str]]:
        """Beliefs and truth now, counted into the agreement share."""
        beliefs, truth = self.beliefs(), self.truth()
        self.samples += len(truth)
        self.agree += sum(beliefs[i] == truth[i] for i in truth)
        return beliefs, truth

    @property
    def agreement(self) -> float | None:
        """Share of sampled robot beliefs that equalled the truth (None before a sample)."""
        return self.agree / self.samples if self.samples else None


def sight_blocker(sim: Simulation) -> Blocker:
    """The radio's line-of-sight test on a simulation: a link between robots i and j is
    blocked unless each sees the other (:attr:`Simulation.sight` both ways)."""

    def blocked(pairs: np.ndarray) -> np.ndarray:
        i, j = np.asarray(pairs, np.int64).reshape(-1, 2).T
        seen = sim.sight(np.concatenate([i, j]), np.concatenate([j, i]))
        return ~(seen[: len(i)] & seen[len(i):])

    return blocked
