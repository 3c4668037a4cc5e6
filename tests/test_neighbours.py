"""One neighbour search per set of positions, shared by the bearing sensor and the radio,
gives each what a search of its own gives: the same pairs, the same bearings, the same
links, whoever asks first and whatever the ranges."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from mjswarm.core import bearing as bearing_module
from mjswarm.core.bearing import BearingSensor
from mjswarm.core.neighbours import Neighbours
from mjswarm.core.radio import Radio, sight_blocker
from mjswarm.core.sight import LineOfSight
from mjswarm.core.simulation import Simulation
from mjswarm.core.world import Pose2D, world_spec
from test_radio import brute_force_links, random_team
from test_raycast import arena_sims, random_state


@pytest.mark.parametrize("seed", range(24))
def test_pairs_equal_the_exact_rule_and_survive_other_askers(seed):
    """Lattices with pairs exactly at the range and random points; one search asked
    about other positions and ranges in between answers as a fresh one."""
    _, positions, range_m = random_team(seed)
    xy = np.array([p for p in positions.values() if np.isfinite(p).all()])
    expected = sorted(tuple(sorted(e)) for e in brute_force_links(dict(enumerate(xy)), range_m))
    shared = Neighbours()
    other = np.random.default_rng(seed).random((30, 2))
    for _ in range(2):
        assert shared.pairs(xy, range_m).tolist() == [list(e) for e in expected]
        assert shared.pairs(xy, range_m * 0.5).tolist() == Neighbours().pairs(xy, range_m * 0.5).tolist()
        assert shared.pairs(other, range_m).tolist() == Neighbours().pairs(other, range_m).tolist()


@pytest.mark.parametrize("seed", range(24))
def test_every_pair_and_the_tree_propose_the_same_pairs(monkeypatch, seed):
    """Below ``TREE_FROM_ROBOTS`` every pair is a candidate, from it the k-d tree's: both
    ways give the same pairs in the same order, at random ranges and on lattices with pairs
    exactly at the range (teams of 2-200)."""
    from mjswarm.core import neighbours

    _, positions, range_m = random_team(seed)
    xy = np.array([p for p in positions.values() if np.isfinite(p).all()])
    answers = []
    for tree_from in (0, 10**9):
        monkeypatch.setattr(neighbours, "TREE_FROM_ROBOTS", tree_from)
        answers.append([Neighbours().pairs(xy, r).tolist() for r in (range_m, range_m * 0.37)])
    assert answers[0] == answers[1]
    assert answers[0][0]  # each of these teams holds pairs within its range: not vacuous


def separate_bearings(sim, fov_rad: float, range_m: float) -> tuple[np.ndarray, ...]:
    """The bearing sensor with a k-d tree and line of sight of its own, every pair's
    bearing wrapped in full (a reference without the shared search)."""
    poses = sim.poses()
    pairs = cKDTree(poses[:, :2]).query_pairs(range_m, output_type="ndarray")
    k = np.concatenate([pairs[:, 0], pairs[:, 1]])
    p = np.concatenate([pairs[:, 1], pairs[:, 0]])
    diff = poses[p, :2] - poses[k, :2]
    beta = np.arctan2(diff[:, 1], diff[:, 0]) - poses[k, 2]
    beta = np.arctan2(np.sin(beta), np.cos(beta))
    ahead = np.abs(beta) <= fov_rad
    k, p, beta = k[ahead], p[ahead], beta[ahead]
    seen = LineOfSight(sim)(k, p)
    order = np.lexsort((p[seen], k[seen]))
    return k[seen][order], p[seen][order], beta[seen][order]


def separate_links(sim, range_m: float) -> list:
    """The radio's links with a search and line of sight of its own."""
    sight = LineOfSight(sim)

    def blocked(pairs):
        i, j = pairs.T
        return ~(sight(i, j) & sight(j, i))

    radio = Radio(range(sim.n), range_m=range_m, blocked=blocked)
    radio.move(sim.poses()[:, :2])
    return sorted(radio.graph().edges)


@pytest.mark.parametrize("seed", range(6))
def test_the_shared_search_gives_bearings_and_links_as_separate_searches(seed):
    sim, _ = arena_sims(24)
    rng = np.random.default_rng(seed)
    fov = [math.pi, math.radians(60.0), math.radians(20.0)][seed % 3]
    bearing_range, radio_range = [(1.0, 1.0), (1.0, 0.4), (0.3, 0.8)][seed % 3]
    bearing = BearingSensor(sim, fov, bearing_range)
    radio = Radio(range(sim.n), range_m=radio_range, blocked=sight_blocker(sim),
                  neighbours=sim.neighbours)
    seen = links = 0
    for state in range(4):
        sim.set_state(*random_state(sim, rng, tipped=0.0))
        if state % 2:  # the bearing sensor asks first, then the radio
            got = bearing.read_pairs()
            radio.move(sim.poses()[:, :2])
        else:
            radio.move(sim.poses()[:, :2])
            got = bearing.read_pairs()
        want = separate_bearings(sim, fov, bearing_range)
        assert all(np.array_equal(a, b) for a, b in zip(got, want))
        assert sorted(radio.graph().edges) == separate_links(sim, radio_range)
        seen, links = seen + len(want[0]), links + radio.graph().number_of_edges()
    assert seen and links


@pytest.mark.parametrize("quick_from", [0, bearing_module.QUICK_WRAP_FROM])
@pytest.mark.parametrize("fov", [math.radians(60.0), math.pi / 2, math.pi])
def test_bearings_at_the_edge_of_the_field_of_view_are_kept_as_before(monkeypatch, fov, quick_from):
    """Robot 1 within a few ulps, and a micro-radian, of robot 0's field-of-view edges
    (and of +-pi): the quick wrap that skips far pairs drops none the reading keeps."""
    monkeypatch.setattr(bearing_module, "QUICK_WRAP_FROM", quick_from)
    sim = Simulation(world_spec([Pose2D(0.0, 0.0, 0.0), Pose2D(0.5, 0.0, 0.0)]))
    bearing = BearingSensor(sim, fov, 1.0)
    rng = np.random.default_rng(7)
    kept = 0
    for edge in (fov, -fov, math.pi, -math.pi):
        for offset in (-1e-6, -1e-15, 0.0, 1e-15, 1e-6):
            yaw = rng.uniform(-math.pi, math.pi)
            angle = yaw + edge + offset
            sim.place_robot(0, Pose2D(0.0, 0.0, yaw))
            sim.place_robot(1, Pose2D(0.5 * math.cos(angle), 0.5 * math.sin(angle), 0.0))
            got, want = bearing.read_pairs(), separate_bearings(sim, fov, 1.0)
            assert all(np.array_equal(a, b) for a, b in zip(got, want))
            kept += int((got[0] == 0).sum())
    assert kept
