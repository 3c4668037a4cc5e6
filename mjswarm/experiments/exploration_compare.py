"""Nagavarapu et al.'s exploration comparisons (section 6), rerun in the graph world.

* Fig. 8: the four 12-edge trees ``tree1``..``tree4``, K = 2..10, proposed vs MR-DFS.
* Fig. 17: the 10 x 10 lattice (100 vertices, 180 edges), K = 1..20, proposed vs BFS, LRV
  and MR-DFS.
* The 4 x 4 lattice with 5 robots (paper: proposed 11, MR-DFS 16). The paper does not say
  where the robots start; we run from the corner ``v0_0`` and from the boundary vertex
  next to it, ``v0_1``.

The paper reports the worst case over "the division of robots along edges". Each setting
is run once with the strategies' fixed tie rules (``canonical``) and once per seed with
random tie-breaking; ``worst`` is the largest makespan of all those runs, ``mean`` the mean.
Makespans are in steps (unit edge time), i.e. the paper's "number of edge traversals".
"""

from __future__ import annotations

import json
import sys
from dataclasses import asdict, dataclass
from pathlib import Path
from statistics import mean

from tqdm import tqdm

from mjswarm.arena import load_arena
from mjswarm.experiments.graph_exploration import explore_world
from mjswarm.worlds.graphworld import GraphWorld

#: Display names of the strategies.
LABELS = {
    "incidence-dfs": "proposed",
    "mr-dfs": "MR-DFS",
    "bfs": "BFS",
    "lrv": "LRV",
    "flooding": "flooding",
}

@dataclass(frozen=True)
class Setting:
    """One panel of a comparison: an arena and start vertex, strategies, robot counts."""

    figure: str
    arena: str
    root: str | None
    strategies: tuple[str, ...]
    robots: tuple[int, ...]


@dataclass
class Row:
    """Makespans (steps) of one strategy with K robots in one setting."""

    figure: str
    arena: str
    root: str
    edges: int
    strategy: str
    robots: int
    canonical: int | None
    worst: int | None
    mean: float | None
    runs: int
    failures: int


def settings(quick: bool = False) -> list[Setting]:
    """The comparisons; ``quick`` keeps every panel but only a few robot counts."""
    fig8_k = (2, 4) if quick else tuple(range(2, 11))
    fig17_k = (1, 10) if quick else tuple(range(1, 21))
    return [
        *(Setting("fig8", f"tree{i}", None, ("incidence-dfs", "mr-dfs"), fig8_k)
          for i in range(1, 5)),
        Setting("fig17", "lattice:10x10", None, ("incidence-dfs", "bfs", "lrv", "mr-dfs"), fig17_k),
        *(Setting("lattice4x4", "lattice:4x4", root, ("incidence-dfs", "mr-dfs"), (5,))
          for root in ("v0_0", "v0_1")),
    ]


def run_comparison(quick: bool = False, seeds: int = 10, progress: bool = True) -> list[Row]:
    """Run every setting with the canonical tie rules and with seeds ``0..seeds-1``."""
    plan = settings(quick)
    total = sum(len(s.strategies) * len(s.robots) * (1 + seeds) for s in plan)
    rows = []
    with tqdm(total=total, desc="compare exploration", unit="run", file=sys.stderr,
              disable=None if progress else True) as bar:
        for setting in plan:
            spec = load_arena(setting.arena)
            world = GraphWorld(spec.graph(), setting.root or spec.root)
            for strategy in setting.strategies:
                for k in setting.robots:
                    results = [
                        explore_world(world, k, strategy, seed=seed, arena=spec.name)
                        for seed in (None, *range(seeds))
                    ]
                    bar.update(len(results))
                    ok = [r.makespan for r in results if r.completed and r.map_correct]
                    rows.append(Row(
                        figure=setting.figure, arena=spec.name, root=world.root,
                        edges=len(spec.edges), strategy=strategy, robots=k,
                        canonical=results[0].makespan if results[0].map_correct else None,
                        worst=max(ok) if len(ok) == len(results) else None,
                        mean=mean(ok) if ok else None,
                        runs=len(results), failures=len(results) - len(ok),
                    ))
    return rows


def markdown(rows: list[Row], seeds: int) -> str:
    """Tables, one per figure: each cell is ``canonical (worst)`` makespan in steps."""
    lines = [
        "# Nagavarapu et al. exploration comparisons (graph world, unit edge time)",
        "",
        "Cells: makespan in steps with the fixed tie rules, and in parentheses the worst "
        + f"over those and {seeds} seeded random tie-breakings. '-' marks a failed run.",
    ]
    titles = {
        "fig8": "Fig. 8: trees with 12 edges, proposed vs MR-DFS (Prop. 2: proposed <= E = 12)",
        "fig17": "Fig. 17: 10 x 10 lattice (100 vertices, 180 edges)",
        "lattice4x4": "4 x 4 lattice, 5 robots (paper: proposed 11, MR-DFS 16; start not given)",
    }
    for figure, title in titles.items():
        panel = [r for r in rows if r.figure == figure]
        if not panel:
            continue
        strategies = list(dict.fromkeys(r.strategy for r in panel))
        lines += ["", f"## {title}", "",
                  "| arena | root | K | " + " | ".join(LABELS[s] for s in strategies) + " |",
                  "|---|---|---|" + "---|" * len(strategies)]
        keys = list(dict.fromkeys((r.arena, r.root, r.robots) for r in panel))
        cell = {(r.arena, r.root, r.robots, r.strategy): r for r in panel}
        for arena, root, k in keys:
            cells = []
            for s in strategies:
                r = cell[(arena, root, k, s)]
                cells.append(f"{_num(r.canonical)} ({_num(r.worst)})")
            lines.append(f"| {arena} | {root} | {k} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _num(x) -> str:
    return "-" if x is None else str(x)


def plot(rows: list[Row], out_dir: Path) -> list[Path]:
    """``fig8.png`` (one panel per tree) and ``fig17.png``: worst (solid) and canonical
    (dashed) makespan against the number of robots."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    written = []
    trees = list(dict.fromkeys(r.arena for r in rows if r.figure == "fig8"))
    if trees:
        fig, axes = plt.subplots(2, 2, figsize=(9, 7), sharey=True)
        for ax, tree in zip(axes.flat, trees, strict=False):
            panel = [r for r in rows if r.figure == "fig8" and r.arena == tree]
            _lines(ax, panel)
            ax.axhline(panel[0].edges, color="grey", lw=0.8, ls=":", label="E")
            ax.set_title(tree)
        axes.flat[0].legend(fontsize=8)
        fig.suptitle("Nagavarapu et al. Fig. 8: edge traversals to complete, trees with 12 edges")
        written.append(_save(fig, out_dir / "fig8.png"))
    panel = [r for r in rows if r.figure == "fig17"]
    if panel:
        fig, ax = plt.subplots(figsize=(7, 5))
        _lines(ax, panel)
        ax.legend(fontsize=8)
        ax.set_title("Nagavarapu et al. Fig. 17: 10 x 10 lattice")
        written.append(_save(fig, out_dir / "fig17.png"))
    return written


def _lines(ax, panel: list[Row]) -> None:
    from matplotlib.ticker import MaxNLocator

    for strategy in dict.fromkeys(r.strategy for r in panel):
        mine = [r for r in panel if r.strategy == strategy]
        k = [r.robots for r in mine]
        line, = ax.plot(k, [r.worst for r in mine], marker="o", ms=3, label=f"{LABELS[strategy]} (worst)")
        ax.plot(k, [r.canonical for r in mine], ls="--", color=line.get_color(), lw=0.8)
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("robots K")
    ax.set_ylabel("makespan (steps; dashed: fixed tie rules)")
    ax.grid(alpha=0.3)


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return path


def write_report(rows: list[Row], out_dir: Path, seeds: int) -> list[Path]:
    """Write ``results.md``, ``results.json`` and the PNG plots into ``out_dir``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    table = out_dir / "results.md"
    table.write_text(markdown(rows, seeds))
    data = out_dir / "results.json"
    data.write_text(json.dumps({"seeds": seeds, "rows": [asdict(r) for r in rows]}, indent=2) + "\n")
    return [table, data, *plot(rows, out_dir)]
