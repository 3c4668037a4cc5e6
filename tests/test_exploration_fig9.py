"""Nagavarapu et al.'s worked example (section 5, Fig. 9): two robots on the 10-vertex, 12-edge graph."""

from __future__ import annotations

import math

import pytest
from exploration_graphs import Probe, fig9

from algorithms.exploration import IncidenceDFS
from algorithms.exploration.incidence_matrix import COMPLETED, OUT, UNEXPLORED
from mjswarm.experiments.graph_exploration import explore
from mjswarm.worlds.graphworld import GraphWorld

PI = math.pi

#: I10(v6) as printed (Nagavarapu et al., section 5): rows v6 v5 v4 v3 v2 v1.
PAPER_EDGES = ["e56", "e46", "e34", "e13", "e25", "e24", "e12", "e68", "e57"]
PAPER_I10_V6 = {
    "v6": [-PI / 2, -PI, 0, 0, 0, 0, 0, 2 * PI, 0],
    "v5": [-3 * PI / 2, 0, 0, 0, -PI, 0, 0, 0, 2 * PI],
    "v4": [0, -2 * PI, -PI, 0, 0, -PI / 2, 0, 0, 0],
    "v3": [0, 0, -2 * PI, -PI / 2, 0, 0, 0, 0, 0],
    "v2": [0, 0, 0, 0, -2 * PI, -3 * PI / 2, -PI, 0, 0],
    "v1": [0, 0, 0, -3 * PI / 2, 0, 0, -2 * PI, 0, 0],
}


def edge_name(u: str, v: str) -> str:
    a, b = sorted((u[1:], v[1:]), key=int)
    return f"e{a}{b}"


class Snapshot(IncidenceDFS):
    """IncidenceDFS that keeps In(Rk) as it is after the first step (Algorithm 3)."""

    def observe(self) -> None:
        self.after_first_step = self.matrix
        super().observe()


@pytest.fixture(scope="module")
def run():
    snapshots = {}
    tags = {}

    def observer(t, i, vertex, mind):
        tags[mind.here] = vertex
        snapshots[(t, i)] = (vertex, mind.after_first_step)

    result = explore(fig9(), "v1", 2, Snapshot, functions=[Probe(observer)])
    return result, snapshots, tags  # snapshots in the order the world handled them


def test_fig9_vertex_sequences_and_completion(run):
    result, _, _ = run
    assert result.paths == [
        ["v1", "v2", "v4", "v2", "v5", "v6", "v5", "v7", "v8"],
        ["v1", "v3", "v4", "v6", "v8", "v9", "v10", "v9", "v8"],
    ]
    assert result.completed and result.makespan == 8
    assert (result.declared_by, result.declared_at) == (1, "v8")
    assert result.map_correct and len(result.map_edges) == 12
    assert result.traversals_per_robot == [8, 8] and result.total_traversals == 16


def test_fig9_final_matrix_is_v_by_e(run):
    """Proposition 1: at completion the matrix is V x E (10 x 12), all columns completed."""
    _, snapshots, _ = run
    _, final = snapshots[(8, 0)]
    _, columns, dense = final.to_array()
    assert dense.shape == (10, 12) and final.is_complete()
    assert all(len(c) == 2 for c in columns) and (dense <= 0).all()


def test_fig9_matrix_at_v6_after_10th_update_matches_paper(run):
    """I10(v6): R1 at v6 at step 5 is the 10th update (R2's update of each step first).

    Orderings: our rows, and our completed and unexplored columns (blocks completed | out |
    unexplored, Algorithm 2), are in the order the team first wrote them, where the paper
    lists rows newest first; only the entries are compared. The printed +2*pi for e68 at
    v6 is a misprint: R2 left v6 along e68 at step 3, which eq. (5) makes out (-2*pi).
    """
    _, snapshots, tags = run
    updates = [k for k in snapshots if k[0] > 0]  # update n = n-th edge traversal handled
    assert updates.index((5, 0)) + 1 == 10
    vertex, matrix = snapshots[(5, 0)]
    assert vertex == "v6"
    world = GraphWorld(fig9(), "v1")
    row_tags, columns, dense = matrix.to_array()
    ours = {}
    for j, column in enumerate(columns):
        if len(column) == 2:
            name = edge_name(tags[column[0][0]], tags[column[1][0]])
        else:
            (tag, theta), = column
            name = edge_name(tags[tag], world.towards[(tags[tag], theta)])
        for i, tag in enumerate(row_tags):
            if dense[i, j]:
                ours[(tags[tag], name)] = dense[i, j]
    paper = {
        (v, e): x for v, row in PAPER_I10_V6.items() for e, x in zip(PAPER_EDGES, row) if x
    }
    paper[("v6", "e68")] = -2 * PI  # the misprint
    assert ours.keys() == paper.keys()
    for key, value in paper.items():
        assert ours[key] == pytest.approx(value), key
    assert [len(c) for c in columns] == [2] * 7 + [1, 1]  # completed block, then e68, e57
    e68, e57 = columns[7][0], columns[8][0]
    assert tags[e68[0]] == "v6" and matrix.status(e68) == OUT
    assert tags[e57[0]] == "v5" and matrix.status(e57) == UNEXPLORED
    assert all(matrix.status(c[0]) == COMPLETED for c in columns[:7])


def test_fig9_robot_one_drops_beacons_a1_a2(run):
    """Beacon names follow the paper (R1: a1, a2, ...; R2: b1, ...). R2 is handled first at
    the root, so b1 is the root's beacon and R1's first beacon a1 is at v2."""
    _, _, tags = run
    assert tags["b1"] == "v1" and tags["a1"] == "v2" and tags["b2"] == "v3"
    assert sorted(tags) == sorted(["a1", "a2", "a3", "b1", "b2", "b3", "b4", "b5", "b6", "b7"])
