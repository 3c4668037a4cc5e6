"""Graph-world speed against another checkout: runs per CPU second, alternately.

The graph world on the one loop is to be no slower than a graph world with its own
engine (``GraphWorld.explore``, as at commit 497d05b). Each side runs in a child process with
its own checkout first on ``sys.path``: ``lattice:10x10``, 10 robots, ``incidence-dfs``,
best of 5 batches of 40 runs by ``time.process_time`` (CPU time, which other jobs on a
shared machine disturb less than the wall clock). Usage::

    git worktree add /tmp/w497 497d05b
    python benchmarks/graphworld_ab.py /tmp/w497 [--pairs 3]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]

#: One side's measurement: prints runs per CPU second.
CHILD = """
import time
from mjswarm.arena import load_arena
from mjswarm.worlds.graphworld import GraphWorld
spec = load_arena("lattice:10x10")
world = GraphWorld(spec.graph(), spec.root)
try:
    from mjswarm.experiments.graph_exploration import explore_world
    run = lambda: explore_world(world, 10, "incidence-dfs")
except ImportError:  # a checkout whose graph world has its own engine
    run = lambda: world.explore(10, "incidence-dfs")
run()
best = float("inf")
for _ in range(5):
    start = time.process_time()
    for _ in range(40):
        run()
    best = min(best, time.process_time() - start)
print(f"{40 / best:.1f}")
"""


def measure(tree: Path) -> float:
    """Runs per CPU second of the checkout at ``tree``."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    out = subprocess.run([sys.executable, "-c", CHILD], cwd=tree, env=env, check=True,
                         capture_output=True, text=True)
    return float(out.stdout.strip())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("other", type=Path, help="the other checkout (e.g. of 497d05b)")
    parser.add_argument("--pairs", type=int, default=3, help="alternating pairs (default 3)")
    args = parser.parse_args()
    if not (args.other / "mjswarm").is_dir():
        parser.error(f"{args.other} is not an mjswarm checkout")
    for _ in range(args.pairs):
        print(f"other {measure(args.other):.1f}  this {measure(HERE):.1f} runs per CPU second",
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
