"""The radio: range, one-tick latency, drops, counters, line of sight, explicit edges."""

from __future__ import annotations

import itertools
import math
from fractions import Fraction

import numpy as np
import pytest
from scipy.spatial import cKDTree

from mjswarm.errors import MjswarmError
from mjswarm.core.radio import Radio, walls_blocker


def line_radio(xs, range_m=1.0, **options) -> Radio:
    radio = Radio([f"r{i}" for i in range(len(xs))], range_m=range_m, **options)
    radio.move({f"r{i}": (x, 0.0) for i, x in enumerate(xs)})
    return radio


def test_range_is_inclusive_and_symmetric():
    radio = line_radio([0.0, 1.0, 2.0000001, 2.5])
    assert radio.neighbors("r0") == {"r1"}
    assert radio.neighbors("r1") == {"r0"}
    assert radio.neighbors("r2") == {"r3"}
    assert radio.neighbors("r3") == {"r2"}


@pytest.mark.parametrize("seed", range(20))
def test_links_match_brute_force_distances(seed):
    rng = np.random.default_rng(seed)
    n, range_m = int(rng.integers(2, 25)), float(rng.uniform(0.1, 0.6))
    xy = rng.random((n, 2))
    radio = Radio(range(n), range_m=range_m)
    radio.move(dict(enumerate(xy)))
    expected = {
        frozenset((i, j))
        for i, j in itertools.combinations(range(n), 2)
        if math.dist(xy[i], xy[j]) <= range_m
    }
    assert {frozenset(e) for e in radio.graph().edges} == expected



def random_team(seed):
    """Robot ids in a shuffled radio order, positions (m) and a range d_c (m).

    Odd seeds put the robots on a lattice of pitch d_c/k: with a dyadic d_c (seed % 4 == 1)
    many pairs are exactly d_c apart on an axis, the first two robots always; with d_c = 0.3
    or 0.7 the lattice distances round either side of d_c. Every fifth seed gives two
    robots a non-finite coordinate.
    """
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 201))
    ids = rng.permutation(n).tolist()
    if seed % 4 == 1:
        range_m = float(rng.choice([0.25, 0.5, 1.0, 1.5]))
    else:
        range_m = float(rng.choice([0.3, 0.7, rng.uniform(0.05, 2.0)]))
    if seed % 2:
        xy = rng.integers(0, 12, (n, 2)) * (range_m / int(rng.choice([1, 2, 4])))
        xy[1] = xy[0] + (range_m, 0.0)
    else:
        xy = rng.random((n, 2)) * rng.uniform(1.0, 10.0)
    if seed % 5 == 0:
        xy[rng.integers(2, n, 2) if n > 2 else 0] = [np.inf, np.nan][seed % 2]
    return ids, dict(zip(ids, xy)), range_m


def brute_force_links(positions, range_m, blocked=lambda i, j: False):
    """O(N^2): the documented link rule, sum((p_i - p_j)**2) <= d_c**2, per pair."""
    with np.errstate(invalid="ignore"):
        return {
            frozenset((i, j))
            for i, j in itertools.combinations(positions, 2)
            if ((positions[i] - positions[j]) ** 2).sum() <= range_m**2 and not blocked(i, j)
        }


@pytest.mark.parametrize("seed", range(60))
def test_links_match_brute_force_with_boundaries_and_a_blocker(seed):
    ids, positions, range_m = random_team(seed)
    plain = Radio(ids, range_m=range_m)
    plain.move(positions)
    expected = brute_force_links(positions, range_m)
    assert {frozenset(e) for e in plain.graph().edges} == expected
    if seed % 4 == 1:  # exactly d_c apart on an axis: linked (inclusive range)
        assert math.dist(positions[ids[0]], positions[ids[1]]) == range_m
        assert ids[1] in plain.neighbors(ids[0])

    def odd(pairs):  # by robot ids, so it depends on which pairs it is asked about
        return np.array([(i + j) % 2 == 1 for i, j in pairs], dtype=bool)

    cut = Radio(ids, range_m=range_m, blocked=odd)
    cut.move(positions)
    expected_cut = brute_force_links(positions, range_m, lambda i, j: (i + j) % 2 == 1)
    assert {frozenset(e) for e in cut.graph().edges} == expected_cut
    assert all(cut.neighbors(r) == {x for e in expected_cut if r in e for x in e} - {r}
               for r in ids)



def test_links_do_not_depend_on_the_k_d_trees_rounding(monkeypatch):
    """The tree only proposes pairs; the exact squared-distance rule decides at d_c."""
    class ShortTree(cKDTree):  # a tree whose own comparison loses pairs exactly at r
        def query_pairs(self, r, *args, **kwargs):
            return super().query_pairs(r * (1 - 1e-12), *args, **kwargs)

    monkeypatch.setattr("scipy.spatial.cKDTree", ShortTree)  # imported when first used
    for seed in range(1, 40, 4):  # the dyadic lattices of random_team
        ids, positions, range_m = random_team(seed)
        radio = Radio(ids, range_m=range_m)
        radio.move(positions)
        assert {frozenset(e) for e in radio.graph().edges} == brute_force_links(
            positions, range_m
        )


@pytest.mark.parametrize("seed", range(20))
def test_broadcast_recipients_are_in_radio_order(seed):
    """Drops are drawn per copy in the radio's robot order (not id or insertion order)."""
    ids, positions, range_m = random_team(seed)
    drop_prob = 0.5
    radio = Radio(ids, range_m=range_m, drop_prob=drop_prob, rng=seed)
    radio.step(positions)
    sender = max(ids, key=lambda r: len(radio.neighbors(r)))
    radio.send(sender, "x")
    radio.step()
    got = {r for r in ids if radio.receive(r)}
    reference = np.random.default_rng(seed)
    in_order = [r for r in ids if r in radio.neighbors(sender)]
    assert got == {r for r in in_order if not reference.random() < drop_prob}


def test_delivery_after_exactly_one_tick():
    radio = line_radio([0.0, 0.5, 0.9])
    radio.step()
    radio.send("r0", "hello")
    assert radio.receive("r1") == []  # not before the next tick
    radio.step()
    got = radio.receive("r1")
    assert [(m.sender, m.payload) for m in got] == [("r0", "hello")]
    assert [m.payload for m in radio.receive("r2")] == ["hello"]
    assert radio.receive("r0") == []  # no echo to the sender
    radio.step()
    assert radio.receive("r1") == []  # delivered once


def test_undrained_inbox_keeps_messages_in_order():
    radio = line_radio([0.0, 0.5])
    for k in range(3):
        radio.step()
        radio.send("r0", k)
    radio.step()
    assert [m.payload for m in radio.receive("r1")] == [0, 1, 2]


def test_addressed_send_reaches_only_the_addressee_if_in_range():
    radio = line_radio([0.0, 0.5, 0.9, 5.0])
    radio.step()
    radio.send("r0", "to r2", to="r2")
    radio.send("r0", "to r3", to="r3")  # out of range: lost, but still transmitted
    radio.step()
    assert [m.payload for m in radio.receive("r2")] == ["to r2"]
    assert radio.receive("r1") == [] and radio.receive("r3") == []
    assert radio.sent["r0"] == 2 and radio.total_sent == 2


def test_counters_count_transmissions_and_copies():
    radio = line_radio([0.0, 0.5, 0.9, 1.4])  # r0-r1-r2 all within 1 m, r3 hears r1, r2
    radio.step()
    radio.send("r0", "a")
    radio.send("r1", "b")
    radio.send("r1", "c")
    radio.step()
    assert radio.sent == {"r0": 1, "r1": 2, "r2": 0, "r3": 0}
    assert radio.received == {"r0": 2, "r1": 1, "r2": 3, "r3": 2}
    assert radio.pending == 0


def test_recipients_are_fixed_when_sent():
    radio = line_radio([0.0, 0.5])
    radio.step()
    radio.send("r0", "x")
    radio.step({"r0": (0.0, 0.0), "r1": (9.0, 0.0)})  # moved away after the send
    assert [m.payload for m in radio.receive("r1")] == ["x"]
    radio.send("r0", "y")
    radio.step()
    assert radio.receive("r1") == []


def drop_pattern(seed, drop_prob=0.3, copies=2000):
    radio = line_radio([0.0, 0.1], drop_prob=drop_prob, rng=seed)
    radio.step()
    for k in range(copies):
        radio.send("r0", k)
    radio.step()
    return [m.payload for m in radio.receive("r1")], radio


def test_drops_are_seeded_and_at_the_requested_rate():
    got_a, radio = drop_pattern(7)
    got_b, _ = drop_pattern(7)
    got_c, _ = drop_pattern(8)
    assert got_a == got_b
    assert got_a != got_c
    assert radio.dropped + radio.received["r1"] == 2000
    # binomial(2000, 0.3): mean 600, sd 20.5; 5 sd either side
    assert 600 - 103 < radio.dropped < 600 + 103
    assert drop_pattern(7, drop_prob=0.0)[1].dropped == 0


def test_walls_block_line_of_sight():
    positions = {"a": (0.0, 0.0), "b": (1.0, 0.0), "c": (0.0, 1.0), "d": (2.0, 0.0)}
    walls = [((0.5, -1.0), (0.5, 0.2))]  # vertical wall between a and b
    radio = Radio(positions, range_m=3.0, blocked=walls_blocker(walls, positions))
    radio.move(positions)
    assert "b" not in radio.neighbors("a") and "d" not in radio.neighbors("a")
    assert radio.neighbors("a") == {"c"}
    assert radio.neighbors("b") == {"c", "d"}  # c-b passes above the wall's end (y = 0.5)


def test_wall_touching_a_link_blocks_it_and_parallel_walls_do_not():
    positions = {"a": (0.0, 0.0), "b": (1.0, 0.0)}
    touching = walls_blocker([((0.5, 0.0), (0.5, 1.0))], positions)
    parallel = walls_blocker([((0.0, 0.1), (1.0, 0.1))], positions)
    collinear_apart = walls_blocker([((2.0, 0.0), (3.0, 0.0))], positions)
    assert touching([("a", "b")]).tolist() == [True]
    assert parallel([("a", "b")]).tolist() == [False]
    assert collinear_apart([("a", "b")]).tolist() == [False]


@pytest.mark.parametrize("seed", range(10))
def test_walls_blocker_matches_parametric_intersection(seed):
    rng = np.random.default_rng(seed)
    positions = {i: tuple(p) for i, p in enumerate(rng.random((8, 2)))}
    walls = [tuple(map(tuple, rng.random((2, 2)))) for _ in range(4)]
    blocked = walls_blocker(walls, positions)

    def crosses(p, q, c, d):  # solve p + t (q - p) = c + s (d - c), generic position
        m = np.array([[q[0] - p[0], c[0] - d[0]], [q[1] - p[1], c[1] - d[1]]])
        t, s = np.linalg.solve(m, np.subtract(c, p))
        return 0 <= t <= 1 and 0 <= s <= 1

    pairs = list(itertools.combinations(positions, 2))
    expected = [any(crosses(positions[i], positions[j], c, d) for c, d in walls) for i, j in pairs]
    assert blocked(pairs).tolist() == expected



def segments_meet(p, q, c, d):
    """Scalar brute force in exact rationals: do closed segments p-q and c-d share a point?"""
    p, q, c, d = (tuple(map(Fraction, x)) for x in (p, q, c, d))

    def sub(u, v):
        return (u[0] - v[0], u[1] - v[1])

    def cross(u, v):
        return u[0] * v[1] - u[1] * v[0]

    r, s = sub(q, p), sub(d, c)
    det = cross(r, s)
    if det:  # one crossing point of the two lines: on both segments?
        t, u = cross(sub(c, p), s) / det, cross(sub(c, p), r) / det
        return 0 <= t <= 1 and 0 <= u <= 1
    if r == (0, 0) and s == (0, 0):
        return p == c
    axis = r if r != (0, 0) else s  # parallel or degenerate: meet only if all collinear
    base = p if r != (0, 0) else c
    if any(cross(axis, sub(x, base)) for x in (p, q, c, d)):
        return False

    def along(x):
        return x[0] * axis[0] + x[1] * axis[1]

    lo1, hi1 = sorted((along(p), along(q)))
    lo2, hi2 = sorted((along(c), along(d)))
    return max(lo1, lo2) <= min(hi1, hi2)


@pytest.mark.parametrize("seed", range(40))
def test_walls_blocker_matches_scalar_brute_force_including_touching(seed):
    """Integer lattice coordinates make touching, collinear and degenerate cases common."""
    rng = np.random.default_rng(seed)
    grid = int(rng.integers(3, 7))
    positions = {i: tuple(p) for i, p in enumerate(rng.integers(0, grid, (10, 2)).astype(float))}
    walls = [tuple(map(tuple, rng.integers(0, grid, (2, 2)).astype(float)))
             for _ in range(int(rng.integers(1, 6)))]
    pairs = [tuple(rng.permutation(p).tolist())
             for p in itertools.combinations(positions, 2)]
    expected = [any(segments_meet(positions[i], positions[j], c, d) for c, d in walls)
                for i, j in pairs]
    assert walls_blocker(walls, positions)(pairs).tolist() == expected


def test_walls_blocker_without_walls_or_pairs():
    positions = {"a": (0.0, 0.0), "b": (1.0, 0.0)}
    assert walls_blocker([], positions)([("a", "b")]).tolist() == [False]
    assert walls_blocker([((0.5, -1.0), (0.5, 1.0))], positions)([]).shape == (0,)


def test_blocker_is_asked_once_for_all_pairs_in_range_and_never_without_any():
    asked = []

    def blocked(pairs):
        asked.append([tuple(p) for p in pairs])
        return np.array([{i, j} == {"r0", "r1"} for i, j in pairs])

    radio = line_radio([0.0, 0.5, 0.9, 5.0], blocked=blocked)
    assert asked == [[("r0", "r1"), ("r0", "r2"), ("r1", "r2")]]  # one call, robot order
    assert radio.neighbors("r0") == {"r2"}
    radio.move({"r0": (0.0, 0.0), "r1": (2.0, 0.0), "r2": (4.0, 0.0), "r3": (6.0, 0.0)})
    assert len(asked) == 1  # no pair in range: not called
    assert radio.graph().number_of_edges() == 0


def test_a_blocker_answering_the_wrong_shape_is_an_error():
    with pytest.raises(MjswarmError, match="blocker returned shape"):
        line_radio([0.0, 0.5, 0.9], blocked=lambda pairs: np.array(False))


def test_explicit_edges_and_removal():
    radio = Radio("abcd", edges=[("a", "b"), ("b", "c"), ("c", "d")])
    assert radio.neighbors("b") == {"a", "c"}
    radio.step()
    radio.send("b", "to all")
    radio.send("d", "from d")
    radio.remove("c")
    radio.step()
    assert [m.payload for m in radio.receive("a")] == ["to all"]
    assert radio.receive("c") == []
    assert radio.neighbors("b") == {"a"} and radio.neighbors("d") == frozenset()
    assert radio.present == ("a", "b", "d")
    radio.set_edges([("a", "d"), ("d", "c")])  # c has left: its links stay down
    assert radio.neighbors("d") == {"a"}
    assert set(radio.graph().nodes) == {"a", "b", "d"}
    with pytest.raises(MjswarmError, match="not in the team"):
        radio.send("c", "ghost")


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"range_m": 0.0}, "positive"),
        ({"range_m": -1.0}, "positive"),
        ({"range_m": float("nan")}, "positive"),
        ({}, "exactly one"),
        ({"range_m": 1.0, "edges": []}, "exactly one"),
        ({"range_m": 1.0, "drop_prob": 1.0}, "drop probability"),
        ({"edges": [("a", "z")]}, "unknown robot"),
    ],
)
def test_bad_parameters_are_one_line_errors(kwargs, words):
    with pytest.raises(MjswarmError, match=words):
        Radio("ab", **kwargs)


def test_misuse_errors():
    with pytest.raises(MjswarmError, match="duplicate"):
        Radio("aa", range_m=1.0)
    with pytest.raises(MjswarmError, match="no position"):
        Radio("ab", range_m=1.0).step({"a": (0, 0)})
    with pytest.raises(MjswarmError, match="needs positions"):
        Radio("ab", range_m=1.0).step()
    with pytest.raises(MjswarmError, match="explicit-edge mode"):
        Radio("ab", edges=[]).move({"a": (0, 0), "b": (0, 0)})
    with pytest.raises(MjswarmError, match="explicit edges"):
        Radio("ab", range_m=1.0).set_edges([])


def test_removing_the_last_robot_leaves_an_empty_radio():
    radio = Radio(["a", "b"], range_m=1.0)
    radio.step({"a": (0, 0), "b": (0.5, 0)})
    radio.remove("a")
    radio.remove("b")
    assert radio.present == () and radio.graph().number_of_nodes() == 0


def test_a_repeated_broadcast_is_checked_again_after_a_robot_leaves():
    """``send_all`` reuses the messages of a heartbeat sent again by the same senders; a
    robot removed in between is refused as on the first send, and counts stay per send."""
    radio = Radio(["a", "b", "c"], range_m=1.0)
    radio.move({"a": (0.0, 0.0), "b": (0.5, 0.0), "c": (0.9, 0.0)})
    beat = ("beat",)
    for _ in range(2):
        radio.send_all(["a", "b", "c"], beat)
        radio.step()
    assert radio.sent == {"a": 2, "b": 2, "c": 2}
    assert [m.sender for m in radio.receive("b")] == ["a", "c", "a", "c"]
    radio.remove("c")
    with pytest.raises(MjswarmError, match="not in the team"):
        radio.send_all(["a", "b", "c"], beat)
