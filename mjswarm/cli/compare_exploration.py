"""``mjswarm compare exploration``: Nagavarapu et al.'s Fig. 8, Fig. 17 and 4 x 4 lattice
comparisons (:mod:`mjswarm.experiments.exploration_compare`)."""

from __future__ import annotations

from pathlib import Path

from mjswarm.cli.numbers import whole
from mjswarm.cli.output import check_directory
from mjswarm.errors import MjswarmError


#: Where the comparison goes without ``--out``.
DEFAULT_OUT = "out/compare_exploration"


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "exploration",
        help="Nagavarapu et al.'s Figs. 8 and 17 and the 4x4 lattice: their incidence-matrix "
             "exploration vs MR-DFS, BFS, LRV",
        description=(
            "Rerun Nagavarapu, Vachhani & Sinha's exploration comparisons in the graph world "
            "(unit edge time): Fig. 8 (trees tree1..tree4, K = 2..10, their proposed "
            "incidence-matrix method vs MR-DFS), Fig. 17 "
            "(lattice:10x10, K = 1..20, proposed vs BFS, LRV, MR-DFS) and the 4x4 lattice "
            "with 5 robots from the corner and from the vertex next to it. Each setting runs "
            "with fixed tie rules and with SEEDS random tie-breakings. Writes results.md, "
            "results.json, fig8.png and fig17.png."
        ),
    )
    parser.add_argument("--out", default=None, metavar="DIR",
                        help="output directory, made if its parent exists (default: "
                             f"{DEFAULT_OUT}, made with its parents)")
    parser.add_argument("--seeds", action=whole(least=0), default=10, metavar="N",
                        help="random tie-breaking runs per setting, besides the fixed rules "
                             "(default: 10)")
    parser.add_argument("--quick", action="store_true",
                        help="only a few robot counts per panel (for a smoke test)")
    parser.set_defaults(func=run)


def run(args) -> int:
    from mjswarm.experiments.exploration_compare import run_comparison, write_report

    check_directory(args.out, "the comparison")
    rows = run_comparison(quick=args.quick, seeds=args.seeds)
    out_dir = Path(args.out or DEFAULT_OUT)
    try:
        written = write_report(rows, out_dir, args.seeds)
    except OSError as exc:
        raise MjswarmError(f"cannot write to {out_dir}: {exc.strerror}") from None
    print((out_dir / "results.md").read_text(), end="")
    print("wrote " + ", ".join(str(p) for p in written))
    failures = sum(r.failures for r in rows)
    return 1 if failures else 0
