"""The radio: range, one-tick latency, drops, counters, line of sight, explicit edges."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from mjswarm.errors import MjswarmError
from mjswarm.radio import Radio, walls_blocker


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
    assert touching("a", "b")
    assert not parallel("a", "b")
    assert not collinear_apart("a", "b")


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

    for i, j in itertools.combinations(positions, 2):
        expected = any(crosses(positions[i], positions[j], c, d) for c, d in walls)
        assert blocked(i, j) == expected


def test_blocker_is_asked_only_for_pairs_in_range():
    asked = []

    def blocked(i, j):
        asked.append(frozenset((i, j)))
        return frozenset((i, j)) == {"r0", "r1"}

    radio = line_radio([0.0, 0.5, 0.9, 5.0], blocked=blocked)
    assert set(asked) == {frozenset(p) for p in [("r0", "r1"), ("r0", "r2"), ("r1", "r2")]}
    assert radio.neighbors("r0") == {"r2"}


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
