"""Write your own exploration strategy and drop it into both exploration worlds.

``BeaconDfs`` is a single-robot depth-first search that keeps its bookkeeping on the
beacons (Tarry's rule): at each vertex it marks the edges it has taken there, leaves by an
untaken edge, turns straight back when an untaken edge led to a vertex it already knew,
and retreats along the edge it first came by when nothing is left; back at the root with
nothing left, the search is complete. Its only inputs are the beacon it stands on and the
incidence angles it measured, so the same class runs in the synchronous graph world and
on an embodied MuJoCo robot.

    python examples/my_strategy.py                 # fig9, graph world then embodied
    python examples/my_strategy.py --arena arena1
"""

import argparse

from algorithms.exploration.base import DONE, Strategy, go, match_angle
from mjswarm.arena import load_arena
from mjswarm.experiments.exploration import EmbodiedConfig, explore_embodied
from mjswarm.worlds.graphworld import explore


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
graph = explore(spec.graph(), spec.root, 1, BeaconDfs)
print(f"graph world: completed={graph.completed}, map correct={graph.map_correct}, "
      f"{graph.total_traversals} traversals for {len(spec.edges)} edges")
body = explore_embodied(spec, 1, BeaconDfs, EmbodiedConfig(speed_m_s=0.15), seed=0)
print(f"embodied:    completed={body.completed}, map correct={body.map_correct}, "
      f"{body.total_traversals} traversals in {body.sim_time_s:.0f} s simulated, "
      f"{body.collisions} contacts")
