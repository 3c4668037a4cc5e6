"""A digest of every control tick's world state in one run, to show a change moved nothing.

Runs the main job (embodied exploration, default ``arena2`` with 4 robots) or the
kinematic bench world, hashing ``qpos``, ``qvel`` and the sensor readings after every
control tick (sha256 over their bytes), and prints the digest with the run's summary.
Two commits that print the same digest stepped the same trajectory to the bit.

    python benchmarks/trajectory_digest.py [--arena arena2] [--robots 4]
    python benchmarks/trajectory_digest.py --bench kinematic --robots 300 --ticks 200
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import time
from pathlib import Path

if __package__ in (None, ""):
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def _hook(sim, digest: "hashlib._Hash") -> None:
    step = sim.step

    def hashed_step(ticks: int = 1) -> None:
        for _ in range(ticks):
            step(1)
            digest.update(sim.data.qpos.tobytes())
            digest.update(sim.data.qvel.tobytes())
            digest.update(sim.readings().tobytes())

    sim.step = hashed_step


def exploration(arena: str, robots: int) -> None:
    from mjswarm.arena import load_arena
    from mjswarm.experiments.exploration import EmbodiedConfig, EmbodiedExploration
    from mjswarm.experiments.minds import make_minds

    digest = hashlib.sha256()
    run = EmbodiedExploration(load_arena(arena), make_minds("incidence-dfs", robots),
                              EmbodiedConfig(speed_m_s=0.05), 0)
    _hook(run.sim, digest)
    start = time.perf_counter()
    r = run.run()
    wall = time.perf_counter() - start
    print(f"{arena} {robots} robots: completed={r.completed} makespan={r.makespan} "
          f"traversals={r.total_traversals} sim_time={r.sim_time_s:.2f}s "
          f"collisions={r.collisions} wall={wall:.2f}s")
    print("digest", digest.hexdigest())


def bench(physics: str, robots: int, ticks: int) -> None:
    """The bench's world and loop (``mjswarm bench``): sensing, bearings, radio with line
    of sight, a heartbeat per robot per tick, the speed rule; also hashes what robots heard."""
    from mjswarm.experiments.bench import bench_loop
    from mjswarm.worlds.bench import bench_world

    digest = hashlib.sha256()
    sim = bench_world(robots, physics=physics)
    _hook(sim, digest)
    loop = bench_loop(sim)
    start = time.perf_counter()
    loop.run(max_ticks=ticks)
    wall = time.perf_counter() - start
    radio = loop.world.radio
    heard = loop.team.heard.tolist()
    digest.update(repr((radio.sent, radio.received, radio.dropped, heard)).encode())
    print(f"bench {physics} {robots} robots, {ticks} ticks: wall={wall:.2f}s "
          f"sent={radio.total_sent} received={sum(radio.received.values())} "
          f"contacts={loop.world.contacts}")
    print("digest", digest.hexdigest())


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--arena", default="arena2")
    p.add_argument("--robots", type=int, default=4)
    p.add_argument("--bench", choices=("dynamic", "kinematic"))
    p.add_argument("--ticks", type=int, default=200)
    a = p.parse_args()
    if a.bench:
        bench(a.bench, a.robots, a.ticks)
    else:
        exploration(a.arena, a.robots)
