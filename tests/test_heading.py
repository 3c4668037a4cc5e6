"""Heading re-anchoring and scan direction (issue 13): the pure pieces, checked against
brute force and ground truth."""

from __future__ import annotations

import math

import numpy as np
import pytest

from algorithms.navigation import Navigator, NavigatorState
from algorithms.navigation.driving import Navigating
from algorithms.navigation.navigator import frame_offset
from mjswarm.arena import incidence_angle, load_arena
from mjswarm.arena.builder import arena_world_spec
from mjswarm.worlds.loop import Loop
from mjswarm.worlds.navigation import calibration, conventions
from mjswarm.core.simulation import Simulation
from mjswarm.worlds.sparkworld import SparkWorld
from mjswarm.core.world import Pose2D


def random_fan(rng: np.random.Generator) -> list[float]:
    """Edge angles at a vertex, at least 45 degrees apart."""
    while True:
        angles = np.sort(rng.uniform(0, 2 * np.pi, rng.integers(1, 7)))
        gaps = np.diff(np.r_[angles, angles[0] + 2 * np.pi])
        if len(angles) == 1 or gaps.min() >= math.radians(45):
            return list(angles)


@pytest.mark.parametrize("seed", range(200))
def test_frame_offset_recovers_the_rotation(seed):
    """Measured = stored rotated by -delta plus noise: frame_offset returns delta within
    the noise, as a brute-force search over rotations does."""
    rng = np.random.default_rng(seed)
    stored = random_fan(rng)
    delta = rng.uniform(-math.radians(15), math.radians(15))
    noise = rng.normal(0.0, math.radians(0.5), len(stored))
    measured = [(a - delta + n) % (2 * math.pi) for a, n in zip(stored, noise)]
    got = frame_offset(measured, stored)
    grid = np.linspace(-0.3, 0.3, 6001)
    cost = [sum(math.cos(s - m - g) for s, m in zip(stored, measured)) for g in grid]
    assert got == pytest.approx(grid[int(np.argmax(cost))], abs=1e-3)
    assert abs(got - delta) < math.radians(0.5) * 3


@pytest.mark.parametrize("direction", [1, -1])
def test_scans_in_either_direction_measure_the_true_angles(direction):
    """A robot on a vertex centre of fig9 scans clockwise or counter-clockwise and finds
    the same edges within 2 degrees (its second scan turns the other way)."""
    spec = load_arena("fig9")
    x, y = spec.vertices["v4"]
    sim = Simulation(arena_world_spec(spec, [Pose2D(x, y, 0.3)]))
    nav = Navigator(calibration(sim.geometry), conventions(sim.geometry), 0.3, 0.1)
    driver = Loop(SparkWorld(sim), {0: Navigating(nav)})
    for scan in range(2 if direction == -1 else 1):
        nav.begin_at_vertex()
        while nav.state is not NavigatorState.AT_VERTEX:
            driver.step()
    truth = [incidence_angle(spec, "v4", w) for w in spec.graph()["v4"]]
    for t in truth:
        assert min(abs(math.remainder(m - t, 2 * math.pi)) for m in nav.edge_angles) < (
            math.radians(2.0))
