"""``mjswarm bench``: full step vs bare ``mj_step``, per robot count."""

from __future__ import annotations

import json
import platform
import sys

from tqdm import tqdm

from mjswarm.cli.numbers import number
from mjswarm.core import PHYSICS
from mjswarm.errors import MjswarmError


#: Longest measurement (simulated s): a rate settles within seconds; the default is 2.
MAX_SECONDS = 3600.0


def _counts(text: str) -> list[int]:
    """``--robots``: robot counts from 1 to the largest team any run takes."""
    from mjswarm.experiments.minds import MAX_ROBOTS

    try:
        counts = [int(part) for part in text.split(",") if part.strip()]
    except ValueError:
        raise MjswarmError(f"--robots takes comma-separated whole numbers, got '{text}'") from None
    if not counts or min(counts) < 1:
        raise MjswarmError(f"--robots needs counts >= 1, got '{text}'")
    if max(counts) > MAX_ROBOTS:
        raise MjswarmError(f"--robots takes counts up to {MAX_ROBOTS} (the largest team any "
                           f"run takes), got {max(counts)}")
    return counts


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "bench",
        help="measure the full step against bare mj_step",
        description=(
            "Drive N robots on a floor with strips and walls, each with every sensor (line, IR, "
            "encoders, bearing sensor), a radio (1 m, line of sight, a heartbeat per tick) and "
            "Nagavarapu et al.'s bearing-rate speed rule over a line follower, and report simulated seconds per "
            "wall second for this full loop and for bare mj_step on the same world, and their "
            "ratio (overhead_ratio = full wall time / bare wall time)."
        ),
    )
    parser.add_argument("--robots", default="1,10,100,300", metavar="N,N,...",
                        help="robot counts to measure (default: 1,10,100,300)")
    parser.add_argument("--seconds", action=number(above=0, most=MAX_SECONDS,
                                                  why="a rate settles within seconds"),
                        default=2.0, metavar="S",
                        help="simulated seconds per measurement (default: 2.0)")
    parser.add_argument("--model", default=None, metavar="MJCF",
                        help="robot model file (default: models/spark_v.xml)")
    parser.add_argument("--sensing", choices=("auto", "grid", "mujoco"), default="auto",
                        help="rangefinder implementation: O(N) grid ray casting, MuJoCo's own "
                             "sensors (O(N^2)), or auto (grid from 32 robots; default)")
    parser.add_argument("--physics", choices=PHYSICS, default="dynamic",
                        help="the full loop's physics tier: dynamic (MuJoCo's contact physics; "
                             "default) or kinematic (wheel kinematics, stop at contacts); bare "
                             "mj_step is dynamic in both, so the ratio says what the tier saves")
    parser.add_argument("--per-robot", action="store_true",
                        help="step one controller per robot (observations and commands one by "
                             "one) instead of the batched team (arrays; default): the same run")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.set_defaults(func=run)


def run(args) -> int:
    from mjswarm.experiments.bench import as_dict, run_bench
    from mjswarm.core.robot import DEFAULT_ROBOT_XML, load_robot_spec

    counts = _counts(args.robots)
    model = args.model or str(DEFAULT_ROBOT_XML)
    load_robot_spec(model)  # fail with one line before any progress bar
    results = [
        as_dict(run_bench(n, args.seconds, model, args.sensing, physics=args.physics,
                          batched=not args.per_robot))
        for n in tqdm(counts, desc="bench", unit="world", disable=None, file=sys.stderr)
    ]
    if args.json:
        print(json.dumps({"machine": _machine(), "results": results}, indent=2))
        return 0
    print(f"machine: {_machine()}")
    print(f"{'robots':>7} {'physics':>9} {'sensing':>8} {'realtime':>10} {'physics-only':>13} {'overhead':>9} "
          f"{'robot-steps/s':>14}")
    for r in results:
        print(f"{r['robots']:>7} {r['physics']:>9} {r['sensing']:>8} {r['realtime_factor']:>9.2f}x "
              f"{r['physics_only_realtime_factor']:>12.2f}x {r['overhead_ratio']:>9.2f} "
              f"{r['robot_steps_per_s']:>14.0f}")
    return 0


def _machine() -> str:
    import os

    import mujoco

    return (f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
            f"Python {platform.python_version()}, MuJoCo {mujoco.__version__}")
