"""Vertex entry (algorithms.exploration.entry, run by mjswarm.experiments.stations): holds,
first-come grants, and no circular wait."""

from __future__ import annotations

import math

import networkx as nx
import numpy as np
import pytest

from algorithms.exploration.entry import (EntryBusy, EntryGranted, EntryRequest, GiveUp,
                                          LeftVertex, TurnedBack, VertexClear, VertexStations,
                                          Withdraw)
from mjswarm.arena import incidence_angle, load_arena
from mjswarm.arena.geometry import vertex_fans
from mjswarm.experiments.exploration import EmbodiedConfig, EmbodiedExploration
from mjswarm.experiments.minds import make_minds


@pytest.fixture
def lattice():
    return VertexStations(vertex_fans(load_arena("lattice:3x3")))


def test_edge_towards_names_the_neighbour_along_an_angle(lattice):
    assert lattice.edge_towards("v1_1", 0.0) == ("v1_2", 0.0)
    neighbour, off = lattice.edge_towards("v1_1", math.radians(95.0))
    assert neighbour == "v2_1" and math.isclose(off, math.radians(5.0))


def test_a_free_vertex_is_granted_and_held(lattice):
    lattice.occupy(0, "v0_0")
    lattice.request(0, "v0_0", "v0_1", 1.0)
    assert lattice.grant() == [(0, "v0_1")]
    assert lattice.holder == {"v0_0": 0, "v0_1": 0}
    lattice.release(0, "v0_0")
    assert lattice.holder == {"v0_1": 0}


def test_a_held_vertex_waits_and_requests_are_served_in_order(lattice):
    lattice.occupy(0, "v1_1")
    lattice.occupy(1, "v0_1")
    lattice.occupy(2, "v1_0")
    lattice.request(2, "v1_0", "v1_1", 5.0)
    lattice.request(1, "v0_1", "v1_1", 3.0)
    assert lattice.grant() == []  # robot 0 stands on v1_1 and is not leaving
    lattice.request(0, "v1_1", "v2_1", 6.0)
    assert lattice.grant() == [(0, "v2_1")]
    lattice.release(0, "v1_1")  # in its corridor
    assert lattice.grant() == [(1, "v1_1")]  # asked first
    assert lattice.requests.keys() == {2}


def test_a_swap_along_one_edge_is_granted_to_both(lattice):
    """A deadlock, reduced: robots on both ends of an edge, each wanting the
    other's vertex, would wait for ever; the stations let them pass on their lanes."""
    lattice.occupy(0, "v0_0")
    lattice.occupy(1, "v0_1")
    lattice.request(0, "v0_0", "v0_1", 1.0)
    lattice.request(1, "v0_1", "v0_0", 2.0)
    assert sorted(lattice.grant()) == [(0, "v0_1"), (1, "v0_0")]
    lattice.release(0, "v0_0")  # robot 1 holds it now: robot 0's release leaves it
    assert lattice.holder == {"v0_1": 0, "v0_0": 1}


def test_a_chain_that_does_not_close_waits(lattice):
    lattice.occupy(0, "v0_0")
    lattice.occupy(1, "v0_1")
    lattice.occupy(2, "v0_2")
    lattice.request(0, "v0_0", "v0_1", 1.0)
    lattice.request(1, "v0_1", "v0_2", 1.0)
    assert lattice.grant() == []  # robot 2 stands on v0_2 and asks for nothing


def test_a_stopped_robot_releases_everything(lattice):
    lattice.occupy(0, "v0_0")
    lattice.request(0, "v0_0", "v0_1", 1.0)
    lattice.grant()
    assert sorted(lattice.release_all(0)) == ["v0_0", "v0_1"]
    assert lattice.holder == {} and lattice.requests == {}


def _wait_for_graph(stations: VertexStations) -> nx.DiGraph:
    """Robot -> robot it waits for (the holder of the vertex it wants)."""
    g = nx.DiGraph()
    for robot, request in stations.requests.items():
        holder = stations.holder.get(request.to)
        if holder is not None:
            g.add_edge(robot, holder)
    return g


@pytest.mark.parametrize("seed", range(40))
def test_no_circular_wait_survives_a_grant(seed):
    """Random teams on the centres of a lattice, each wanting a random neighbour, and
    robots turned back on lanes (holding nothing) wanting a random vertex: after one grant
    no cycle of robots waits for each other (networkx finds none), and every grant
    respects one robot per vertex."""
    spec = load_arena("lattice:4x4")
    g = spec.graph()
    rng = np.random.default_rng(seed)
    vertices = list(spec.vertices)
    team = rng.choice(len(vertices), size=rng.integers(2, 12), replace=False)
    stations = VertexStations(vertex_fans(spec))
    for robot, k in enumerate(team):
        stations.occupy(robot, vertices[k])
    for robot, k in enumerate(team):
        if rng.random() < 0.85:
            nbrs = sorted(g.neighbors(vertices[k]))
            stations.request(robot, vertices[k], nbrs[rng.integers(len(nbrs))], float(robot))
    for robot in range(len(team), len(team) + rng.integers(0, 4)):  # on lanes
        stations.request(robot, None, vertices[rng.integers(len(vertices))], rng.random() * 12)
    granted = stations.grant()
    assert len({v for _, v in granted}) == len(granted)
    assert all(stations.holder[v] == r for r, v in granted)
    assert list(nx.simple_cycles(_wait_for_graph(stations))) == []


def test_a_swap_grants_both_robots_and_tells_each_its_vertex_is_not_yet_clear():
    """Two robots on the two ends of an edge, each asking for the other's vertex: the
    cycle is granted whole, and each is told that its vertex is still being left (a
    grant told 'clear' before the other grant took effect would drive robots into each
    other); a robot's 'left' clears the other's way."""
    run = EmbodiedExploration(load_arena("fig9"), make_minds("incidence-dfs", 2),
                              EmbodiedConfig(), 0)
    u, w = load_arena("fig9").edges[0]
    run.launching.queue.clear()
    run.stations.entry.target[:] = [u, w]
    run.stations.entry.grants.occupy(0, u)
    run.stations.entry.grants.occupy(1, w)
    run.stations.entry.grants.request(0, u, w, 0.0)
    run.stations.entry.grants.request(1, w, u, 0.0)
    run.stations.before_step(run.loop)
    run.uplink.step()
    replies = [[m.payload for m in run.uplink.receive_for(i)] for i in (0, 1)]
    assert replies == [[EntryGranted(clear=False)], [EntryGranted(clear=False)]]
    assert run.stations.entry.target == [w, u] and run.stations.entry.leaving == [u, w]
    _tell(run, 0, LeftVertex())  # R1 is in its corridor: u is free for R2
    run.uplink.step()
    assert [m.payload for m in run.uplink.receive_for(1)] == [VertexClear()]
    assert run.uplink.receive_for(0) == []


def test_a_withdrawn_request_is_dropped(lattice):
    lattice.occupy(0, "v0_0")
    lattice.occupy(1, "v0_1")
    lattice.request(0, "v0_0", "v0_1", 1.0)
    lattice.withdraw(0)
    lattice.release(1, "v0_1")
    assert lattice.grant() == [] and lattice.holder == {"v0_0": 0}


def _on_fig9(k: int = 2) -> tuple[EmbodiedExploration, str, str]:
    run = EmbodiedExploration(load_arena("fig9"), make_minds("incidence-dfs", k),
                              EmbodiedConfig(), 0)
    run.launching.queue.clear()
    u, w = load_arena("fig9").edges[0]
    return run, u, w


def _granted(run, i, u, w):
    """Robot ``i`` on ``u`` asks for the edge to ``w`` and gets it."""
    run.stations.entry.target[i] = u
    run.stations.entry.grants.occupy(i, u)
    _tell(run, i, EntryRequest(_angle(run, u, w)))
    run.stations.before_step(run.loop)
    run.uplink.step()
    return [m.payload for m in run.uplink.receive_for(i)]


def _tell(run, i, payload):
    """Robot ``i``'s message reaches the stations, which answer at once."""
    run.stations.entry.receive(i, payload, run.world.time_s)
    run.stations._send(run.loop)


def _angle(run, u, w):
    return incidence_angle(run.spec, u, w)


def test_a_robot_turning_back_short_of_its_corridor_gets_its_vertex_back_at_once():
    run, u, w = _on_fig9()
    assert _granted(run, 0, u, w) == [EntryGranted(True, _angle(run, u, w))]
    _tell(run, 0, TurnedBack(from_lane=False))
    run.uplink.step()
    assert [m.payload for m in run.uplink.receive_for(0)] == [EntryGranted(clear=True)]
    assert run.stations.entry.target[0] == u and run.stations.entry.leaving[0] is None and run.stations.entry.grants.holder == {u: 0}
    # its word that its way on is closed, once the vertex is its own: nothing to undo
    _tell(run, 0, TurnedBack(from_lane=False, way_on_closed=True))
    run.stations.before_step(run.loop)
    run.uplink.step()
    assert run.uplink.receive_for(0) == [] and run.stations.entry.grants.holder == {u: 0}
    assert run.stations.entry.grants.requests == {} and run.stations.entry.target[0] == u


def test_a_robot_turning_back_from_its_lane_waits_for_its_vertex_like_a_centre():
    """Once it left ``u``'s area (``u`` went to another robot), its walk back is a request
    from its lane: granted when ``u`` is free, with the vertex ahead freed at once."""
    run, u, w = _on_fig9()
    _granted(run, 0, u, w)
    _tell(run, 0, LeftVertex())
    run.stations.entry.grants.occupy(1, u)
    run.stations.entry.target[1] = u
    _tell(run, 0, TurnedBack(from_lane=True))
    assert run.stations.entry.grants.holder == {u: 1} and run.stations.entry.grants.requests[0].at is None
    run.stations.before_step(run.loop)
    assert run.stations.entry.grants.holder == {u: 1}  # u is held: it waits
    run.stations.entry.grants.release(1, u)
    run.stations.before_step(run.loop)
    run.uplink.step()
    assert [m.payload for m in run.uplink.receive_for(0)] == [EntryGranted(True, None)]
    assert run.stations.entry.target[0] == u and run.stations.entry.grants.holder == {u: 0}


def _swapped(run, u, w):
    """Robots 0 on ``u`` and 1 on ``w`` are granted each other's vertex (a swap)."""
    run.stations.entry.target[:] = [u, w]
    run.stations.entry.grants.occupy(0, u)
    run.stations.entry.grants.occupy(1, w)
    for i, (a, b) in enumerate(((u, w), (w, u))):
        _tell(run, i, EntryRequest(_angle(run, a, b)))
    run.stations.before_step(run.loop)
    run.uplink.step()
    for i in (0, 1):
        assert [m.payload for m in run.uplink.receive_for(i)] == [
            EntryGranted(False, _angle(run, *((u, w), (w, u))[i]))]


def test_a_swap_partner_keeps_its_grant_when_the_other_turns_back_or_withdraws():
    """In a swap each robot was given the other's vertex: one that then asks to turn back
    into its old area gets no answer (it goes on), and one that withdraws leaves the
    other waiting until it has left its area."""
    run, u, w = _on_fig9()
    _swapped(run, u, w)
    _tell(run, 0, TurnedBack(from_lane=False))
    run.uplink.step()
    assert run.uplink.receive_for(0) == [] and run.stations.entry.target == [w, u]
    _tell(run, 1, Withdraw())
    assert run.stations.entry.target[1] == w and run.stations.entry.leaving[1] == w  # robot 0 still waits for it to go
    assert run.stations.entry.grants.holder == {w: 0}
    run.uplink.step()
    assert run.uplink.receive_for(0) == []  # no VertexClear for robot 0


def test_a_swap_is_undone_for_a_robot_that_can_go_neither_on_nor_back():
    """Robot 0 asks to turn back into ``u``, which the swap gave robot 1, and a wall closed
    its way on: while robot 1 waits on its lane for ``u`` to clear, ``u`` goes back to
    robot 0 and robot 1's grant becomes a request from its lane, granted once ``u`` is
    free again (with the angle it had asked for, so robot 1 takes it as its grant)."""
    run, u, w = _on_fig9()
    _swapped(run, u, w)
    entry = run.stations.entry
    _tell(run, 1, LeftVertex())  # robot 1 is on its lane, out of every area
    run.uplink.step()
    assert [m.payload for m in run.uplink.receive_for(0)] == [VertexClear()]
    _tell(run, 0, TurnedBack(from_lane=False))
    run.uplink.step()
    assert run.uplink.receive_for(0) == []  # it may go on: the swap stands
    _tell(run, 0, TurnedBack(from_lane=False, way_on_closed=True))
    run.uplink.step()
    assert [m.payload for m in run.uplink.receive_for(0)] == [EntryGranted(clear=True)]
    assert run.uplink.receive_for(1) == []  # robot 1 keeps waiting where it is
    assert entry.grants.holder == {u: 0} and entry.target == [u, None]
    assert entry.grants.requests[1].at is None and entry.grants.requests[1].to == u
    run.stations.before_step(run.loop)
    assert entry.grants.holder == {u: 0}  # robot 0 stands in u: robot 1 waits
    _tell(run, 0, EntryRequest(_angle(run, u, w)))  # robot 0 leaves u for w at last
    run.stations.before_step(run.loop)
    run.uplink.step()
    assert [m.payload for m in run.uplink.receive_for(0)] == [EntryGranted(True, _angle(run, u, w))]
    _tell(run, 0, LeftVertex())
    run.stations.before_step(run.loop)
    run.uplink.step()
    assert [m.payload for m in run.uplink.receive_for(1)] == [EntryGranted(True, _angle(run, w, u))]
    assert entry.grants.holder == {u: 1, w: 0}


def test_a_swap_stands_while_its_partner_is_still_in_the_area_it_left():
    """Robot 1 has not yet left ``w``'s area: undoing the swap would leave it two vertex
    areas to wait between, so robot 0's word that its way on is closed changes nothing."""
    run, u, w = _on_fig9()
    _swapped(run, u, w)
    _tell(run, 0, TurnedBack(from_lane=False, way_on_closed=True))
    run.uplink.step()
    assert run.uplink.receive_for(0) == [] and run.stations.entry.target == [w, u]
    assert run.stations.entry.grants.holder == {u: 1, w: 0}


def test_a_withdrawn_clear_grant_is_taken_back():
    run, u, w = _on_fig9()
    _granted(run, 0, u, w)
    _tell(run, 0, Withdraw())
    assert run.stations.entry.target[0] == u and run.stations.entry.leaving[0] is None and run.stations.entry.grants.holder == {u: 0}


def test_a_robot_that_gives_up_a_waiting_request_is_told_busy_and_never_granted():
    """Step 8: a request still waiting is dropped and answered ``EntryBusy`` with its
    angle; the vertex, freed later, is not granted to it; the robot keeps its own."""
    run, u, w = _on_fig9()
    run.stations.entry.target[:] = [u, w]
    run.stations.entry.grants.occupy(0, u)
    run.stations.entry.grants.occupy(1, w)  # w is held: robot 0's request waits
    angle = _angle(run, u, w)
    _tell(run, 0, EntryRequest(angle))
    run.stations.before_step(run.loop)
    run.uplink.step()
    assert run.uplink.receive_for(0) == []
    _tell(run, 0, GiveUp())
    run.uplink.step()
    assert [m.payload for m in run.uplink.receive_for(0)] == [EntryBusy(angle)]
    assert run.stations.gave_up == 1
    run.stations.entry.grants.release(1, w)
    run.stations.before_step(run.loop)
    run.uplink.step()
    assert run.uplink.receive_for(0) == [] and run.stations.entry.grants.holder == {u: 0}


def test_a_give_up_that_crosses_its_grant_leaves_the_grant_standing():
    """A robot whose request was granted as it gave up gets no ``EntryBusy``: the grant
    on its way stands and the robot obeys it (no grant is taken back half-way)."""
    run, u, w = _on_fig9()
    assert _granted(run, 0, u, w) == [EntryGranted(True, _angle(run, u, w))]
    _tell(run, 0, GiveUp())
    run.uplink.step()
    assert run.uplink.receive_for(0) == [] and run.stations.gave_up == 0
    assert run.stations.entry.target[0] == w and run.stations.entry.grants.holder[w] == 0


@pytest.mark.parametrize("seed", range(6))
def test_nearest_vertex_by_the_whole_matrix_equals_the_k_d_tree(monkeypatch, seed):
    """Below ``NEAREST_TREE_FROM`` robot-vertex pairs the stations find each robot's
    vertex from the whole distance matrix; the k-d tree gives the same vertices and
    distances (robots anywhere on and off the arena, some on vertex centres), and so
    does each way when only some robots are on the floor (the rest asked one by one)."""
    from mjswarm.experiments import stations

    class Sim:  # the two things NearestVertex reads of a simulation
        def __init__(self, xy):
            self.n, self.state_version, self._xy = len(xy), 0, xy

        def poses(self):
            return np.column_stack([self._xy, np.zeros(self.n)])

    spec = load_arena(["arena2", "lattice:5x4", "hex:3x3"][seed % 3])
    rng = np.random.default_rng(seed)
    vertices = np.array(list(spec.vertices.values()))
    lo, hi = vertices.min(axis=0) - 0.5, vertices.max(axis=0) + 0.5
    xy = rng.uniform(lo, hi, (40, 2))
    xy[:5] = vertices[rng.integers(len(vertices), size=5)]  # standing on centres
    answers = []
    present = rng.random(len(xy)) < 0.5
    for tree_from in (10**9, 0):  # the matrix, then the tree
        monkeypatch.setattr(stations, "NEAREST_TREE_FROM", tree_from)
        for on_floor in (None, present):
            nearest = stations.NearestVertex(Sim(xy), spec, on_floor)
            assert (nearest._tree is None) == (tree_from > 0)
            answers.append([nearest(i) for i in range(len(xy))])
    assert answers[0] == answers[1] == answers[2] == answers[3]
    assert all(d == 0.0 for _, d in answers[0][:5])
