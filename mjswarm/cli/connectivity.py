"""``mjswarm connectivity``: is a static team connected / biconnected, and at what cost?"""

from __future__ import annotations

import argparse

from mjswarm.cli.numbers import number, whole
from mjswarm.cli.output import check_writable, write_json
from mjswarm.core.radio import MAX_RANGE_M
from mjswarm.experiments.connectivity import DEFAULT_MESSAGE_CAP, METHODS


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "connectivity",
        help="run a distributed biconnectivity check on a static team",
        description=(
            "Run one connectivity-awareness method on robots at fixed positions, message by "
            "message over the radio (one tick per hop), and report its verdicts and costs. "
            "stamps: Ahmadi & Stone's stamped-message check; tables: Le et al.'s "
            "connectivity tables; tables-2: their forward-two variant."
        ),
        epilog=(
            'FILE is JSON: {"positions": {"id": [x, y], ...}} in metres, optionally with '
            '"edges": [[id, id], ...] (explicit radio links; then give no --range) and '
            '"walls": [[[x1, y1], [x2, y2]], ...] (segments that block links).'
        ),
    )
    parser.add_argument("--positions", required=True, metavar="FILE", help="team file (JSON)")
    parser.add_argument(
        "--range", dest="range_m", metavar="R",
        action=number(above=0, most=MAX_RANGE_M, why="m; a longer range reaches no further"),
        help="radio range d_c in metres (required unless FILE has edges)",
    )
    parser.add_argument(
        "--method", required=True, metavar="{" + ",".join(METHODS) + "}",
        help="which method to run",
    )
    parser.add_argument(
        "--initiator", metavar="ID",
        help="robot that starts the check (stamps) or is the reference (tables); "
        "default: the file's first robot",
    )
    parser.add_argument(
        "--max-robots", action=whole(), metavar="N",
        help="N, the known maximum team size that sets the waits (default: team size)",
    )
    parser.add_argument(
        "--drop-prob", action=number(least=0), default=0.0, metavar="P",
        help="probability that a radio copy is lost (default 0, as the papers assume)",
    )
    parser.add_argument("--seed", action=whole(least=0), default=0,
                        help="seed for radio drops (default 0)")
    parser.add_argument(
        "--message-cap", action=whole(), default=DEFAULT_MESSAGE_CAP, metavar="M",
        help=f"stop after M messages and report unknown verdicts (default {DEFAULT_MESSAGE_CAP})",
    )
    parser.add_argument(
        "--json", metavar="PATH", help="write the result as JSON to PATH ('-' for stdout)"
    )
    parser.set_defaults(func=run)


def _yes_no(value: bool | None) -> str:
    return "unknown" if value is None else ("yes" if value else "no")


def run(args: argparse.Namespace) -> int:
    from mjswarm.experiments.connectivity import load_team, run_check

    check_writable(args.json, "JSON")  # before any work, not after it
    team = load_team(args.positions)
    result = run_check(
        team,
        args.method,
        range_m=args.range_m,
        initiator=args.initiator,
        max_robots=args.max_robots,
        drop_prob=args.drop_prob,
        seed=args.seed,
        message_cap=args.message_cap,
    )
    record = {"positions": args.positions, "range_m": args.range_m, **result.to_dict()}
    if write_json(record, args.json):
        return 0
    link = f"range {args.range_m} m" if args.range_m is not None else "explicit edges"
    role = "initiator" if result.method == "stamps" else "reference"
    points = result.articulation_points
    print(f"{args.positions}: {result.robots} robots, {link}; {result.method}, "
          f"{role} {result.initiator}")
    if result.capped:
        print(f"  stopped at the message cap ({args.message_cap}): verdicts unknown")
    print(f"  connected:           {_yes_no(result.connected)}")
    print(f"  biconnected:         {_yes_no(result.biconnected)}")
    if points is not None:
        print(f"  articulation points: {', '.join(points) if points else 'none'}")
    print(f"  messages:            {result.messages} (max {result.max_messages_per_robot} "
          f"by one robot; {result.deliveries} deliveries)")
    print(f"  rounds:              {result.rounds} ticks")
    return 0
