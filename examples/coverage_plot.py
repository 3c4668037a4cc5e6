"""Run one experiment from Python and plot its result.

Ahmadi & Stone's S-coverage experiment (biconnected add / remove) on kinematic points, for both
communication ranges the paper reports, plotted episode by episode against the paper's
means.

    python examples/coverage_plot.py              # 40 episodes, recordings/coverage.png
    python examples/coverage_plot.py --episodes 100 --world embodied --out cov.pdf

It runs from any directory: the default picture goes to the repository's recordings/
folder; a relative ``--out`` is taken from the current directory.
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402

from mjswarm.experiments.coverage import PAPER_COVERAGE, run_coverage  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--episodes", type=int, default=40)
parser.add_argument("--world", choices=("point", "embodied"), default="point")
parser.add_argument("--seed", type=int, default=0)
parser.add_argument("--out", default=str(Path(__file__).resolve().parents[1] / "recordings"
                                         / "coverage.png"),
                    help="the picture to write (.png, .svg, .pdf; default: recordings/"
                         "coverage.png in the repository)")
args = parser.parse_args()

fig, ax = plt.subplots(figsize=(7, 4))
for cr, color in ((2.0, "tab:blue"), (4.0, "tab:orange")):
    result = run_coverage(cr, "heuristic", args.episodes, args.seed, args.world)
    episodes = [e for e in result.episodes if e.coverage is not None]
    ax.plot([e.index + 1 for e in episodes], [100 * e.coverage for e in episodes],
            color=color, marker=".", label=f"cr = {cr:g}: mean {result.mean_coverage:.1%}")
    ax.axhline(PAPER_COVERAGE[(cr, "heuristic")], color=color, linestyle="--",
               label=f"cr = {cr:g}: paper {PAPER_COVERAGE[(cr, 'heuristic')]:.0f}%")
    print(f"cr {cr:g}: mean S-coverage {result.mean_coverage:.1%} over {args.episodes} episodes")
ax.set_xlabel("episode")
ax.set_ylabel("S-coverage (%)")
ax.set_title(f"Biconnected add / remove (Ahmadi & Stone), {args.world} world, seed {args.seed}")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(args.out)
print(f"plot: {args.out}")
