"""Closed vertices: a body stopped for good in a vertex area closes
that vertex; the team finishes every edge it can still reach, declares completion of that
part (Theorem 1 on the reach, :mod:`algorithms.exploration.incidence_matrix`) and the
result names the edges it could not reach.

The strategy-level checks drive ``incidence-dfs`` minds over random graphs in a small
synchronous harness (every edge one time unit, robots arriving together handled in
descending index, as in the graph world): a request for a closed vertex is answered as the
station answers it (``Strategy.block``, then a new call at the same vertex), and a robot
on its way to a vertex that closes behind it turns back and is answered at the vertex it
left. networkx gives the part of the graph reachable from the root without entering a
closed vertex.
"""

from __future__ import annotations

import zlib

import networkx as nx
import numpy as np
import pytest

from algorithms.exploration import Beacon
from algorithms.exploration.incidence_matrix import (
    COMPLETED,
    OUT,
    UNEXPLORED,
    IncidenceMatrix,
    merge,
)
from mjswarm.arena import load_arena
from mjswarm.experiments.minds import make_minds
from mjswarm.worlds.graphworld import GraphWorld


def reachable_edges(g: nx.Graph, root: str, closed: set[str]) -> set[frozenset]:
    """Edges among the vertices reachable from ``root`` without entering ``closed``."""
    part = nx.node_connected_component(g.subgraph(set(g) - closed), root)
    return {frozenset(e) for e in g.subgraph(part).edges}


def explore_closed(spec_name: str, k: int, closed: set[str] = frozenset(),
                   deaths: dict[int, int] | None = None, seed: int | None = None,
                   strategy: str = "incidence-dfs", max_time: int = 2000,
                   root_death: int | None = None):
    """Run ``k`` minds on ``spec_name`` with ``closed`` vertices closed from the start and
    ``deaths`` {time: robot}: that robot stops for good on the vertex it arrives at then
    (if it arrives then, not at the root, and no robot stands idle there), closing it;
    ``root_death``: that robot stops for good on the root at the start, at its turn,
    closing the root (the robots after it never leave: they are the depot's). A robot
    that answers CUT_OFF stands for good. Returns (declared (robot, vertex, map)
    or None, closed vertices, live robots' vertices, the graph, the root, the robots cut
    off {robot: (vertex, map)})."""
    spec = load_arena(spec_name)
    world = GraphWorld(spec.graph(), spec.root)  # the true angles at every vertex
    g, root = spec.graph(), spec.root
    closed, deaths = set(closed), dict(deaths or {})
    minds = make_minds(strategy, k, seed)
    beacons = {v: Beacon() for v in g}
    at, due, by = [root] * k, [0] * k, [None] * k
    left: list[tuple[str, float] | None] = [None] * k  # on its way: (from, angle)
    alive, cut = set(range(k)), {}

    def mapped(i):
        ids = {b.id: u for u, b in beacons.items() if b.id is not None}
        return {frozenset((ids[a], ids[b])) for a, b in minds[i].map_edges()}

    for t in range(max_time):
        dying = deaths.pop(t, None)
        if dying in alive and due[dying] == t and at[dying] != root and not any(
                at[j] == at[dying] and by[j] is None for j in alive - {dying}):
            alive.discard(dying)  # it dies as it arrives, on the vertex centre; others
            closed.add(at[dying])  # arriving there now were on their way: they turn back
        for i in sorted((i for i in alive - cut.keys() if due[i] == t), reverse=True):
            if t == 0 and root_death is not None and i <= root_death:
                alive -= set(range(root_death + 1))  # it dies, the rest never leave
                closed.add(root)
                break
            if at[i] in closed:  # it was on its way when the vertex closed: back
                (at[i], angle), by[i] = left[i], None
                minds[i].block(angle)
            v = at[i]
            assert v not in closed
            decision = minds[i].on_vertex(beacons[v], world.angles[v], by[i])
            while decision.action == "go" and world.towards[(v, decision.angle)] in closed:
                minds[i].block(decision.angle)  # the station's EntryBlocked
                decision = minds[i].on_vertex(beacons[v], world.angles[v], None)
            if decision.action == "done":
                return (i, v, mapped(i)), closed, {at[j] for j in alive}, g, root, cut
            if decision.action == "cut off":
                cut[i] = (v, mapped(i))
                continue
            if decision.action == "go":
                w = world.towards[(v, decision.angle)]
                left[i], at[i], by[i] = (v, decision.angle), w, world.angle_of[(w, v)]
            else:
                by[i] = None
            due[i] = t + 1
        if not any(due[i] > t for i in alive - cut.keys()):
            break
    return None, closed, {at[j] for j in alive}, g, root, cut


GRAPHS = [f"random-graph:{v}:{e}:{s}" for v, e, s in
          [(10, 13, 1), (12, 16, 3), (14, 20, 5), (16, 22, 7), (11, 11, 2)]] + \
         [f"random-planar:{v}:{s}" for v, s in [(12, 4), (15, 6), (18, 8)]] + \
         [f"random-tree:{e}:{s}" for e, s in [(14, 1), (20, 2)]] + ["lattice:4x4", "arena2"]


@pytest.mark.parametrize("arena", GRAPHS)
def test_closed_from_the_start_the_map_is_exactly_the_reachable_part(arena):
    """Vertices closed before the run: the team declares, and the declared map is exactly
    the part reachable from the root without entering a closed vertex (networkx)."""
    rng = np.random.default_rng(zlib.crc32(arena.encode()))
    g = load_arena(arena).graph()
    root = load_arena(arena).root
    others = sorted(set(g) - {root})
    for trial in range(12):
        closed = set(rng.choice(others, size=int(rng.integers(1, 4)), replace=False))
        k = int(rng.integers(1, 6))
        seed = None if trial % 2 else int(rng.integers(1000))
        declared, _, _, g, root, _ = explore_closed(arena, k, closed, seed=seed)
        assert declared is not None, (arena, closed, k)
        assert declared[2] == reachable_edges(g, root, closed), (arena, closed, k, seed)


@pytest.mark.parametrize("arena", GRAPHS)
def test_a_robot_dying_mid_run_leaves_an_honest_declaration(arena):
    """A robot stops for good on a vertex during the run: a declaration's map holds every
    edge of the reachable part and only true edges (edges completed before the vertex
    closed may be in it); a run nobody declares is one whose live robots are all cut off
    from the root."""
    rng = np.random.default_rng(zlib.crc32(arena.encode()) + 1)
    spec = load_arena(arena)
    true = {frozenset(e) for e in spec.graph().edges}
    declarations = cut = 0
    for trial in range(16):
        k = int(rng.integers(2, 7))
        deaths = {int(rng.integers(1, len(true))): int(rng.integers(k))
                  for _ in range(int(rng.integers(1, 3)))}
        seed = None if trial % 2 else int(rng.integers(1000))
        declared, closed, standing, g, root, _ = explore_closed(arena, k, deaths=deaths,
                                                                seed=seed)
        reach = reachable_edges(g, root, closed) if root not in closed else set()
        if declared is None:
            part = nx.node_connected_component(g.subgraph(set(g) - closed), root)
            assert not standing & part, (arena, deaths, k, seed)
            continue
        declarations += 1
        cut += reach != true
        assert reach <= declared[2] <= true, (arena, deaths, k, seed)
    assert declarations >= 8 and cut >= 3


@pytest.mark.parametrize("arena", GRAPHS)
def test_a_closed_root_leaves_every_robot_out_to_finish_its_part(arena):
    """A robot stops for good on the root as the team sets out (and, in two trials of
    three, another stops mid-run). Unless a robot's reach still holds the root (every
    end of the root was finished as the team set out; nobody asked for it since) and it
    declares, every live robot out ends CUT_OFF with a map that covers its component of
    the graph without the closed vertices (networkx); a declared map covers every such
    component next to the root. Only true edges in any map."""
    rng = np.random.default_rng(zlib.crc32(arena.encode()) + 2)
    spec = load_arena(arena)
    true = {frozenset(e) for e in spec.graph().edges}
    for trial in range(10):
        k = int(rng.integers(2, 7))
        root_death = int(rng.integers(k - 1))  # robots root_death + 1 .. k - 1 are out
        deaths = {int(rng.integers(1, len(true))): int(rng.integers(root_death + 1, k))
                  } if trial % 3 else {}
        seed = None if trial % 2 else int(rng.integers(1000))
        declared, closed, standing, g, root, cut = explore_closed(
            arena, k, deaths=deaths, seed=seed, root_death=root_death)
        assert root in closed
        open_part = g.subgraph(set(g) - closed)
        if declared is not None:  # every end of its reach, the root's too, was finished:
            # the map covers the components next to the root (none closed from it)
            maps = [(v, declared[2]) for v in set(g[root]) - closed]
        else:
            maps = list(cut.values())
            assert {v for v, _ in maps} == standing, (arena, root_death, k, seed)
        for v, mapped in maps:
            component = nx.node_connected_component(open_part, v)
            around = {frozenset(e) for e in g.edges(component)}  # every edge it touches
            assert {frozenset(e) for e in open_part.subgraph(component).edges} <= mapped
            assert mapped <= true and around - mapped <= {
                e for e in around if e & closed}, (arena, root_death, k, seed)


def test_without_closed_vertices_nothing_changes():
    """The harness without closures explores the whole graph, as the graph world does."""
    for arena in GRAPHS:
        declared, *_, g, root, _ = explore_closed(arena, 3)
        assert declared[2] == {frozenset(e) for e in g.edges}


def test_other_strategies_refuse_closed_vertices():
    """Only incidence-dfs routes round closed vertices; the others say so."""
    spec = load_arena("arena2")
    for name in ("mr-dfs", "bfs", "lrv", "flooding"):
        mind = make_minds(name, 1, None)[0]
        mind.on_vertex(Beacon(), GraphWorld(spec.graph(), spec.root).angles[spec.root], None)
        with pytest.raises(NotImplementedError, match="closed vertex"):
            mind.block(0.0)


# -- the matrix ---------------------------------------------------------------------------

def two_vertices():
    """a1 -- a2 completed, a1 with one more edge (pi/2) and a2 with one more (pi)."""
    return merge(IncidenceMatrix.initial("a1", (HALF, TWO)),
                 IncidenceMatrix.edge(("a1", TWO), (HALF, TWO), ("a2", PI), (PI, TWO)))


TWO, PI, HALF = 2 * np.pi, np.pi, np.pi / 2


def test_a_blocked_end_is_no_candidate_and_counts_as_finished():
    m = two_vertices()
    assert m.unexplored_at("a1") == [HALF] and not m.is_complete("a1", "a1")
    b = m.block(("a1", HALF))
    assert b.is_blocked(("a1", HALF)) and not m.is_blocked(("a1", HALF))
    assert b.status(("a1", HALF)) == UNEXPLORED  # the status is kept
    assert b.unexplored_at("a1") == [] and ("a1", HALF) not in b.unexplored()
    assert b.nearest_open("a1") == [("a2", TWO)]
    assert not b.is_complete("a1", "a1")
    done = b.block(("a2", TWO))
    assert done.is_complete("a1", "a1") and done.is_complete("a2", "a1")
    assert done.nearest_open("a1") == []


def test_blocked_marks_merge_as_a_union_and_survive_containment():
    m = two_vertices()
    b = m.block(("a1", HALF))
    assert merge(m, b).is_blocked(("a1", HALF)) and merge(b, m).is_blocked(("a1", HALF))
    assert merge(m, b) is b  # b contains m
    c = m.block(("a2", TWO))
    both = merge(b, c)
    assert set(both.blocked) == {("a1", HALF), ("a2", TWO)}
    out = m.select(("a2", TWO), "A")
    assert merge(out, b).status(("a2", TWO)) == OUT
    # a copy in another numbering keeps its marks
    other = IncidenceMatrix(b.rows, b.completed, b.out, None, b.blocked)
    assert merge(m, other).is_blocked(("a1", HALF))


def test_no_route_leaves_by_a_blocked_end_and_the_reach_stops_there():
    m = two_vertices()
    cut = m.block(("a1", TWO))  # the completed edge to a2 leads to a closed vertex
    assert cut.status(("a1", TWO)) == COMPLETED
    assert cut.reach("a1") == {"a1"} and m.reach("a1") == {"a1", "a2"}
    with pytest.raises(ValueError):
        cut.route("a1", "a2")
    # a2's open end is out of reach: from a1 only a1's own end is open
    assert cut.nearest_open("a1") == [("a1", HALF)]
    assert cut.block(("a1", HALF)).is_complete("a1", "a1")
    # a robot on a2 whose way back to the root a1 is blocked (a1 closed behind it) has
    # its own ends finished but the root out of reach: it never declares
    beyond = m.block(("a2", PI)).block(("a2", TWO))
    assert beyond.reach("a2") == {"a2"} and not beyond.is_complete("a2", "a1")


# -- embodied -----------------------------------------------------------------------------

def test_embodied_robot_dying_on_a_vertex_centre_leaves_the_reachable_part_completed():
    """arena2, 3 robots (kinematic tier): R2 is switched off at 150 s on the centre of v6
    (it stands there from 144 s to 159 s), closing v6. A robot that asks for v6 is
    answered EntryBlocked, marks the edge and decides anew; the team declares completion
    of the part reachable from the root, names the four edges beyond, with 0 contacts."""
    from mjswarm.experiments.embodied import EmbodiedConfig
    from mjswarm.experiments.exploration import EmbodiedExploration
    from mjswarm.experiments.faults import parse_fault
    from algorithms.exploration.entry import EntryBlocked
    from mjswarm.cli.explore import summary

    spec = load_arena("arena2")
    run = EmbodiedExploration(spec, make_minds("incidence-dfs", 3, None), EmbodiedConfig(
        physics="kinematic", faults=[parse_fault("robot:2@150")]))
    answers = []
    reply = run.uplink.reply
    run.uplink.reply = lambda i, payload: (answers.append((i, payload)), reply(i, payload))[1]
    result = run.run()
    assert result.ended_because == "completed reachable part"
    assert result.collisions == 0
    assert result.closed_vertices == [{"vertex": "v6", "robot": 2, "at_s": 150.0}]
    beyond = {("v10", "v11"), ("v10", "v12"), ("v10", "v6"), ("v3", "v6")}
    assert {tuple(e["edge"]) for e in result.unreachable_edges} == beyond
    assert all("v6 closed by R2 stopped in its area at 150.0 s" in e["why"]
               for e in result.unreachable_edges)
    true = {tuple(sorted(e)) for e in spec.edges}
    assert set(result.map_edges) == true - beyond and result.map_correct
    assert any(type(p) is EntryBlocked and i != 1 for i, p in answers)
    assert [s["robot"] for s in result.stopped_robots] == [2]  # nobody else stopped
    d = result.to_dict()
    d["world"], d["recording"], d["video"] = "embodied", None, None
    text = summary(d)
    assert "completed the reachable part: R" in text
    assert "unreachable: v3-v6: vertex v6 closed by R2 stopped in its area at 150.0 s" in text


def test_embodied_root_closed_before_anyone_left_ends_with_nothing_reachable():
    """arena2, 2 robots at 0.05 m/s: R1 is switched off at 16 s on the root, before it
    has left; R2 can never be launched. Nothing can be reached from a closed root: the
    team's completion (the experiment's rule for a closed root) with an empty map, every
    edge named unreachable beyond the root, nobody declaring and nobody stopped but R1."""
    from mjswarm.cli.explore import summary
    from mjswarm.experiments.embodied import EmbodiedConfig
    from mjswarm.experiments.exploration import explore_embodied
    from mjswarm.experiments.faults import parse_fault

    spec = load_arena("arena2")
    result = explore_embodied(spec, 2, config=EmbodiedConfig(
        speed_m_s=0.05, faults=[parse_fault("robot:1@16")]))
    assert result.ended_because == "completed reachable part"
    assert result.completed and result.map_correct and result.declared_by is None
    assert result.map_edges == [] and result.total_traversals == 0
    assert result.closed_vertices == [{"vertex": "v1", "robot": 1, "at_s": 16.0}]
    assert len(result.unreachable_edges) == len(spec.edges)
    assert all("v1 closed by R1" in e["why"] for e in result.unreachable_edges)
    assert [s["robot"] for s in result.stopped_robots] == [1]
    d = result.to_dict()
    d["world"], d["recording"], d["video"] = "embodied", None, None
    assert "completed the reachable part: no robot was out when the root closed" in summary(d)


def test_embodied_robot_cut_off_by_a_closed_root_finishes_its_part():
    """tree3, 2 robots at 0.2 m/s (kinematic tier): R1 and R2 swap v1 (the root) and v3;
    R1 is switched off at 320 s turning on the root's centre, closing it, while R2 is in
    v3's corridor on its way to the root. The station gives R2 v3 back (its swap partner
    stopped for good), R2 walks back, finds every end of its reach finished and says it is
    cut off; nobody declares: the team's completion is its map, which covers its
    component of the arena without the root, and the result names the rest."""
    import networkx as nx

    from mjswarm.cli.explore import summary
    from mjswarm.experiments.embodied import EmbodiedConfig
    from mjswarm.experiments.exploration import explore_embodied
    from mjswarm.experiments.faults import parse_fault

    spec = load_arena("tree3")
    result = explore_embodied(spec, 2, config=EmbodiedConfig(
        speed_m_s=0.2, physics="kinematic", faults=[parse_fault("robot:1@320")]))
    assert result.ended_because == "completed reachable part"
    assert result.closed_vertices[0]["vertex"] == spec.root and result.collisions == 0
    assert result.declared_by is None and result.map_correct
    [cut] = result.cut_off_robots
    assert cut["robot"] == 2 and cut["at_s"] > 320.0
    assert [s["robot"] for s in result.stopped_robots] == [1]
    g = spec.graph()
    part = nx.node_connected_component(g.subgraph(set(g) - {spec.root}), cut["vertex"])
    inside = {tuple(sorted(e)) for e in g.subgraph(part).edges}
    assert inside and inside <= set(result.map_edges)
    named = {tuple(e["edge"]) for e in result.unreachable_edges}
    assert named == {tuple(sorted(e)) for e in g.edges} - set(result.map_edges)
    d = result.to_dict()
    d["world"], d["recording"], d["video"] = "embodied", None, None
    assert (f"completed the reachable part: every robot left is cut off from the root and "
            f"finished its part (R2 at {cut['vertex']})") in summary(d)


def test_a_body_where_corridors_still_meet_closes_the_vertex():
    """wheel:6, 3 robots at 0.15 m/s (kinematic): R3 fails at 76 s on its spoke 0.28 m from
    rim vertex r5, beyond r5's area but where the spoke's corridor still meets the rim's
    (they meet at 60 degrees: the walls start 0.38 m out, ``junction_depths``). The body
    closes r5 (else R1 would drive along the rim into it), and the team completes the
    reachable part with no contact."""
    from mjswarm.arena.geometry import VERTEX_CLEAR_RADIUS_M, junction_depths
    from mjswarm.experiments.embodied import EmbodiedConfig
    from mjswarm.experiments.exploration import explore_embodied
    from mjswarm.experiments.faults import parse_fault

    square = junction_depths(load_arena("lattice:3x3"))
    assert set(square.values()) == {VERTEX_CLEAR_RADIUS_M}  # 90 degrees: the area only
    spec = load_arena("wheel:6")
    assert junction_depths(spec)[("r5", "c")] > 0.3
    result = explore_embodied(spec, 3, config=EmbodiedConfig(
        speed_m_s=0.15, physics="kinematic", faults=[parse_fault("robot:3@76")]))
    assert result.collisions == 0 and result.ended_because == "completed reachable part"
    assert result.map_correct and [c["vertex"] for c in result.closed_vertices] == ["r5"]
