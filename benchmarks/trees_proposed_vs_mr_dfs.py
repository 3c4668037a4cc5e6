"""How often seed 003's method needs more steps than MR-DFS on random trees.

Seed 003 claims its makespan on trees is never above MR-DFS's. This counts, over the
arena generator's random trees ``random-tree:E:SEED`` (seeds 0..N-1, E = 5..30 edges) and
K = 2..8 robots in the graph world, the runs where it is above, and by how many steps.

    python benchmarks/trees_proposed_vs_mr_dfs.py [--trees 300]
"""

import argparse

from mjswarm.arena import load_arena
from mjswarm.experiments.graph_exploration import explore_world
from mjswarm.worlds.graphworld import GraphWorld

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--trees", type=int, default=300)
args = parser.parse_args()

worse, total, margins = 0, 0, set()
for seed in range(args.trees):
    spec = load_arena(f"random-tree:{5 + seed % 26}:{seed}")
    world = GraphWorld(spec.graph(), spec.root)
    for k in range(2, 9):
        ours = explore_world(world, k, "incidence-dfs").makespan
        theirs = explore_world(world, k, "mr-dfs").makespan
        total += 1
        if ours > theirs:
            worse += 1
            margins.add(ours - theirs)
print(f"proposed above MR-DFS in {worse} of {total} runs, by {sorted(margins)} steps")
