"""Write your own controller: a random walk that keeps clear of other robots.

The controller below is all a user writes. It sees only its own observation (its
positioning sensor's pose, the robots its range-and-bearing sensor detects) and answers
with a command; the same class runs unchanged on kinematic points and on MuJoCo Spark V
robots, and each run is recorded with rerun (open it with ``mjswarm view FILE.rrd``).

    python examples/random_walk.py                  # 8 robots, 60 s in each world
    python examples/random_walk.py --robots 12 --seconds 120 --out /tmp

It runs from any directory: the recordings go to the repository's recordings/ folder
unless ``--out`` names another (a relative one is taken from the current directory).
"""

import argparse
import math
import random
import sys
from pathlib import Path

from algorithms.robot import Command, Controller, Observation
from mjswarm.worlds.loop import Loop
from mjswarm.worlds.openfloor import EmbodiedFloor, PointWorld, spread
from mjswarm.outputs.recording import Recorder, Recording


class RandomWalk(Controller):
    """Heads for a random heading, picks a new one every 2-6 s, and turns its back on
    any robot closer than 0.4 m."""

    SPEED_M_S = 0.1
    TURN_GAIN = 2.0  # rad/s per rad of heading error
    CLEAR_M = 0.4

    def __init__(self, seed: int) -> None:
        self.rng = random.Random(seed)
        self.heading = 0.0
        self.next_pick_s = 0.0

    def step(self, observation: Observation) -> Command:
        yaw = observation.pose[2]
        if observation.time_s >= self.next_pick_s:
            self.heading = self.rng.uniform(-math.pi, math.pi)
            self.next_pick_s = observation.time_s + self.rng.uniform(2.0, 6.0)
        near = [d for d in observation.detections.values() if d.range_m < self.CLEAR_M]
        if near:  # face away from the closest robot
            closest = min(near, key=lambda d: d.range_m)
            self.heading = yaw + closest.bearing_rad + math.pi
        error = math.remainder(self.heading - yaw, 2 * math.pi)
        speed = self.SPEED_M_S if abs(error) < 0.5 else 0.0  # turn first, then drive
        return Command(speed, max(-1.0, min(1.0, self.TURN_GAIN * error)))


parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--robots", type=int, default=8)
parser.add_argument("--seconds", type=float, default=60.0, help="simulated time per world")
parser.add_argument("--out", default=str(Path(__file__).resolve().parents[1] / "recordings"),
                    help="folder for the .rrd files (default: recordings/ in the repository)")
args = parser.parse_args()
if not Path(args.out).is_dir():  # one line, as mjswarm's own refusals
    print(f"random_walk.py: error: --out {args.out} is not a directory", file=sys.stderr)
    sys.exit(2)

starts = spread(args.robots, radius_m=1.0, seed=1)
for name, World in (("point", PointWorld), ("mujoco", EmbodiedFloor)):
    world = World(starts, detection_range_m=1.0, control_dt_s=0.1)
    robots = {i: RandomWalk(seed=i) for i in range(args.robots)}
    path = f"{args.out}/random_walk_{name}.rrd"
    with Recorder(path, None, args.robots, sensors=False, bounds_m=(-3, -3, 3, 3),
                  name=f"random walk, {name}") as recorder:
        Loop(world, robots, [Recording(recorder)]).run(max_ticks=round(args.seconds / 0.1))
    xy = world.true_positions()
    closest = min(math.dist(xy[a], xy[b]) for a in range(args.robots) for b in range(a))
    print(f"{name:>6}: {world.time_s:.0f} s simulated, robots end at least {closest:.2f} m "
          f"apart, {world.contacts if world.contacts is not None else 'no'} contacts "
          f"(bodies only in MuJoCo); recording {path}")
