"""How much a robot's scans over-read a turn in place, by physics tier and wheel slip.

Runs the main job (``arena2``, 4 robots, seed 0) noise-free in both physics tiers at 0.05
and 0.2 m/s, and with ``--wheel-slip`` in each tier at 0.05 m/s, and prints every robot's
effective track over its model's (:meth:`algorithms.navigation.odometry.Odometry.calibrate`:
the average of its scans' full-turn readings over 2 pi) and the distance scale it took.
Noise-free, the quotient is the floor's scrub, what
:data:`mjswarm.worlds.navigation.TURN_OVER_READ` holds per tier; with slip S, beyond the
scrub, the encoders' mean over-read ``E|N(0, S)| = 0.798 S``. Then, with line noise and no
slip, the spread of single scans' over-reads beyond the scrub (every scan of every robot,
``arena2`` and ``hex:2x2@30`` at 0.2 m/s in both tiers): what
:data:`algorithms.navigation.odometry.SCAN_OVER_READ_SPREAD` must cover.

    python benchmarks/turn_over_read.py [--slip 0.05] [--line-noise 0.0005]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from mjswarm.arena import load_arena  # noqa: E402
from mjswarm.experiments.embodied import EmbodiedConfig  # noqa: E402
from mjswarm.experiments.exploration import EmbodiedExploration  # noqa: E402
from mjswarm.experiments.minds import make_minds  # noqa: E402
from mjswarm.worlds.navigation import TURN_OVER_READ  # noqa: E402


def explored(arena: str, physics: str, speed_m_s: float, **noise: float) -> list:
    """The robots (explorers) of one finished exploration with 4 robots, seed 0."""
    config = EmbodiedConfig(physics=physics, speed_m_s=speed_m_s, **noise)
    run = EmbodiedExploration(load_arena(arena), make_minds("incidence-dfs", 4, 0), config, 0)
    run.run()
    return run.robots


def over_reads(physics: str, speed_m_s: float, slip: float) -> tuple[list[float], list[float]]:
    """Each robot's effective track over its model's, and its distance scale, at the end."""
    odometries = [r.nav.odometry for r in explored("arena2", physics, speed_m_s, wheel_slip=slip)]
    return ([o.track_m / o.cal.track_m for o in odometries],
            [o.distance_scale for o in odometries])


def scan_over_reads(line_noise_m: float) -> list[float]:
    """Every single scan's over-read beyond the scrub (a fraction), with line noise."""
    out = []
    for arena in ("arena2", "hex:2x2@30"):
        for physics in ("dynamic", "kinematic"):
            for robot in explored(arena, physics, 0.2, line_noise_m=line_noise_m):
                cal = robot.nav.odometry.cal
                out += [t / (cal.track_m * cal.turn_over_read) - 1.0 for t in robot.nav._tracks]
    return out


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--slip", type=float, default=0.05, help="the slip runs' --wheel-slip")
    parser.add_argument("--line-noise", type=float, default=0.0005,
                        help="the line-noise runs' --line-noise (m)")
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
    scans = np.array(scan_over_reads(args.line_noise))
    print(f"line noise {args.line_noise} m, no slip: {len(scans)} scans, over-read beyond the "
          f"scrub {100 * scans.mean():+.2f} % mean, {100 * scans.std():.2f} % standard "
          f"deviation, {100 * scans.min():+.2f} % to {100 * scans.max():+.2f} %")
