"""``mjswarm sweep``: a grid of exploration runs in parallel, resumable."""

from __future__ import annotations

import sys

from tqdm import tqdm

from mjswarm.cli.numbers import check_number, whole
from mjswarm.errors import MjswarmError


#: Most values one list option may expand to.
MAX_LIST = 10_000


def _ints(text: str, what: str) -> list[int]:
    """``1,2,5`` or ``0-9`` or a mix: ``0-3,7``; at most MAX_LIST values."""
    values: list[int] = []
    try:
        for part in text.split(","):
            if "-" in part.strip()[1:]:
                lo, hi = (int(x) for x in part.split("-", 1))
                if hi < lo:
                    raise MjswarmError(f"{what}: the range {lo}-{hi} is reversed "
                                       f"(write {hi}-{lo})")
                if hi - lo + 1 > MAX_LIST:
                    raise MjswarmError(f"{what}: the range {lo}-{hi} has more than "
                                       f"{MAX_LIST} values")
                values.extend(range(lo, hi + 1))
            elif part.strip():
                values.append(int(part))
    except ValueError:
        raise MjswarmError(f"{what} takes whole numbers like 1,2,5 or 0-9, got '{text}'") from None
    return values


def _floats(text: str | None, what: str) -> list[float | None]:
    """``0.7,1,1.5`` (metres); no option: ``[None]`` (no radio)."""
    if text is None:
        return [None]
    try:
        return [float(part) for part in text.split(",") if part.strip()]
    except ValueError:
        raise MjswarmError(f"{what} takes numbers like 0.7,1,1.5, got '{text}'") from None


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "sweep",
        help="run a grid of explorations in parallel (process pool or Ray)",
        description="Run every combination of arenas x robot counts x strategies x seeds in "
                    "one world and append one result per run to OUT (.jsonl or .csv). "
                    "Running the same sweep again skips the runs already in OUT.",
    )
    parser.add_argument("--world", default="graph", help="graph (default) or embodied")
    parser.add_argument("--arenas", required=True, metavar="A,B,...",
                        help="arenas: shipped names, spec files or generators, comma-separated")
    parser.add_argument("--robots", required=True, metavar="K,...", help="robot counts, e.g. 2-10")
    parser.add_argument("--strategies", default="incidence-dfs", metavar="S,...",
                        help="strategies, comma-separated (default: incidence-dfs)")
    parser.add_argument("--seeds", default="0", metavar="N,...", help="seeds, e.g. 0-29")
    parser.add_argument("--radio-ranges", default=None, metavar="M,...",
                        help="radio ranges to sweep, m, e.g. 0.7,1,1.5 (default: no radio; "
                             "embodied without a constraint: connectivity tables)")
    parser.add_argument("--connectivity", default="none", metavar="C,...",
                        help="constraints to sweep, of none, connected, biconnected "
                             "(default: none; others need --radio-ranges)")
    parser.add_argument("--out", required=True, metavar="OUT", help="results file .jsonl or .csv")
    parser.add_argument("--backend", default="local",
                        help="local (process pool, default) or ray (pip install -e '.[ray]'; "
                             "connects to RAY_ADDRESS if set)")
    parser.add_argument("--workers", action=whole(), default=None, metavar="N",
                        help="parallel workers (default: all CPUs)")
    parser.set_defaults(func=run)


def run(args) -> int:
    from mjswarm.experiments.sweep import ResultsFile, grid, sweep

    seeds = _ints(args.seeds, "--seeds")
    for seed in seeds:
        check_number("--seeds", seed, whole=True, least=0)
    cells = grid(args.world, [a for a in args.arenas.split(",") if a],
                 _ints(args.robots, "--robots"), [s for s in args.strategies.split(",") if s],
                 seeds, _floats(args.radio_ranges, "--radio-ranges"),
                 [c for c in args.connectivity.split(",") if c])
    done = ResultsFile(args.out).done()
    bar = tqdm(total=len(cells), initial=sum(c.key in done for c in cells), unit="run",
               desc="sweep", disable=None, file=sys.stderr)
    completed = 0

    def count(record: dict) -> None:
        nonlocal completed
        completed += bool(record.get("completed"))
        bar.update()

    ran, skipped = sweep(cells, args.out, args.backend, args.workers, on_result=count)
    bar.close()
    print(f"{len(cells)} runs: {ran} ran ({completed} completed), {skipped} already in {args.out}")
    return 0
