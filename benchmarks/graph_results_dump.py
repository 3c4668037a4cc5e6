"""Dump the graph worlds' results on a large grid, to check that a change to the graph
worlds or the loop leaves them identical.

    python benchmarks/graph_results_dump.py OUT.jsonl      # about 2 minutes on 2 cores
    python benchmarks/graph_results_dump.py NEW.jsonl && cmp OLD.jsonl NEW.jsonl

Every line is one run's full result (JSON, keys sorted): the graph world for every
shipped strategy on paper arenas, lattices, random trees, graphs and planar graphs, with
1 to 8 robots, canonical tie rules and three seeds, unit and length edge times; and the
radio graph world (1728 runs) under each connectivity constraint, at two ranges, both edge
times, 2 to 6 robots.
"""

from __future__ import annotations

import itertools
import json
import sys

from algorithms.exploration import STRATEGIES
from mjswarm.arena import load_arena
from mjswarm.experiments.graph_exploration import explore_world
from mjswarm.experiments.minds import make_minds
from mjswarm.experiments.radio_exploration import run_connected
from mjswarm.worlds.graphworld import GraphWorld

ARENAS = ("fig9", "arena1", "arena2", "tree1", "tree2", "tree3", "tree4", "lattice:4x4",
          "lattice:3x5", "random-tree:14:1", "random-tree:20:2", "random-graph:12:16:3",
          "random-planar:12:4", "hex:2x2", "wheel:6")
ROBOTS = (1, 2, 3, 4, 6, 8)
SEEDS = (None, 0, 1, 2)
#: the radio graph world's arenas and a radio range for each (m); every run also at twice it
RADIO = (("lattice:4x4", 1.3), ("arena2", 1.0), ("random-graph:12:16:3", 1.5), ("tree2", 1.2),
         ("arena1", 0.8), ("fig9", 1.0), ("lattice:3x5", 0.9), ("random-tree:14:1", 1.1),
         ("random-planar:12:4", 1.0), ("hex:2x2", 0.7), ("tree4", 0.6), ("wheel:6", 0.9))


def graph_runs():
    for arena in ARENAS:
        spec = load_arena(arena)
        for edge_time in ("unit", "length"):
            world = GraphWorld(spec.graph(), spec.root, edge_time=edge_time)
            for strategy, k, seed in itertools.product(STRATEGIES, ROBOTS, SEEDS):
                result = explore_world(world, k, strategy, seed=seed, arena=arena)
                yield {"world": "graph", **result.to_dict()}


def radio_runs():
    for (arena, range_m), connectivity, edge_time in itertools.product(
            RADIO, ("none", "connected", "biconnected"), ("unit", "length")):
        spec = load_arena(arena)
        world = GraphWorld(spec.graph(), spec.root, edge_time=edge_time)
        for k, seed, scale in itertools.product((2, 3, 4, 6), (None, 0, 1), (1, 2)):
            result = run_connected(world, make_minds("incidence-dfs", k, seed), scale * range_m,
                                   connectivity, seed=seed, arena=arena)
            yield {"world": "radio-graph", "range": scale * range_m, **result.to_dict()}


def main(path: str) -> None:
    with open(path, "w", encoding="utf-8") as out:
        for run in itertools.chain(graph_runs(), radio_runs()):
            out.write(json.dumps(run, sort_keys=True) + "\n")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
