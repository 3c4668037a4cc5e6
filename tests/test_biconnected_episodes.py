"""Ahmadi & Stone's add / remove episodes: the team's radio graph stays biconnected (networkx on
ground truth), the robots' tables agree, and the CLI reports mean_coverage."""

from __future__ import annotations

import json
import math

import networkx as nx
import pytest

from mjswarm.cli import main
from mjswarm.experiments.coverage import CLEARANCE_M, CoverageRun
from mjswarm.worlds.loop import LoopFunctions


def truth_graph(run: CoverageRun) -> nx.Graph:
    """The radio graph from the ground-truth positions (range = the run's link range)."""
    pos = run.world.true_positions()
    ids = [i for i in range(run.world.n) if run.world.present[i]]
    g = nx.Graph()
    g.add_nodes_from(ids)
    g.add_edges_from((a, b) for a in ids for b in ids
                     if a < b and math.dist(pos[a], pos[b]) <= run.params.link_m)
    return g


def minds(run: CoverageRun) -> dict:
    """The controllers of the robots on the floor (a test may look inside them)."""
    return {k: run.loop.controllers[k] for k in run.team}


def assert_team_sound(run: CoverageRun) -> None:
    g = truth_graph(run)
    n = g.number_of_nodes()
    assert set(g) == set(run.team)
    if n >= 3:
        assert nx.is_biconnected(g), sorted(g.edges)
    elif n == 2:
        assert nx.is_connected(g)
    centres = {k: m.centre for k, m in minds(run).items()}
    for mind in minds(run).values():
        assert mind.table.keys() == centres.keys()
        assert all(math.dist(mind.table[k], c) < 1e-9 for k, c in centres.items())


@pytest.mark.parametrize("cr,placement,seeds", [
    (2.0, "heuristic", range(6)),
    (4.0, "heuristic", range(6)),
    (2.0, "min-intersection", range(2)),
])
def test_point_world_stays_biconnected_after_every_episode(cr, placement, seeds):
    actions = set()
    for seed in seeds:
        run = CoverageRun(cr, placement, "point", seed)
        assert len(run.team) == 5
        assert_team_sound(run)
        for _ in range(20):
            episode = run.step_episode()
            actions.add(episode.action)
            assert_team_sound(run)
            if episode.coverage is not None:
                assert 0.0 < episode.coverage <= 1.0 + 1e-12
    assert actions == {"add", "remove"}


@pytest.mark.parametrize("cr,placement,seed", [
    (2.0, "heuristic", 0), (2.0, "heuristic", 3), (2.0, "min-intersection", 1),
])
def test_bodies_keep_their_distance_and_see_the_same_episodes(cr, placement, seed):
    """Points given the embodied clearance never come within a body width of each other
    (brute force at every tick), settle, stay biconnected, and see the same random episodes
    as bodiless points (placing the entry clear of bodies draws no extra random numbers).
    Coverages may differ: the distributed check runs on the radio graph of where the robots
    really hold."""
    points = CoverageRun(cr, placement, "point", seed)
    bodies = CoverageRun(cr, placement, "point", seed, clearance_m=CLEARANCE_M)
    closest = [math.inf]

    class Watcher(LoopFunctions):
        def after_step(self, loop):
            pos = loop.world.true_positions()
            ids = loop.world.active()
            closest[0] = min([closest[0], *(math.dist(pos[a], pos[b])
                                             for a in ids for b in ids if a < b)])

    bodies.loop.add(Watcher())
    for _ in range(60):
        a, b = points.step_episode(), bodies.step_episode()
        assert (a.action, a.robot, a.robots) == (b.action, b.robot, b.robots)
        assert_team_sound(bodies)
    assert closest[0] >= 0.16  # chassis 0.15 m wide: no contact (MOVE crossings come close)


def test_cli_json_has_mean_coverage(capsys):
    code = main(["experiment", "biconnected-coverage", "--cr", "2", "--world", "point",
                 "--episodes", "4", "--seed", "3", "--json", "-"])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert len(data["episodes"]) == 4
    assert 0.0 < data["mean_coverage"] <= 1.0
    assert data["paper_mean_coverage"] == pytest.approx(0.73)
    assert data["link_m"] == pytest.approx(1.0)


@pytest.mark.parametrize("argv,words", [
    (["--cr", "2", "--episodes", "0"], "--episodes must be a whole number >= 1"),
    (["--cr", "2", "--region-diameter", "0.1"], "--region-diameter must be"),
])
def test_cli_user_errors_are_one_line(capsys, argv, words):
    code = main(["experiment", "biconnected-coverage", "--world", "point", *argv])
    err = capsys.readouterr().err
    assert code == 2 and words in err and err.count("\n") == 1


@pytest.mark.slow
def test_embodied_episodes_stay_biconnected():
    run = CoverageRun(2.0, "heuristic", "embodied", seed=1)
    assert_team_sound(run)
    for _ in range(6):
        run.step_episode()
        assert_team_sound(run)
    assert run.world.sim.collisions.count == 0
