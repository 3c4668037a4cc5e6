"""Ahmadi & Stone's stamped-message biconnectivity check (Ahmadi & Stone), against networkx."""

from __future__ import annotations

import itertools

import networkx as nx
import numpy as np
import pytest

from algorithms.connectivity import BiconnectivityCheck, dcr_members, stamp_relay
from mjswarm.experiments.connectivity import Team, drive, run_check
from mjswarm.experiments.connectivity.comparison import geometric_range, random_team, ring_team


def edge_team(edges, nodes=()) -> Team:
    ids = list(dict.fromkeys([*nodes, *itertools.chain.from_iterable(edges)]))
    return Team(positions={r: (0.0, 0.0) for r in ids}, edges=tuple(edges))


def truth(graph):
    return nx.is_connected(graph), nx.is_biconnected(graph)


def test_algorithm1_stamps_or_stops():
    assert stamp_relay(("a", "b"), "c") == ("a", "b", "c")
    assert stamp_relay(("a", "b"), "a") is None
    assert stamp_relay(("a", "b"), "b") is None


def test_algorithm2_takes_s2_only_when_a_loop_closes():
    assert dcr_members(("x", "r", "a", "b"), "r") == ("a", "b")
    assert dcr_members(("r", "a", "b", "c"), "r") == ("a", "b", "c")
    assert dcr_members(("r", "a"), "r") == ()  # straight back from a neighbour
    assert dcr_members(("x", "y"), "r") == ()  # not stamped by r


def check_cases(make, count):
    """Run stamps on ``count`` seeded teams; compare with networkx; tally the kinds."""
    kinds = {"capped": 0, "biconnected": 0, "connected only": 0, "disconnected": 0}
    for k in range(count):
        rng = np.random.default_rng(k)
        n = 3 + k % 28
        team, range_m = make(n, rng, k)
        graph = team.graph(range_m)
        result = run_check(team, "stamps", range_m=range_m, message_cap=20_000)
        if result.capped:
            kinds["capped"] += 1
            assert result.connected is None and result.biconnected is None
            continue
        assert (result.connected, result.biconnected) == truth(graph), (k, n, range_m)
        assert result.articulation_points is None
        connected, biconnected = truth(graph)
        kind = "biconnected" if biconnected else "connected only" if connected else "disconnected"
        kinds[kind] += 1
    return kinds


def test_verdicts_match_networkx_on_300_uniform_geometric_teams():
    degrees = (1.5, 2.5, 3.5, 5.0)  # ranges: several mean degrees per team size

    def make(n, rng, k):
        return random_team(n, rng), geometric_range(n, degrees[k % len(degrees)])

    kinds = check_cases(make, 300)
    assert kinds["capped"] <= 70
    assert min(kinds["biconnected"], kinds["connected only"], kinds["disconnected"]) >= 10


def test_verdicts_match_networkx_on_300_ring_teams():
    factors = (1.0, 1.3, 1.6)

    def make(n, rng, k):
        return ring_team(n, rng, spacing_factor=factors[k % len(factors)])

    kinds = check_cases(make, 300)
    assert kinds["capped"] == 0
    assert kinds["biconnected"] >= 80 and kinds["connected only"] >= 20


def blocks_of_three_or_more(graph, robot):
    """Robots doubly connected to ``robot``: sharing a biconnected component of size >= 3."""
    return {
        v for c in nx.biconnected_components(graph) if robot in c and len(c) >= 3 for v in c
    } - {robot}


@pytest.mark.parametrize("seed", range(40))
def test_cr_and_dcr_lists_of_the_initiator_and_its_neighbours(seed):
    rng = np.random.default_rng(1000 + seed)
    n = int(rng.integers(3, 11))
    team = random_team(n, rng)
    range_m = geometric_range(n, 3.0)
    graph = team.graph(range_m)
    ids = team.ids
    nodes = {r: BiconnectivityCheck(r, n, initiator=r == ids[0]) for r in ids}
    radio = team.radio(range_m)
    drive(radio, nodes, lambda _: nodes[ids[0]].result is not None)
    running = [r for r, node in nodes.items() if node.started_at is not None]
    assert ids[0] in running
    for r in running:
        node = nodes[r]
        assert node.result is not None  # neighbours decide at 6N + 1, the initiator after
        assert node.cr == nx.node_connected_component(graph, r) - {r}
        assert node.dcr == blocks_of_three_or_more(graph, r)


def figure1():
    """Ahmadi & Stone Figure 1 (drawn from its caption): v joins two loops, v is a cut robot."""
    return edge_team([("v", "a"), ("a", "b"), ("b", "v"), ("v", "c"), ("c", "d"), ("d", "v")])


def test_figure1_v_is_doubly_connected_to_all_but_not_biconnected():
    team = figure1()
    nodes = {r: BiconnectivityCheck(r, 5, initiator=r == "v") for r in team.ids}
    drive(team.radio(), nodes, lambda _: nodes["v"].result is not None)
    v = nodes["v"]
    assert v.cr == v.dcr == {"a", "b", "c", "d"}  # |DCR_v| = |CR_v|: v says DC-TRUE
    assert v.result is False  # but its neighbours say DC-FALSE
    assert all(nodes[r].result is False for r in "abcd")


@pytest.mark.parametrize("max_robots", [None, 12])
def test_decision_times_are_6Nc_plus_2c_and_3Nc(max_robots):
    cycle = edge_team([("a", "b"), ("b", "c"), ("c", "d"), ("d", "a")])
    path = edge_team([("a", "b"), ("b", "c"), ("c", "d")])
    big_n = max_robots or 4
    result = run_check(cycle, "stamps", max_robots=max_robots)
    assert result.biconnected is True and result.rounds == 6 * big_n + 2
    result = run_check(path, "stamps", max_robots=max_robots)  # a is not doubly connected
    assert result.biconnected is False and result.rounds == 3 * big_n


def simple_paths_from(graph, v):
    """Simple paths starting at v, the one-robot path included (brute force)."""
    return 1 + sum(
        len(list(nx.all_simple_paths(graph, v, t))) for t in graph if t != v
    )


@pytest.mark.parametrize("seed", range(25))
def test_message_count_is_one_per_simple_path_plus_the_check(seed):
    rng = np.random.default_rng(2000 + seed)
    n = int(rng.integers(3, 9))
    team = random_team(n, rng)
    range_m = geometric_range(n, 3.0)
    graph = team.graph(range_m)
    leader = team.ids[0]
    component = graph.subgraph(nx.node_connected_component(graph, leader))
    cr = sum(simple_paths_from(component, v) for v in component)
    leader_ok = blocks_of_three_or_more(graph, leader) == set(component) - {leader}
    dcr_origins = [leader, *graph[leader]] if leader_ok else [leader]
    dcr = sum(simple_paths_from(component, o) for o in dcr_origins)
    control = 1 + (1 + len(graph[leader]) if leader_ok else 1)  # CHECK-REQUEST, DC-*
    result = run_check(team, "stamps", range_m=range_m)
    assert result.messages == cr + dcr + control


def test_dense_team_is_capped_with_unknown_verdicts():
    team = Team(positions={f"r{i}": (0.0, 0.01 * i) for i in range(12)})  # complete K12
    result = run_check(team, "stamps", range_m=1.0, message_cap=5_000)
    assert result.capped
    assert (result.connected, result.biconnected, result.articulation_points) == (None,) * 3
    assert 5_000 < result.messages < 5_000 + 12 * 5_000  # stops within one robot's burst
    assert result.rounds < 3 * 12


def test_two_robots_follow_the_paper_not_networkx():
    # one link is one path, not two internally disjoint ones (Definition 3)
    result = run_check(edge_team([("a", "b")]), "stamps")
    assert result.connected is True and result.biconnected is False


def test_single_robot_and_isolated_initiator():
    alone = Team(positions={"a": (0.0, 0.0)})
    result = run_check(alone, "stamps", range_m=1.0)
    assert (result.connected, result.biconnected) == (True, False)
    apart = Team(positions={"a": (0.0, 0.0), "b": (5.0, 0.0), "c": (5.5, 0.0)})
    result = run_check(apart, "stamps", range_m=1.0)
    assert (result.connected, result.biconnected) == (False, False)


def test_a_non_initiator_waits_for_the_check_request():
    node = BiconnectivityCheck("b", 3)
    assert node.tick(0, [], ()) == []
    assert node.started_at is None and node.result is None


def test_n_below_team_size_is_refused():
    with pytest.raises(ValueError):
        BiconnectivityCheck("a", 5, max_robots=4)
