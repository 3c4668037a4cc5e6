"""Ahmadi & Stone's geometry: union area, MOVE, Theorem 1, region choice and the leader's d,
checked against closed forms, grids, networkx and brute force on seeded random cases."""

from __future__ import annotations

import itertools
import math

import networkx as nx
import numpy as np
import pytest

from algorithms.maintenance.biconnected import Params, choose_region, least_d
from algorithms.maintenance.regions import (
    biconnected,
    hold_points,
    move_towards,
    neighbour_graph,
    path_around,
    two_closest_sum,
    union_area,
)


def lens_union(d: float, r: float) -> float:
    """Union of two discs of radius r with centres d apart (closed form)."""
    if d >= 2 * r:
        return 2 * math.pi * r * r
    lens = 2 * r * r * math.acos(d / (2 * r)) - d / 2 * math.sqrt(4 * r * r - d * d)
    return 2 * math.pi * r * r - lens


@pytest.mark.parametrize("d", [0.0, 0.3, 1.0, 1.7, 2.0, 2.5])
def test_union_of_two_discs_matches_closed_form(d):
    assert union_area([(0, 0), (d, 0)], 1.0) == pytest.approx(lens_union(d, 1.0), rel=1e-12)


@pytest.mark.parametrize("seed", range(12))
def test_union_area_matches_a_fine_grid(seed):
    rng = np.random.default_rng(seed)
    n, r = int(rng.integers(1, 11)), 0.5
    centres = rng.uniform(-1.5, 1.5, (n, 2))
    side = np.linspace(-2.2, 2.2, 1501)
    h = side[1] - side[0]
    x, y = np.meshgrid(side, side)
    inside = np.zeros_like(x, bool)
    for cx, cy in centres:
        inside |= (x - cx) ** 2 + (y - cy) ** 2 <= r * r
    grid = inside.sum() * h * h
    # a cell straddling a boundary is the only error: bound by total perimeter * cell diagonal
    bound = n * 2 * math.pi * r * h * math.sqrt(2)
    assert abs(union_area(centres, r) - grid) <= bound
    assert union_area(centres, r) <= n * math.pi * r * r + 1e-12


@pytest.mark.parametrize("seed", range(40))
def test_move_towards_never_lengthens_a_link(seed):
    rng = np.random.default_rng(seed)
    pts = rng.uniform(-3, 3, (8, 2))
    pos, d = rng.uniform(-3, 3, 2), rng.uniform(0, 4)
    moved = np.array([move_towards(p, pos, d) for p in pts])
    before = np.linalg.norm(pts[:, None] - pts[None], axis=-1)
    after = np.linalg.norm(moved[:, None] - moved[None], axis=-1)
    assert np.all(after <= before + 1e-12)
    travelled = np.linalg.norm(moved - pts, axis=1)
    assert np.all(travelled <= d + 1e-12)


def test_theorem1_check_agrees_with_networkx():
    rng = np.random.default_rng(7)
    seen = {True: 0, False: 0}
    for _ in range(400):
        n = int(rng.integers(1, 9))
        g = nx.gnp_random_graph(n, rng.uniform(0.2, 0.9), seed=int(rng.integers(1 << 30)))
        adj = {u: set(g[u]) for u in g}
        expected = nx.is_connected(g) if n <= 2 else nx.is_biconnected(g)
        assert biconnected(adj) == expected, sorted(g.edges)
        seen[expected] += 1
    assert min(seen.values()) > 50  # both answers were exercised


@pytest.mark.parametrize("seed", range(10))
def test_heuristic_choice_is_a_feasible_grid_optimum(seed):
    rng = np.random.default_rng(seed)
    params = Params(link_m=1.0, region_radius_m=0.5, v_max=0.2)
    # a random connected team: each new centre within the plan range of an earlier one
    pts = [np.zeros(2)]
    while len(pts) < int(rng.integers(3, 8)):
        a = rng.uniform(0, 2 * math.pi)
        pts.append(pts[int(rng.integers(len(pts)))] + rng.uniform(0.3, 0.95)
                   * np.array([math.cos(a), math.sin(a)]))
    centres = {i: (float(p[0]), float(p[1])) for i, p in enumerate(pts)}
    best, nearest = choose_region(centres, params)
    within = [i for i, c in centres.items() if math.dist(best, c) <= params.plan_m + 1e-9]
    assert len(within) >= 2 and set(nearest) <= set(within)
    value = two_closest_sum(best, list(centres.values()))
    # brute force over a grid of the feasible set
    xy = np.array(list(centres.values()))
    side = np.linspace(-4, 4, 321)
    gx, gy = np.meshgrid(side, side)
    grid = np.stack([gx.ravel(), gy.ravel()], axis=1)
    dist = np.linalg.norm(grid[:, None] - xy[None], axis=-1)
    feasible = (dist <= params.plan_m).sum(axis=1) >= 2
    two = np.sort(dist, axis=1)[:, :2].sum(axis=1)
    assert value >= two[feasible].max() - 2e-3  # candidates are 5 degrees apart on arcs
    assert value <= 2 * params.plan_m + 1e-9


@pytest.mark.parametrize("seed", range(15))
def test_least_d_is_the_first_step_that_makes_the_ex_neighbours_biconnected(seed):
    rng = np.random.default_rng(seed)
    params = Params(link_m=1.0, region_radius_m=0.5, v_max=0.2)
    pos = (0.0, 0.0)
    ex = {}
    for i in range(int(rng.integers(2, 6))):
        a, r = rng.uniform(0, 2 * math.pi), rng.uniform(0.2, 1.0)
        ex[i] = (r * math.cos(a), r * math.sin(a))
    d = least_d(ex, pos, params)
    moved = {k: move_towards(c, pos, d) for k, c in ex.items()}
    assert biconnected(neighbour_graph(moved, params.plan_m))
    if d > 0:
        earlier = {k: move_towards(c, pos, d - params.d_step_m) for k, c in ex.items()}
        assert not biconnected(neighbour_graph(earlier, params.plan_m))


@pytest.mark.parametrize("seed", range(20))
def test_hold_points_space_crowded_centres_and_leave_the_rest(seed):
    rng = np.random.default_rng(seed)
    spacing = 0.25
    centres = {i: tuple(rng.uniform(-0.6, 0.6, 2)) for i in range(int(rng.integers(2, 9)))}
    if seed % 4 == 0:  # MOVE can make centres coincide
        centres[1] = centres[0]
    held = hold_points(centres, spacing)
    pts = list(held.values())
    assert min(math.dist(a, b) for i, a in enumerate(pts) for b in pts[i + 1:]) >= spacing - 1e-3
    lonely = [k for k, c in centres.items()
              if all(math.dist(c, o) >= spacing for j, o in centres.items() if j != k)]
    if all(math.dist(centres[a], centres[b]) >= spacing
           for a in centres for b in centres if a < b):
        assert held == centres
    for k in lonely:  # only moved if a crowded neighbour was pushed into it
        assert math.dist(held[k], centres[k]) < spacing
    assert hold_points(centres, 0.0) == {k: (float(c[0]), float(c[1])) for k, c in centres.items()}


def test_hold_points_split_a_pair_symmetrically():
    held = hold_points({0: (0.0, 0.0), 1: (0.1, 0.0), 2: (2.0, 2.0)}, 0.25)
    assert held[0] == pytest.approx((-0.075, 0.0)) and held[1] == pytest.approx((0.175, 0.0))
    assert held[2] == (2.0, 2.0)


def segment_clearance(a, b, obstacle, samples=400):
    t = np.linspace(0.0, 1.0, samples)[:, None]
    return float(np.min(np.linalg.norm(np.asarray(a) + t * (np.asarray(b) - a) - obstacle, axis=1)))


@pytest.mark.parametrize("seed", range(25))
def test_path_around_keeps_its_distance_and_ends_at_the_goal(seed):
    rng = np.random.default_rng(seed)
    radius = 0.25
    start, goal = (0.0, 0.0), tuple(rng.uniform(1.0, 2.0, 2))
    obstacles = [tuple(o) for o in rng.uniform(-0.3, 2.3, (int(rng.integers(1, 10)), 2))
                 if math.dist(o, start) >= radius and math.dist(o, goal) >= radius]
    path = path_around(start, goal, obstacles, radius)
    assert path[-1] == pytest.approx(goal)
    points = [start, *path]
    if len(path) > 1:  # a detour: every leg keeps the radius (sampled finely)
        for a, b in itertools.pairwise(points):
            assert all(segment_clearance(a, b, np.array(o)) >= radius - 1e-3 for o in obstacles)
    else:  # straight: only when the straight line is free
        assert all(segment_clearance(start, goal, np.array(o)) >= radius - 1e-3
                   for o in obstacles)
    length = sum(math.dist(a, b) for a, b in itertools.pairwise(points))
    assert length >= math.dist(start, goal) - 1e-12


def test_path_around_a_boxed_in_start_falls_back_to_the_goal():
    ring = [(0.3 * math.cos(k * math.pi / 4), 0.3 * math.sin(k * math.pi / 4)) for k in range(8)]
    assert path_around((0.0, 0.0), (2.0, 0.0), ring, 0.25) == [(2.0, 0.0)]
