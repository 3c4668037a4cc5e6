"""``mjswarm experiment biconnected-coverage``: Ahmadi & Stone's S-coverage experiment."""

from __future__ import annotations

import argparse
import sys
import time
from contextlib import ExitStack

from tqdm import tqdm

from algorithms.maintenance.biconnected import PLACEMENTS
from mjswarm.cli.numbers import number, whole
from mjswarm.cli.output import check_outputs, check_writable, write_json
from mjswarm.cli.video_options import add_video_options, check_video
from mjswarm.cli.watch import watchers
from mjswarm.experiments.coverage import MAX_REGION_DIAMETER_M, WORLDS


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "biconnected-coverage",
        help="Ahmadi & Stone: S-coverage of a biconnected team under random add / remove",
        description=(
            "Ahmadi & Stone's experiment: robots hold circular regions of one diameter D "
            "and stay biconnected while, each episode, a random robot is removed or added "
            "(at most 10, 5 at the start). Reports S-coverage = area of the union of the "
            "regions / sum of their areas, averaged over the episodes. Region size is read "
            "as the diameter; regions are neighbours when their centres are at most "
            "(cr - 1) D apart (the radio range). Paper: 73% (cr 2), 91% (cr 4), 75% "
            "(cr 2, min-intersection)."
        ),
    )
    parser.add_argument("--cr", type=float, choices=(2.0, 4.0), required=True,
                        help="communication range / region diameter (2 or 4)")
    parser.add_argument("--placement", choices=PLACEMENTS, default="heuristic",
                        help="where an added robot goes: the paper's max-distance heuristic "
                             "(default) or the region of minimum intersection")
    parser.add_argument("--episodes", action=whole(), default=100,
                        help="random add / remove episodes (default 100)")
    parser.add_argument("--seed", action=whole(least=0), default=0, help="seed (default 0)")
    parser.add_argument("--world", choices=WORLDS, default="embodied",
                        help="embodied MuJoCo robots (default) or kinematic points (faster)")
    parser.add_argument("--region-diameter", default=1.0, metavar="M",
                        action=number(above=0.2, most=MAX_REGION_DIAMETER_M,
                                      why="m; the embodied floor reaches up to 90 D from the origin"),
                        help="region diameter D in metres, more than a robot's 0.15 m "
                             f"(default 1.0; at most {MAX_REGION_DIAMETER_M:g})")
    parser.add_argument("--json", metavar="PATH",
                        help="write the result as JSON to PATH ('-' for stdout only)")
    parser.add_argument("--record", metavar="FILE.rrd",
                        help="write a rerun recording of the run: poses and trails, each "
                             "robot's controller state, the radio graph, events")
    add_video_options(parser)
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from mjswarm.experiments.coverage import MAX_ROBOTS, area, run_coverage

    check_writable(args.json, "JSON")  # before any work, not after it
    check_writable(args.record, "recording")
    check_outputs({"--record": args.record, "--video": args.video, "--json": args.json},
                  {"--record": ".rrd"})
    speedup = check_video(args)
    start = time.perf_counter()
    with ExitStack() as outputs:
        functions = watchers(outputs, args, robots=MAX_ROBOTS,
                             bounds_m=area(args.cr, args.region_diameter),
                             name=f"biconnected coverage, cr {args.cr:g}, {args.world} world",
                             title=f"coverage, cr {args.cr:g}", speedup=speedup)
        bar = outputs.enter_context(tqdm(total=args.episodes, desc="episodes", unit="ep",
                                         file=sys.stderr, disable=not sys.stderr.isatty()))
        result = run_coverage(args.cr, args.placement, args.episodes, args.seed, args.world,
                              args.region_diameter, progress=bar.update, functions=functions)
    data = result.to_dict()
    data["wall_time_s"] = round(time.perf_counter() - start, 2)
    if write_json(data, args.json):
        return 0
    paper = data["paper_mean_coverage"]
    paper_text = f" (paper: {paper:.0%})" if paper is not None else ""
    adds = sum(e.action == "add" for e in result.episodes)
    print(f"cr {args.cr:g}, {args.placement} placement, {args.world} world, seed {args.seed}: "
          f"mean S-coverage {result.mean_coverage:.1%}{paper_text} over {args.episodes} "
          f"episodes ({adds} adds, {args.episodes - adds} removes)")
    print(f"simulated {result.sim_time_s:.0f} s in {data['wall_time_s']:.1f} s wall"
          + (f", {result.collisions} robot contacts" if result.collisions is not None else ""))
    return 0
