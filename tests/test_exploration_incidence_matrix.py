"""The modified incidence matrix (Nagavarapu et al. section 2, Algorithms 1 and 2), beacon ids and
angle helpers, checked against brute force and networkx on many seeded random cases."""

from __future__ import annotations

import math

import networkx as nx
import numpy as np
import pytest
from exploration_graphs import planar_graph

from algorithms.exploration.base import (
    TWO_PI,
    AngleMismatch,
    ccw_from,
    match_angle,
    normalize_angle,
)
from algorithms.exploration.beacon_ids import beacon_id, robot_letters
from algorithms.exploration.incidence_matrix import (
    COMPLETED,
    EMPTY,
    OUT,
    UNEXPLORED,
    UNKNOWN,
    IncidenceMatrix,
    merge,
)
from mjswarm.worlds.graphworld import GraphWorld


def random_knowledge(world: GraphWorld, rng: np.random.Generator) -> IncidenceMatrix:
    """A matrix some robot could hold: random known vertices (tag = vertex id), random
    completed edges between them, random out ends (selected by robots a..d) among the rest."""
    vertices = [v for v in world.graph if rng.random() < 0.6] or [world.root]
    rows = {v: world.angles[v] for v in vertices}
    completed = {}
    for u, v in world.graph.edges:
        if u in rows and v in rows and rng.random() < 0.5:
            eu, ev = (u, world.angle_of[(u, v)]), (v, world.angle_of[(v, u)])
            completed[eu], completed[ev] = ev, eu
    ends = [(v, a) for v in rows for a in rows[v] if (v, a) not in completed]
    out = {e: frozenset(x for x in "abcd" if rng.random() < 0.5) | {"e"} for e in ends if rng.random() < 0.3}
    return IncidenceMatrix(rows, completed, out)


def all_ends(world: GraphWorld):
    return [(v, a) for v in world.graph for a in world.angles[v]]


def literal_algorithm_1_and_2(m1: IncidenceMatrix, m2: IncidenceMatrix) -> set[frozenset]:
    """Algorithm 1 on the dense matrices, pair by pair as printed, then the columns as sets
    of (vertex tag, entry). Independent of the sparse implementation."""
    tags1, cols1, d1 = m1.to_array()
    tags2, cols2, d2 = m2.to_array()
    columns = [{t: d1[i, j] for i, t in enumerate(tags1) if d1[i, j]} for j in range(len(cols1))]
    columns += [{t: d2[i, j] for i, t in enumerate(tags2) if d2[i, j]} for j in range(len(cols2))]
    n1 = len(cols1)
    deleted = set()
    for j1 in range(n1):
        for j2 in range(n1, len(columns)):
            if j1 in deleted or j2 in deleted:
                continue
            a, b = columns[j1], columns[j2]
            if not any(t in b and abs(x) == abs(b[t]) for t, x in a.items()):
                continue  # no common vertex with a common |theta|: not a common edge
            # differing signs become negative; the entries of the other vertex are copied
            merged = {
                t: -abs(x) if a.get(t, 1) < 0 or b.get(t, 1) < 0 else x
                for t, x in {**a, **b}.items()
            }
            keep, drop = (j2, j1) if len(b) == 2 or len(a) < 2 else (j1, j2)
            columns[keep] = merged
            deleted.add(drop)
    return {frozenset(c.items()) for j, c in enumerate(columns) if j not in deleted}


def columns_of(m: IncidenceMatrix) -> set[frozenset]:
    tags, cols, dense = m.to_array()
    return {frozenset((t, dense[i, j]) for i, t in enumerate(tags) if dense[i, j]) for j in range(len(cols))}


@pytest.mark.parametrize("seed", range(40))
def test_merge_is_the_status_join_and_matches_literal_algorithm_1(seed):
    g, root = planar_graph(seed)
    world = GraphWorld(g, root)
    rng = np.random.default_rng(seed)
    a, b, c = (random_knowledge(world, rng) for _ in range(3))
    ab = merge(a, b)
    for e in all_ends(world):
        assert ab.status(e) == max(a.status(e), b.status(e)), e
        if ab.status(e) == OUT:
            assert ab.out[e] == a.out.get(e, frozenset()) | b.out.get(e, frozenset())
    assert ab.rows.keys() == a.rows.keys() | b.rows.keys()
    assert columns_of(ab) == literal_algorithm_1_and_2(a, b)
    # a join: commutative, associative, idempotent, EMPTY is the identity
    ba, abc, a_bc = merge(b, a), merge(ab, c), merge(a, merge(b, c))
    assert ab.out == ba.out and abc.out == a_bc.out
    for e in all_ends(world):
        assert ab.status(e) == ba.status(e)
        assert abc.status(e) == a_bc.status(e)
    assert merge(a, a) is a and merge(a, EMPTY) is a and merge(EMPTY, a) is a
    assert merge(ab, a) is ab  # an operand that contains the other is returned as is


@pytest.mark.parametrize("seed", range(20))
def test_order_blocks_signs_and_theorem_1(seed):
    g, root = planar_graph(seed)
    world = GraphWorld(g, root)
    m = random_knowledge(world, np.random.default_rng(seed))
    _, columns, dense = m.to_array()
    kinds = [
        COMPLETED if len(c) == 2 else m.status(c[0]) for c in columns
    ]
    assert kinds == sorted(kinds, reverse=True)  # Algorithm 2: completed | out | unexplored
    for j, kind in enumerate(kinds):
        nonzero = dense[:, j][dense[:, j] != 0]
        assert len(nonzero) == (2 if kind == COMPLETED else 1)
        assert (nonzero < 0).all() if kind in (COMPLETED, OUT) else (nonzero > 0).all()
        assert all(0 < abs(x) <= TWO_PI for x in nonzero)
    # Theorem 1 / Remark 5: complete iff the rightmost column is a completed one
    assert m.is_complete() == (kinds[-1] == COMPLETED)
    assert len(m.unexplored()) == kinds.count(UNEXPLORED)


def test_complete_knowledge_is_v_by_e_proposition_1():
    g, root = planar_graph(3)
    world = GraphWorld(g, root)
    matrices = [EMPTY]
    for u, v in g.edges:
        eu, ev = (u, world.angle_of[(u, v)]), (v, world.angle_of[(v, u)])
        matrices.append(merge(matrices[-1], IncidenceMatrix.edge(eu, world.angles[u], ev, world.angles[v])))
    m, almost = matrices[-1], matrices[-2]
    assert m.is_complete()
    assert m.to_array()[2].shape == (g.number_of_nodes(), g.number_of_edges())
    assert not almost.is_complete() and len(almost.order()[-1]) == 1


@pytest.mark.parametrize("seed", range(20))
def test_route_and_distances_agree_with_networkx(seed):
    g, root = planar_graph(seed)
    world = GraphWorld(g, root)
    m = random_knowledge(world, np.random.default_rng(seed))
    gc = nx.Graph()
    gc.add_nodes_from(m.rows)
    gc.add_edges_from((e[0], f[0]) for e, f in m.completed_edges())
    source = next(iter(m.rows))
    expected = nx.single_source_shortest_path_length(gc, source)
    assert m.distances(source) == expected
    for target, d in expected.items():
        path = m.route(source, target)
        assert len(path) == d
        at = source
        for tag, angle in path:
            assert tag == at and m.status((tag, angle)) == COMPLETED
            at = m.completed[(tag, angle)][0]
        assert at == target
    unreachable = set(m.rows) - set(expected)
    if unreachable:
        with pytest.raises(ValueError):
            m.route(source, min(unreachable))


def test_status_and_select():
    m = IncidenceMatrix.initial("a1", (math.pi, TWO_PI))
    assert m.status(("a1", math.pi)) == UNEXPLORED and m.status(("b1", 1.0)) == UNKNOWN
    out = m.select(("a1", math.pi), "a")  # eq. (5): the selected column is negated
    assert out.status(("a1", math.pi)) == OUT and m.status(("a1", math.pi)) == UNEXPLORED
    assert out.out == {("a1", math.pi): {"a"}} and out.unexplored_at("a1") == [TWO_PI]
    again = out.select(("a1", math.pi), "b")  # another robot selects the out edge
    assert again.out == {("a1", math.pi): {"a", "b"}} and out.out == {("a1", math.pi): {"a"}}
    assert again.select(("a1", math.pi), "b") is again
    # robots a and c selected it concurrently: the merge knows both
    both = merge(out, m.select(("a1", math.pi), "c"))
    assert both.out == {("a1", math.pi): {"a", "c"}}
    done = merge(again, IncidenceMatrix.edge(("a1", math.pi), (math.pi, TWO_PI), ("b1", 1.0), (1.0,)))
    assert done.out == {} and done.select(("a1", math.pi), "c") is done


def test_selectors_angles_and_numberings():
    e = ("a1", math.pi)
    m = IncidenceMatrix.initial("a1", (math.pi, TWO_PI)).select(e, "a").select(e, "b")
    assert m.selectors(e) == {"a", "b"} and m.selectors(("a1", TWO_PI)) == frozenset()
    assert m.angles("a1") == (math.pi, TWO_PI)
    with pytest.raises(KeyError):
        m.angles("b1")
    # matrices written in one numbering merge as they are; others are renumbered first
    column = IncidenceMatrix.edge(e, (math.pi, TWO_PI), ("b1", 1.0), (1.0,), m.numbering)
    alone = IncidenceMatrix.edge(e, (math.pi, TWO_PI), ("b1", 1.0), (1.0,))
    assert merge(m, column).numbering is m.numbering is column.numbering
    assert alone.numbering is not m.numbering
    assert merge(m, alone).completed == merge(m, column).completed == {e: ("b1", 1.0),
                                                                       ("b1", 1.0): e}
    assert merge(m, column).out == {} and merge(m, column).selectors(e) == frozenset()
    with pytest.raises(ValueError):  # a tag names one vertex, with one row
        IncidenceMatrix.initial("a1", (1.0,), m.numbering)


def test_an_end_completed_towards_two_ends():
    """A beacon wiped and dropped again gives its vertex a second tag, so an edge end can
    be completed towards both names. A merge keeps the other end known to the operand with
    fewer completed ends, and takes a one-edge matrix as known when the other operand knows
    its rows and its first end as completed (as the dictionary union did; the wiped-beacon
    fault run depends on it)."""
    x, old, new, y = ("x1", 1.0), ("a1", 2.0), ("a2", 2.0), ("y1", 3.0)
    a1 = (2.0, 4.0)
    a = IncidenceMatrix.edge(x, (1.0,), old, a1)
    a = merge(a, IncidenceMatrix.edge(("a1", 4.0), a1, y, (3.0,), a.numbering))
    b = IncidenceMatrix.edge(x, (1.0,), new, (2.0,), a.numbering)
    m = merge(a, b)
    assert m.completed[x] == new and m.completed[old] == x and merge(b, a).completed == m.completed
    assert m.distances("x1") == {"x1": 0, "a2": 1}
    assert m.distances("a1") == {"a1": 0, "x1": 1, "y1": 1, "a2": 2}
    known = merge(a, IncidenceMatrix.initial("a2", (2.0,), a.numbering))
    assert merge(known, b) is known and known.completed[x] == old


def test_beacon_ids_follow_the_paper_and_continue_past_26_robots():
    assert [beacon_id(0, 1), beacon_id(0, 2), beacon_id(1, 1)] == ["a1", "a2", "b1"]
    assert [robot_letters(i) for i in (0, 25, 26, 27, 51, 52, 701, 702)] == [
        "a", "z", "aa", "ab", "az", "ba", "zz", "aaa"
    ]
    names = {beacon_id(i, s) for i in range(800) for s in (1, 7, 12)}
    assert len(names) == 2400  # letters then digits: no two robots' beacons share a name
    with pytest.raises(ValueError):
        beacon_id(-1, 1)
    with pytest.raises(ValueError):
        beacon_id(0, 0)  # sequence numbers start at 1


def test_angle_helpers():
    assert normalize_angle(0.0) == TWO_PI and normalize_angle(TWO_PI) == TWO_PI
    assert normalize_angle(-math.pi / 2) == pytest.approx(3 * math.pi / 2)
    # counter-clockwise from the arrival edge, the arrival direction itself last
    assert ccw_from(math.pi, [math.pi / 2, math.pi, TWO_PI, 3 * math.pi / 2]) == [
        3 * math.pi / 2, TWO_PI, math.pi / 2, math.pi
    ]
    assert ccw_from(TWO_PI, [TWO_PI, 3 * math.pi / 2]) == [3 * math.pi / 2, TWO_PI]
    stored = (math.pi / 2, math.pi, TWO_PI)
    assert match_angle(math.radians(350), stored) == TWO_PI
    assert match_angle(math.radians(105), stored) == math.pi / 2
    with pytest.raises(AngleMismatch):
        match_angle(math.radians(135), stored)
