"""The synchronous graph world: timing, ordering, idling, metrics and input errors."""

from __future__ import annotations

from typing import ClassVar

import networkx as nx
import pytest
from exploration_graphs import Probe, fig9, graph, lattice

from algorithms.exploration import DONE, IDLE, go
from algorithms.exploration.base import Strategy
from mjswarm.errors import MjswarmError
from mjswarm.experiments.graph_exploration import explore, explore_world, run_minds
from mjswarm.experiments.minds import make_minds
from mjswarm.experiments.results import Paths
from mjswarm.worlds.graphworld import GraphWorld


class Script(Strategy):
    """A mind that plays a fixed list of answers ("idle", "done", or an angle)."""

    name = "script"
    log: ClassVar[list] = []

    def __init__(self, index, n_robots, rng=None, answers=()):
        super().__init__(index, n_robots, rng)
        self.answers = list(answers)

    def on_vertex(self, beacon, angles, arrived_by):
        # the vertex's beacon behind the handle (a handle lives one tick)
        Script.log.append((self.index, getattr(beacon, "_beacon", beacon), arrived_by))
        answer = self.answers.pop(0) if self.answers else "idle"
        return {"idle": IDLE, "done": DONE}.get(answer) or go(answer)

    def map_edges(self):
        return []


def path_graph():
    """a --1 m-- b --3 m-- c (mean edge length 2 m)."""
    return graph({"a": (0, 0), "b": (1, 0), "c": (4, 0)}, [("a", "b"), ("b", "c")])


@pytest.mark.parametrize("edge_time, expected", [("unit", 2), ("length", 2.0)])
def test_edge_time_unit_or_proportional_to_length(edge_time, expected):
    r = explore(path_graph(), "a", 1, edge_time=edge_time)
    assert r.paths == [["a", "b", "c"]] and r.makespan == expected
    assert r.declared_at == "c" and r.map_correct
    times = []
    explore(path_graph(), "a", 1, edge_time=edge_time,
            functions=[Probe(lambda t, *_: times.append(t))])
    assert times == ([0, 1, 2] if edge_time == "unit" else [0, 0.5, 2.0])


def test_length_edge_time_on_a_lattice_equals_unit_time():
    from mjswarm.arena import load_arena

    g = load_arena("lattice:5x5").graph()  # 0.6 m spacing: durations 1 up to rounding
    for k in (3, 7):
        unit = explore(g, "v0_0", k)
        length = explore(g, "v0_0", k, edge_time="length")
        assert (length.makespan, length.paths) == (unit.makespan, unit.paths)


def test_idle_robots_are_asked_again_one_time_unit_later_and_max_time_stops_a_run():
    Script.log = []
    r = explore(path_graph(), "a", 1, lambda i, k, rng: Script(i, k, rng, ["idle", "idle", "done"]))
    assert r.completed and r.makespan == 2 and r.total_traversals == 0
    assert [a for _, _, a in Script.log] == [None, None, None]
    r = explore(path_graph(), "a", 2, Script, max_time=7)
    assert not r.completed and r.makespan is None and r.declared_by is None and r.map_edges == []


def test_simultaneous_arrivals_are_handled_in_descending_robot_index_sharing_the_beacon():
    Script.log = []
    explore(path_graph(), "a", 3, lambda i, k, rng: Script(i, k, rng, ["idle", "done"]))
    order = [i for i, _, _ in Script.log]
    assert order[:3] == [2, 1, 0]
    assert len({id(b) for _, b, _ in Script.log}) == 1  # one beacon per vertex


def test_traversals_under_way_at_the_declaration_do_not_count():
    # R2 (index 1) leaves along the 3 m edge at t=0 and arrives at t=1.5; R1 declares at t=1
    world = GraphWorld(path_graph(), "b", edge_time="length")
    minds = [Script(0, 2, None, [world.angle_of[("b", "a")], "done"]),
             Script(1, 2, None, [world.angle_of[("b", "c")], "done"])]
    r = run_minds(world, minds)
    assert (r.completed, r.makespan, r.declared_by, r.declared_at) == (True, 0.5, 1, "a")
    assert r.traversals_per_robot == [1, 0] and r.paths == [["b", "a"], ["b"]]


def test_map_edges_are_translated_from_beacon_ids_to_arena_vertices():
    r = explore(fig9(), "v1", 3)
    assert r.map_correct
    assert sorted(map(sorted, r.map_edges)) == sorted(map(sorted, fig9().edges))
    assert r.to_dict()["map_edges"][0] == list(r.map_edges[0])


def test_single_vertex_graph_is_complete_at_once():
    g = nx.Graph()
    g.add_node("only", pos=(0, 0))
    r = explore(g, "only", 3)
    assert r.completed and r.makespan == 0 and r.map_edges == [] and r.map_correct


@pytest.mark.parametrize("make, message", [
    (lambda: explore(fig9(), "v1", 0), "at least one robot"),
    (lambda: explore(fig9(), "v1", 2, "random-walk"), "unknown strategy 'random-walk'"),
    (lambda: explore(fig9(), "v99", 2), "root 'v99'"),
    (lambda: explore(fig9(), "v1", 2, edge_time="euclid"), "edge time"),
    (lambda: GraphWorld(nx.path_graph(3), 0), "no 'pos'"),
    (lambda: GraphWorld(graph({"a": (0, 0), "b": (1, 0), "c": (5, 5)}, [("a", "b")]), "a"),
     "not connected"),
    (lambda: GraphWorld(graph({"a": (0, 0), "b": (1, 0), "c": (2, 0)}, [("a", "b"), ("a", "c")]), "a"),
     "same angle"),
])
def test_bad_input_is_one_clear_error(make, message):
    with pytest.raises(MjswarmError, match=message):
        make()


def test_make_minds_seeds_each_robot_differently():
    a, b = make_minds("lrv", 2, seed=5)
    assert a.rng.integers(1 << 30) != b.rng.integers(1 << 30)
    assert all(m.rng is None for m in make_minds("lrv", 2))


def test_lattice_ten_by_ten_all_strategies_complete():
    g = lattice(10, 10)
    world = GraphWorld(g, "v0_0")
    for name in ("incidence-dfs", "mr-dfs", "bfs", "lrv", "flooding"):
        r = explore_world(world, 10, name)
        assert r.completed and r.map_correct, name


def test_a_users_controller_runs_in_the_graph_world():
    """Any controller written against Observation and Command runs in the graph
    world (here: always the smallest incidence angle, declaring after five calls)."""
    from algorithms.exploration.events import Declared
    from algorithms.robot import Command, Controller
    from mjswarm.experiments.graph_exploration import run_controllers

    class Smallest(Controller):
        def __init__(self) -> None:
            self.calls = 0

        def step(self, observation):
            self.calls += 1
            if self.calls == 5:
                return Command(events=(Declared(()),))
            return Command(edge_rad=min(observation.vertex.angles_rad))

    world = GraphWorld(fig9(), "v1")
    result = run_controllers(world, [Smallest(), Smallest()], "smallest")
    assert result.completed and result.makespan == 4 and result.declared_by == 2
    assert result.paths[0] == result.paths[1] and len(result.paths[0]) == 5
    assert not result.map_correct  # an empty map


def test_a_vertex_call_is_the_observation_built_by_name():
    """The graph world builds its observations as tuples (a call per decision): each is
    field for field the observation the named constructor gives."""
    from algorithms.robot import Observation, VertexSense

    g = fig9()
    root = next(iter(g))
    world = GraphWorld(g, root)
    world.reset(2)
    o = world.observe(1)
    expected = Observation(1, 0, beacon=o.beacon, vertex=VertexSense(world.angles[root], None))
    assert type(o) is Observation and len(o) == len(Observation._fields)
    assert o == expected and o.vertex == expected.vertex and o.leg is None


def test_paths_keep_the_first_or_the_last_declaration_of_a_tick():
    """Every world's path accounting (``Paths``): arrivals extend a path; of two
    declarations the first counts in the graph worlds, the last in the embodied world."""
    for keep, winner in (("first", 0), ("last", 1)):
        paths = Paths(2, "r", keep=keep)
        paths.arrive(0, "a")
        paths.arrive(1, "b")
        paths.declare(3.0, 0, "a", (("a1", "b1"),))
        paths.declare(3.0, 1, "b", (("b1", "a1"),))
        assert paths.declared == (3.0, winner, "ab"[winner])
        assert paths.declared_map == ((("a1", "b1"),), (("b1", "a1"),))[winner]
        assert paths.counted([1]) == [["r", "a"], ["r"]] and paths.paths[1] == ["r", "b"]
    with pytest.raises(ValueError):
        Paths(1, "r", keep="any")
