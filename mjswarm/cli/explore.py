"""``mjswarm explore``: run one exploration and report seed 003's metrics.

Worlds: ``graph`` (the fast abstract graph world, :mod:`mjswarm.graphworld`). Each world is
a function ``run_<world>(args) -> dict`` registered in :data:`WORLDS`.
"""

from __future__ import annotations

import json
from pathlib import Path

from algorithms.exploration import STRATEGIES
from mjswarm.errors import MjswarmError
from mjswarm.graphworld import EDGE_TIMES, GraphWorld


def run_graph(args) -> dict:
    """One run in the graph world; the JSON-ready result (see ``ExplorationResult``)."""
    from mjswarm.arena import load_arena

    spec = load_arena(args.arena)
    world = GraphWorld(spec.graph(), args.root or spec.root, edge_time=args.edge_time)
    result = world.explore(
        args.robots, args.strategy, seed=args.seed, max_time=args.max_time, arena=spec.name
    )
    return {"world": "graph", **result.to_dict()}


#: World name -> runner.
WORLDS = {"graph": run_graph}


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "explore",
        help="explore an arena with K robots and report makespan, traversals and the map",
        description=(
            "Explore an arena from its root with K robots running one strategy and report "
            "seed 003's metrics: makespan (time steps until a robot declares completion; "
            "with unit edge time, the paper's number of edge traversals), total and "
            "per-robot traversals, who declared where, and the declaring robot's map. "
            "Exit status 1 if no robot declared completion before --max-time."
        ),
    )
    parser.add_argument("--world", default="graph", metavar="WORLD",
                        help=f"simulation world: {', '.join(WORLDS)} (default: graph)")
    parser.add_argument("--arena", required=True, metavar="ARENA",
                        help="shipped arena name (e.g. fig9, tree1, arena2), path to a "
                             ".json/.toml spec, or generator (lattice:RxC, "
                             "random-tree:E:SEED, random-graph:V:E:SEED)")
    parser.add_argument("--robots", type=int, required=True, metavar="K",
                        help="number of robots, all starting at the root")
    parser.add_argument("--strategy", default="incidence-dfs", metavar="NAME",
                        help=f"one of {', '.join(STRATEGIES)} (default: incidence-dfs, "
                             "seed 003's method)")
    parser.add_argument("--root", default=None, metavar="VERTEX",
                        help="start vertex (default: the arena's root)")
    parser.add_argument("--seed", type=int, default=None, metavar="S",
                        help="randomise tie-breaking with this seed (default: the "
                             "strategies' fixed tie rules)")
    parser.add_argument("--edge-time", default="unit", choices=EDGE_TIMES,
                        help="time to traverse an edge: 'unit' (1 step each, as in the "
                             "paper) or 'length' (length / mean edge length) (default: unit)")
    parser.add_argument("--max-time", type=float, default=None, metavar="T",
                        help="give up after T time units (default: 50 (E + 1) + 100)")
    parser.add_argument("--json", default=None, metavar="PATH|-",
                        help="write the result as JSON to PATH, or to stdout with '-'")
    parser.set_defaults(func=run)


def run(args) -> int:
    if args.world not in WORLDS:
        raise MjswarmError(f"unknown world '{args.world}' (choose from {', '.join(WORLDS)})")
    result = WORLDS[args.world](args)
    text = json.dumps(result, indent=2)
    if args.json == "-":
        print(text)
        return 0 if result["completed"] else 1
    if args.json:
        try:
            Path(args.json).write_text(text + "\n")
        except OSError as exc:
            raise MjswarmError(f"cannot write {args.json}: {exc.strerror}") from None
    print(summary(result))
    return 0 if result["completed"] else 1


def summary(result: dict) -> str:
    """Human-readable lines for one run."""
    head = (f"{result['arena']}: {result['robots']} robot(s), {result['strategy']}, "
            f"{result['world']} world, root {result['root']}")
    if not result["completed"]:
        return f"{head}\nnot completed: no robot declared completion in time"
    per_robot = " ".join(f"R{i + 1}={n}" for i, n in enumerate(result["traversals_per_robot"]))
    verdict = "equal to" if result["map_correct"] else "DIFFERENT from"
    return "\n".join([
        head,
        f"completed: R{result['declared_by']} declared at {result['declared_at']} after "
        + f"{result['makespan']} steps",
        f"traversals: {result['total_traversals']} in total ({per_robot})",
        f"map: {len(result['map_edges'])} edges, {verdict} the arena's",
    ])
