"""How much a robot's scans over-read a turn in place, by physics tier and wheel slip.

Runs the main job (``arena2``, 4 robots, seed 0) noise-free in both physics tiers at 0.05
and 0.2 m/s, and with ``--wheel-slip`` in each tier at 0.05 m/s, and prints every robot's
effective track over its model's (:meth:`algorithms.navigation.odometry.Odometry.calibrate`:
the average of its scans' full-turn readings over 2 pi) and the distance scale it took.
Noise-free, the quotient is the floor's scrub, what
:data:`mjswarm.worlds.navigation.TURN_OVER_READ` holds per tier; with slip S, beyond the
scrub, the encoders' mean over-read ``E|N(0, S)| = 0.798 S``.

    python benchmarks/turn_over_read.py [--slip 0.05]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mjswarm.arena import load_arena  # noqa: E402
from mjswarm.experiments.embodied import EmbodiedConfig  # noqa: E402
from mjswarm.experiments.exploration import EmbodiedExploration  # noqa: E402
from mjswarm.experiments.minds import make_minds  # noqa: E402
from mjswarm.worlds.navigation import TURN_OVER_READ  # noqa: E402


def over_reads(physics: str, speed_m_s: float, slip: float) -> tuple[list[float], list[float]]:
    """Each robot's effective track over its model's, and its distance scale, at the end."""
    config = EmbodiedConfig(physics=physics, speed_m_s=speed_m_s, wheel_slip=slip)
    run = EmbodiedExploration(load_arena("arena2"), make_minds("incidence-dfs", 4, 0), config, 0)
    run.run()
    odometries = [robot.nav.odometry for robot in run.robots]
    return ([o.track_m / o.cal.track_m for o in odometries],
            [o.distance_scale for o in odometries])


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--slip", type=float, default=0.05, help="the slip runs' --wheel-slip")
    args = parser.parse_args()
    print("tier       speed (m/s)  slip   effective track / model's   distance scale   "
          "(shipped scrub)")
    for physics in ("dynamic", "kinematic"):
        for speed, slip in ((0.05, 0.0), (0.2, 0.0), (0.05, args.slip)):
            tracks, scales = over_reads(physics, speed, slip)
            expected = f", slip alone {1.0 + slip * math.sqrt(2.0 / math.pi):.4f}" if slip else ""
            print(f"{physics:10s} {speed:11.2f}  {slip:4.2f}   "
                  f"{' '.join(f'{t:.4f}' for t in tracks):26s}  "
                  f"{' '.join(f'{s:.4f}' for s in scales):15s}  "
                  f"({TURN_OVER_READ[physics]}{expected})")
