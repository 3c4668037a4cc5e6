"""``mjswarm experiment patrol``: Kobayashi et al.'s patrol mission with role switching."""

from __future__ import annotations

import argparse
import sys
from contextlib import ExitStack

from tqdm import tqdm

from mjswarm.cli.numbers import whole
from mjswarm.cli.output import check_outputs, check_writable, write_json
from mjswarm.cli.video_options import add_video_options, check_video
from mjswarm.cli.watch import watchers
from mjswarm.errors import MjswarmError
from mjswarm.experiments.patrol import MAX_ROBOTS, MIN_ROBOTS, STEP_S, WORLDS


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "patrol",
        help="Kobayashi et al.: patrol mission keeping the swarm connected to a base station",
        description=(
            "Kobayashi, Higuchi & Ueno's patrol: a base station at the origin, a local "
            "leader led to random targets in [0, 1.8 sqrt(N)]^2 m, explorers flocking "
            "around it, repeaters deployed and collected by role switching (Algorithm 1), "
            "connections by the Acute Angle Test with Algorithm 2. 1 paper unit = 1 m, "
            f"1 timestep = {STEP_S} s (0.03 m/step = 0.2 m/s), d_c = 3 m. Reports "
            "disconnections per trial, mean recovery steps, processing time and messages "
            "per robot per step, algebraic connectivity, and the AAT's cost with Algorithm "
            "2 against the every-step baseline run on the same positions. The embodied "
            "world simulates 300 s per 2000-step trial in MuJoCo; --world point is the "
            "fast kinematic world."
        ),
    )
    parser.add_argument("--robots", default=10, metavar="N",
                        action=whole(least=MIN_ROBOTS, most=MAX_ROBOTS,
                                     why="a step's cost grows as N squared"),
                        help=f"swarm size N including the base station, {MIN_ROBOTS} to "
                             f"{MAX_ROBOTS} (default 10)")
    parser.add_argument("--trials", action=whole(), default=1,
                        help="missions, seeds S..S+T-1 (default 1; the paper ran 30)")
    parser.add_argument("--seed", action=whole(least=0), default=0,
                        help="first seed (default 0)")
    parser.add_argument("--steps", action=whole(), default=2000,
                        help=f"timesteps per mission, {STEP_S} s each (default 2000)")
    parser.add_argument("--world", choices=WORLDS, default="embodied",
                        help="embodied MuJoCo robots (default) or kinematic points (faster)")
    parser.add_argument("--aat", choices=("alg2", "every-step"), default="alg2",
                        help="drive connections by Algorithm 2 (default) or by the every-step "
                             "baseline")
    parser.add_argument("--json", metavar="PATH",
                        help="write the result as JSON to PATH ('-' for stdout only)")
    parser.add_argument("--record", metavar="FILE.rrd",
                        help="write a rerun recording of the run: poses and trails, each "
                             "robot's controller state, the radio graph, events"
                             " (one trial only)")
    add_video_options(parser)
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from mjswarm.experiments.patrol import area, run_patrol

    check_writable(args.json, "JSON")  # before any work, not after it
    check_writable(args.record, "recording")
    check_outputs({"--record": args.record, "--video": args.video, "--json": args.json},
                  {"--record": ".rrd"})
    speedup = check_video(args)
    if (args.record or args.video) and args.trials != 1:
        raise MjswarmError(f"--record and --video hold one mission; drop --trials {args.trials}")
    with ExitStack() as outputs:
        functions = watchers(outputs, args, robots=args.robots, bounds_m=area(args.robots),
                             name=f"patrol, N = {args.robots}, {args.world} world",
                             title=f"patrol, N = {args.robots}", speedup=speedup)
        bar = outputs.enter_context(tqdm(total=args.trials * args.steps, desc="steps",
                                         unit="step", file=sys.stderr,
                                         disable=not sys.stderr.isatty()))
        result = run_patrol(args.robots, args.trials, args.seed, args.world, args.steps,
                            every_step_aat=args.aat == "every-step", progress=bar.update,
                            functions=functions)
    if write_json(result, args.json):
        return 0
    alg2, base = result["aat_robots"], result["aat_every_step"]  # robots' AAT, shadow
    recovery = result["mean_recovery_steps"]
    rows = [
        ("disconnections per trial", f"{result['disconnections_per_trial']:.2f}"),
        ("mean recovery (steps)", "-" if recovery is None else f"{recovery:.1f}"),
        ("longest recovery (steps)", f"{result['max_recovery_steps']}"),
        ("leader gaps per trial (longest, steps)",
         f"{result['leader_gaps_per_trial']:.2f} ({result['max_leader_gap_steps']})"),
        ("targets reached per trial", f"{result['targets_per_trial']:.1f}"),
        ("processing time per robot per step (ms)",
         f"{1e3 * result['processing_s_per_robot_step']:.3f}"),
        ("messages received per robot per step", f"{result['messages_per_robot_step']:.2f}"),
        ("algebraic connectivity (network)", f"{result['algebraic_connectivity']:.3f}"),
        (f"AAT angle tests per robot per step: {args.aat} / every-step",
         f"{alg2['angle_tests_per_robot_step']:.1f} / {base['angle_tests_per_robot_step']:.1f}"),
        (f"AAT circle tests per robot per step ({args.aat})",
         f"{alg2['circle_tests_per_robot_step']:.1f}"),
        (f"AAT time per robot per step (ms): {args.aat} / every-step",
         f"{1e3 * alg2['seconds_per_robot_step']:.3f} / "
         + f"{1e3 * base['seconds_per_robot_step']:.3f}"),
        (f"algebraic connectivity, leader+explorers: {args.aat} / every-step",
         f"{alg2['algebraic_connectivity']:.3f} / {base['algebraic_connectivity']:.3f}"),
    ]
    if result["collisions_per_trial"] is not None:
        rows.append(("robot contacts per trial", f"{result['collisions_per_trial']:.1f}"))
    print(f"patrol: N = {result['robots']}, {result['trials']} trial(s) x {result['steps']} "
          f"steps, {result['world']} world, AAT {args.aat}, {result['wall_s']:.1f} s wall")
    width = max(len(name) for name, _ in rows)
    for name, value in rows:
        print(f"  {name:<{width}}  {value}")
    return 0
