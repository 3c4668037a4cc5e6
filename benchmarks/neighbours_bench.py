"""The neighbour search's two candidate sources against each other, in one run.

For teams of 2 to 512 robots at random positions (a 1 m range over a square holding
about 10 robots per square metre), times ``Neighbours.pairs`` on fresh positions with
every pair as candidates and with the k-d tree's, and prints both (us a search) and
their quotient: ``mjswarm.core.neighbours.TREE_FROM_ROBOTS`` is set where they meet.

    python benchmarks/neighbours_bench.py [--repeat 2000]
"""

from __future__ import annotations

import argparse
import sys
import timeit
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from mjswarm.core import neighbours  # noqa: E402


def search_us(xy: np.ndarray, tree_from: int, repeat: int) -> float:
    """Mean wall time (us) of one search of fresh positions ``xy`` (m), 1 m range."""
    neighbours.TREE_FROM_ROBOTS = tree_from
    search = neighbours.Neighbours()

    def fresh() -> np.ndarray:
        search._key = ()  # as if the robots had moved
        return search.pairs(xy, 1.0)

    return timeit.timeit(fresh, number=repeat) / repeat * 1e6


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=2000, help="searches timed per cell")
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    shipped = neighbours.TREE_FROM_ROBOTS
    print(f"robots  every pair (us)  k-d tree (us)  tree / every   (shipped: tree from {shipped})")
    for n in (2, 4, 8, 16, 32, 64, 128, 256, 512):
        xy = rng.uniform(0.0, np.sqrt(n / 10.0), (n, 2))
        every, tree = search_us(xy, 10**9, args.repeat), search_us(xy, 0, args.repeat)
        print(f"{n:6d}  {every:15.1f}  {tree:13.1f}  {tree / every:12.2f}")
