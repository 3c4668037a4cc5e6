"""Acute Angle Test and Algorithm 2 (Kobayashi et al.) against the centrally computed Gabriel graph."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import Delaunay

from algorithms.maintenance.gabriel import gabriel_graph, refresh_connections

SEEDS = range(60)


def _scene(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 25))
    side = np.sqrt(n)  # the paper's constant density (Sect. IV-A)
    return rng.uniform(0.0, side, (n, 2)), float(rng.choice([1.5, 3.0, np.inf]))


def _candidates(points, i, detect_m):
    return {k: points[k] for k in range(len(points))
            if k != i and np.linalg.norm(points[k] - points[i]) <= detect_m}


def _neighbours(edges, i):
    return {next(iter(e - {i})) for e in edges if i in e}


@pytest.mark.parametrize("seed", SEEDS)
def test_every_robot_running_the_aat_builds_the_gabriel_graph(seed):
    points, range_m = _scene(seed)
    central = gabriel_graph(points, range_m)
    for i in range(len(points)):
        mine = refresh_connections(points[i], (), _candidates(points, i, range_m),
                                   range_m=range_m, eta_c=3, force_full=True)
        assert set(mine.connections) == _neighbours(central, i)


@pytest.mark.parametrize("seed", SEEDS[:20])
def test_gabriel_graph_is_the_delaunay_subgraph_with_empty_diametral_discs(seed):
    points, _ = _scene(seed)
    delaunay = set()
    for simplex in Delaunay(points).simplices:
        for a in range(3):
            for b in range(a + 1, 3):
                delaunay.add(frozenset((int(simplex[a]), int(simplex[b]))))
    central = gabriel_graph(points)
    assert central <= delaunay
    brute = {frozenset((i, j)) for i in range(len(points)) for j in range(i + 1, len(points))
             if all(np.dot(points[i] - points[k], points[j] - points[k]) > 0
                    for k in range(len(points)) if k not in (i, j))}
    assert central == brute


@pytest.mark.parametrize("seed", SEEDS)
def test_algorithm2_drops_every_non_gabriel_link_and_keeps_the_others(seed):
    points, range_m = _scene(seed)
    rng = np.random.default_rng(1000 + seed)
    central = gabriel_graph(points, range_m)
    for i in range(len(points)):
        candidates = _candidates(points, i, range_m)
        current = {k for k in candidates if rng.uniform() < 0.5} | _neighbours(central, i)
        result = refresh_connections(points[i], current, candidates, range_m=range_m,
                                     eta_c=0, force_full=False)
        assert set(result.connections) == _neighbours(central, i)


@pytest.mark.parametrize("seed", SEEDS[:30])
def test_algorithm2_is_free_on_a_settled_gabriel_graph_and_only_prunes_partial_sets(seed):
    points, range_m = _scene(seed)
    central = gabriel_graph(points, range_m)
    for i in range(len(points)):
        candidates = _candidates(points, i, range_m)
        gg = _neighbours(central, i)
        settled = refresh_connections(points[i], gg, candidates, range_m=range_m, eta_c=0,
                                      force_full=False)
        assert set(settled.connections) == gg
        assert settled.angle_tests == 0
        assert settled.circle_tests == len(gg) * max(len(candidates) - 1, 0)
        full = refresh_connections(points[i], gg, candidates, range_m=range_m, eta_c=0,
                                   force_full=True)
        assert full.angle_tests == len(candidates) * max(len(candidates) - 1, 0)
        partial = set(list(gg)[: len(gg) // 2])
        kept = refresh_connections(points[i], partial, candidates, range_m=range_m,
                                   eta_c=0, force_full=False)
        assert set(kept.connections) == partial  # no new links without a trigger


def test_fewer_connections_than_eta_c_trigger_the_full_test():
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.2]])
    candidates = {k: points[k] for k in (1, 2, 3)}
    result = refresh_connections(points[0], {1}, candidates, range_m=3.0, eta_c=3,
                                 force_full=False)
    assert set(result.connections) == {1, 2, 3}


def test_a_witness_on_the_circle_blocks_the_link():
    x_i, x_j = np.array([0.0, 0.0]), np.array([2.0, 0.0])
    candidates = {1: x_j, 2: np.array([1.0, 1.0])}  # right angle at robot 2
    result = refresh_connections(x_i, (), candidates, range_m=3.0, eta_c=3, force_full=True)
    assert 1 not in result.connections and 2 in result.connections
