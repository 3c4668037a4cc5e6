"""Write your own exploration strategy and drop it into both exploration worlds.

``BeaconDfs`` is a single-robot depth-first search that keeps its bookkeeping on the
beacons (Tarry's rule): at each vertex it marks the edges it has taken there, leaves by an
untaken edge, turns straight back when an untaken edge led to a vertex it already knew,
and retreats along the edge it first came by when nothing is left; back at the root with
nothing left, the search is complete. Its only inputs are the beacon it stands on and the
incidence angles it measured, so the same class runs in the synchronous graph world and
on an embodied MuJoCo robot, through one entry point
(:func:`mjswarm.experiments.runs.run_exploration`): in each world it runs inside that
world's controller.

    python examples/my_strategy.py                 # fig9, graph world then embodied
    python examples/my_strategy.py --arena arena1
"""

import argparse

from algorithms.exploration.base import DONE, Strategy, go, match_angle
from mjswarm.arena import load_arena
from mjswarm.experiments.exploration import EmbodiedConfig
from mjswarm.experiments.runs import run_exploration


class BeaconDfs(Strategy):
    name = "beacon-dfs"

    def __init__(self, index, n_robots, rng=None):
        super().__init__(index, n_robots, rng)
        self.dropped = 0
        self.previous = None  # the beacon it left last
        self.edges = set()

    def on_vertex(self, beacon, angles, arrived_by):
        new = beacon.id is None
        if new:  # the first visit drops a beacon: the angles, and the edges taken here
            self.dropped += 1
            beacon.id = f"R{self.index + 1}.{self.dropped}"
            beacon.data = {"angles": tuple(angles), "taken": set(), "parent": None}
        data = beacon.data
        self.stored_angles = None if new else data["angles"]  # embodied re-anchoring
        if arrived_by is not None:
            came = match_angle(arrived_by, data["angles"])
            self.edges.add(tuple(sorted((self.previous, beacon.id))))
            if new:
                data["parent"] = came
            elif came not in data["taken"]:  # a new edge to a known vertex: go back
                data["taken"].add(came)
                return self._leave(beacon, came)
            data["taken"].add(came)
        for angle in data["angles"]:
            if angle not in data["taken"]:
                data["taken"].add(angle)
                return self._leave(beacon, angle)
        return DONE if data["parent"] is None else self._leave(beacon, data["parent"])

    def _leave(self, beacon, angle):
        self.previous = beacon.id
        return go(angle)

    def map_edges(self):
        return sorted(self.edges)


parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--arena", default="fig9")
args = parser.parse_args()

spec = load_arena(args.arena)
for world in ("graph", "embodied"):  # one entry point, any world
    r = run_exploration(spec, 1, BeaconDfs, world=world, seed=0,
                        config=EmbodiedConfig(speed_m_s=0.15))
    where = f"in {r.sim_time_s:.0f} s simulated, {r.collisions} contacts" \
        if world == "embodied" else f"in {r.makespan:g} time units"
    print(f"{world + ' world:':<16}completed={r.completed}, map correct={r.map_correct}, "
          f"{r.total_traversals} traversals for {len(spec.edges)} edges {where}")
