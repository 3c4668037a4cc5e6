"""``mjswarm compare connectivity``: messages against team size for the three methods."""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict

from tqdm import tqdm

from mjswarm.cli.numbers import number, whole
from mjswarm.cli.output import check_directory, check_writable, write_json
from mjswarm.errors import MjswarmError

#: Where the comparison goes without ``--out``.
DEFAULT_OUT = "out/compare_connectivity"


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "connectivity",
        help="messages vs team size: Ahmadi & Stone's stamps against Le et al.'s tables",
        description=(
            "Count the messages each connectivity method needs to reach its verdict for "
            "team sizes n_min..n_max on random geometric teams, sparse ring teams and "
            "complete graphs (the stamps worst case), check the verdicts against networkx, "
            "and write "
            "messages.csv, messages.md and messages.png."
        ),
    )
    parser.add_argument("--out", default=None, metavar="DIR",
                        help="output directory, made if its parent exists (default: "
                             f"{DEFAULT_OUT}, made with its parents)")
    parser.add_argument("--n-min", action=whole(), default=3, help="smallest team (default 3)")
    parser.add_argument("--n-max", action=whole(), default=30,
                        help="largest team (default 30)")
    parser.add_argument("--n-step", action=whole(), default=3,
                        help="team size step (default 3)")
    parser.add_argument("--samples", action=whole(), default=5,
                        help="random teams per size and family (default 5)")
    parser.add_argument("--mean-degree", action=number(above=0), default=4.0,
                        help="target mean number of radio neighbours (default 4)")
    parser.add_argument("--seed", action=whole(least=0), default=0,
                        help="seed for the teams (default 0)")
    parser.add_argument("--message-cap", action=whole(), default=100_000, metavar="M",
                        help="stop a run after M messages, counted as capped (default 100000)")
    parser.add_argument("--json", metavar="PATH",
                        help="also write the rows as JSON to PATH ('-' for stdout only)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from mjswarm.experiments.connectivity.comparison import (
        FAMILIES,
        compare_messages,
        markdown_table,
        write_outputs,
    )

    check_writable(args.json, "JSON")  # before any work, not after it
    check_directory(args.out, "the comparison")
    if args.n_min > args.n_max:
        raise MjswarmError("need --n-min <= --n-max")
    ns = list(range(args.n_min, args.n_max + 1, args.n_step))
    total = len(ns) * (args.samples * (len(FAMILIES) - 1) + 1)
    with tqdm(total=total, desc="teams", unit="team", file=sys.stderr,
              disable=not sys.stderr.isatty()) as bar:
        rows = compare_messages(
            ns,
            samples=args.samples,
            mean_degree=args.mean_degree,
            seed=args.seed,
            message_cap=args.message_cap,
            progress=bar.update,
        )
    paths = write_outputs(rows, args.out or DEFAULT_OUT)
    records = [asdict(r) for r in rows]
    if write_json(records, args.json):
        return 0
    print(markdown_table(rows))
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0
