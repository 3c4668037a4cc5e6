"""Launching robots from the root, one at a time (a loop function of embodied exploration).

Robots wait in a depot outside the arena and are put on the root centre one at a time
(as Nagavarapu et al.'s robots were placed by hand), in ``order``, at least ``interval_s`` apart,
whenever the root is free: no launched robot that is still at work stands within
``ROOT_CLEAR_M`` of it, and (with vertex entry) no robot holds it. Each starts with
compass heading 0 along the world's +x, the common reference direction of the
incidence angles. A robot switched off while it waits is never launched, and neither is
any robot once the root is closed (a body stands in its area; the robots left
in the depot are then done, :attr:`~mjswarm.experiments.metrics.Roster.unlaunched`).
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from mjswarm.arena import ArenaSpec
from mjswarm.core.world import Pose2D
from mjswarm.worlds.loop import Loop, LoopFunctions

#: The root counts as free for a launch when no active robot is this close to it (m).
ROOT_CLEAR_M = 0.35
DEPOT_SPACING_M = 0.4
DEPOT_OFFSET_M = 1.5


def depot(spec: ArenaSpec, k: int) -> list[Pose2D]:
    """Where ``k`` robots wait before their launch: a row below the arena (m)."""
    xs = [x for x, _ in spec.vertices.values()]
    ys = [y for _, y in spec.vertices.values()]
    return [Pose2D(min(xs) + DEPOT_SPACING_M * i, min(ys) - DEPOT_OFFSET_M, 0.0)
            for i in range(k)]


class Launching(LoopFunctions):
    """Puts the robots of ``order`` on ``spec``'s root (module docstring). ``stations``
    (a :class:`~mjswarm.experiments.stations.StationService`) hears of each launch;
    ``roster`` (:class:`~mjswarm.experiments.metrics.Roster`) says who is done."""

    def __init__(self, spec: ArenaSpec, world, order: list[int], interval_s: float,
                 stations, roster) -> None:
        self.world, self.stations, self.roster = world, stations, roster
        self.root = spec.root
        self.root_xy = np.array(spec.vertices[spec.root], float)
        self.queue = deque(order)
        self.interval_s = interval_s
        self.last_launch_s = -math.inf

    def switched_off(self, i: int, reason: str) -> None:
        """Robot ``i`` was switched off (a fault): unlaunched, it never will be."""
        if i in self.queue:  # not launched yet: it never will be
            self.queue.remove(i)

    def before_step(self, loop: Loop) -> None:
        if not self.queue:
            return
        if self.root in self.stations.closed:
            for i in self.queue:
                self.roster.unlaunched.add(i)
                self.roster.finished.add(i)
                loop.event(f"R{i + 1} cannot be launched: {self.root} is closed", i)
            self.queue.clear()
            return
        now = self.world.time_s
        if now - self.last_launch_s < self.interval_s:
            return
        near = np.hypot(*(self.world.true_poses()[:, :2] - self.root_xy).T) < ROOT_CLEAR_M
        present, done = self.world.present, self.roster.is_done
        if any(present[j] and not done(j) for j in np.flatnonzero(near).tolist()):
            return  # O(robots near the root), never O(K^2)
        if self.stations.avoid and self.root in self.stations.entry.grants.holder:
            return
        i = self.queue.popleft()
        self.world.place(i, Pose2D(self.root_xy[0], self.root_xy[1], 0.0))
        self.last_launch_s = self.roster.last_progress_s = now
        self.stations.launched(i, self.root)
        loop.event(f"R{i + 1} launched at {self.root}", i)
