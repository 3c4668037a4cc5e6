"""How often Nagavarapu et al.'s method needs more steps than MR-DFS on random trees.

The paper claims its makespan on trees is never above MR-DFS's, and at most E
(Proposition 2). This counts, over the arena generator's random trees
``random-tree:E:SEED`` (seeds 0..N-1, E = 5..30 edges) and K = 2..8 robots in the graph
world, the runs where it is above either, and by how many steps.

    python benchmarks/trees_proposed_vs_mr_dfs.py [--trees 300]
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, field
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mjswarm.arena import load_arena  # noqa: E402
from mjswarm.experiments.graph_exploration import explore_world  # noqa: E402
from mjswarm.worlds.graphworld import GraphWorld  # noqa: E402

#: Random trees compared by default.
N_TREES = 300


@dataclass
class Comparison:
    total: int = 0
    #: runs where the proposed makespan is above MR-DFS's
    worse: int = 0
    #: runs where the proposed makespan is above E (Proposition 2 broken)
    over_e: int = 0
    #: steps above MR-DFS -> runs
    margins: dict[int, int] = field(default_factory=dict)


def compare(n_trees: int = N_TREES) -> Comparison:
    c = Comparison()
    for seed in range(n_trees):
        spec = load_arena(f"random-tree:{5 + seed % 26}:{seed}")
        world = GraphWorld(spec.graph(), spec.root)
        for k in range(2, 9):
            ours = explore_world(world, k, "incidence-dfs").makespan
            theirs = explore_world(world, k, "mr-dfs").makespan
            c.total += 1
            c.over_e += ours > len(spec.edges)
            if ours > theirs:
                c.worse += 1
                c.margins[ours - theirs] = c.margins.get(ours - theirs, 0) + 1
    return c


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trees", type=int, default=N_TREES)
    c = compare(parser.parse_args().trees)
    print(f"proposed above E in {c.over_e} of {c.total} runs; above MR-DFS in {c.worse} "
          f"of {c.total} runs, by (steps: runs) {dict(sorted(c.margins.items()))}")
