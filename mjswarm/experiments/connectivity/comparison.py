"""Messages against team size for the three methods (Ahmadi & Stone vs Le et al.).

The papers' claims: the stamped-message check of Ahmadi & Stone costs up to (n - 1)! messages
per robot; Le et al.'s tables cost O(n^2) messages ("O(4n^2)" with the check) and the
forward-two variant O(n) ("O(2n)"). We measure messages to the decision on two families:

* ``geometric``: n robots uniform in a 1 m x 1 m square, range chosen for a mean degree
  of ``mean_degree`` (r = sqrt(d / (pi (n - 1))) metres, border effects ignored), redrawn
  until the radio graph is connected, ``samples`` teams per n, all methods on the same
  teams;
* ``ring``: :func:`ring_team`, sparse teams near a circle, often biconnected, redrawn
  until connected;
* ``complete``: every robot hears every other (explicit edges), the stamps worst case.

Runs that hit the message cap count as capped (their messages are the cap, a lower
bound). ``wrong`` counts verdicts (connected, biconnected) that differ from networkx.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import networkx as nx
import numpy as np

from mjswarm.experiments.connectivity.harness import METHODS, CheckResult, run_check
from mjswarm.experiments.connectivity.team import Team
from mjswarm.errors import MjswarmError

FAMILIES: tuple[str, ...] = ("geometric", "ring", "complete")
_STYLE = {
    "stamps": {"marker": "o"},
    "tables": {"marker": "s", "markersize": 8, "linestyle": "--"},
    "tables-2": {"marker": "^"},
}


def random_team(n: int, rng: np.random.Generator, *, size_m: float = 1.0) -> Team:
    """n robots ``r0..r{n-1}`` uniform in a ``size_m`` x ``size_m`` square (metres)."""
    xy = rng.random((n, 2)) * size_m
    return Team(positions={f"r{i}": (float(x), float(y)) for i, (x, y) in enumerate(xy)})


def geometric_range(n: int, mean_degree: float, *, size_m: float = 1.0) -> float:
    """Range (metres) giving about ``mean_degree`` neighbours: pi r^2 (n - 1) = d size^2."""
    return size_m * math.sqrt(mean_degree / (math.pi * max(n - 1, 1)))


def connected_draw(
    draw: Callable[[], tuple[Team, float | None]], what: str, *, tries: int = 10_000
) -> tuple[Team, float | None]:
    """Call ``draw() -> (team, range_m)`` until the team's radio graph is connected."""
    for _ in range(tries):
        team, range_m = draw()
        if nx.is_connected(team.graph(range_m)):
            return team, range_m
    raise MjswarmError(f"no connected {what} in {tries} draws")


def ring_team(
    n: int, rng: np.random.Generator, *, spacing_factor: float = 1.6, jitter: float = 0.3
) -> tuple[Team, float]:
    """n robots near a circle of radius 1 m, and a range of ``spacing_factor`` chords.

    Robot k sits at angle 2 pi (k + u) / n, u uniform in [-jitter, jitter], and radius
    1 + v metres, v uniform in [-jitter / 2, jitter / 2]; the range is ``spacing_factor``
    times the regular chord 2 sin(pi / n). That gives sparse teams (a cycle with some
    chords, sometimes broken) that are often biconnected yet have few simple paths.
    """
    angles = 2 * math.pi * (np.arange(n) + rng.uniform(-jitter, jitter, n)) / n
    radii = 1.0 + rng.uniform(-jitter / 2, jitter / 2, n)
    positions = {
        f"r{k}": (float(r * math.cos(a)), float(r * math.sin(a)))
        for k, (r, a) in enumerate(zip(radii, angles))
    }
    return Team(positions=positions), spacing_factor * 2 * math.sin(math.pi / n)


def complete_team(n: int) -> Team:
    """n robots that all hear each other (explicit edges; positions on a unit circle)."""
    ids = [f"r{i}" for i in range(n)]
    angles = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    positions = {r: (float(math.cos(a)), float(math.sin(a))) for r, a in zip(ids, angles)}
    edges = tuple((a, b) for i, a in enumerate(ids) for b in ids[i + 1 :])
    return Team(positions=positions, edges=edges)


@dataclass(frozen=True)
class Row:
    """One line of the comparison table (one family, team size and method)."""

    family: str
    n: int
    method: str
    runs: int
    mean_messages: float
    max_messages: int
    capped: int
    wrong: int


def compare_messages(
    ns: Sequence[int],
    *,
    samples: int = 5,
    mean_degree: float = 4.0,
    seed: int = 0,
    message_cap: int = 100_000,
    progress: Callable[[], None] | None = None,
) -> list[Row]:
    """Measure messages to the decision for every method, family and team size in ``ns``.

    ``progress`` is called once per team (for a progress bar).
    """
    if samples < 1 or any(n < 3 for n in ns):
        raise MjswarmError("need samples >= 1 and team sizes >= 3")
    rng = np.random.default_rng(seed)
    rows = []
    for n in ns:
        teams: dict[str, list[tuple[Team, float | None]]] = {
            "geometric": [
                connected_draw(
                    lambda n=n: (random_team(n, rng), geometric_range(n, mean_degree)),
                    f"team of {n} robots at mean degree {mean_degree}",
                )
                for _ in range(samples)
            ],
            "ring": [
                connected_draw(lambda n=n: ring_team(n, rng), f"ring of {n} robots")
                for _ in range(samples)
            ],
            "complete": [(complete_team(n), None)],
        }
        for family in FAMILIES:
            runs: dict[str, list] = {m: [] for m in METHODS}
            for team, range_m in teams[family]:
                graph = team.graph(range_m)
                truth = (nx.is_connected(graph), nx.is_biconnected(graph))
                for method in METHODS:
                    result = run_check(team, method, range_m=range_m, message_cap=message_cap)
                    runs[method].append((result, truth))
                if progress is not None:
                    progress()
            rows += [_row(family, n, method, runs[method]) for method in METHODS]
    return rows


def _row(family: str, n: int, method: str, runs: list[tuple[CheckResult, tuple]]) -> Row:
    results = [r for r, _ in runs]
    messages = [r.messages for r in results]
    wrong = sum(1 for r, truth in runs if not r.capped and (r.connected, r.biconnected) != truth)
    return Row(
        family=family,
        n=n,
        method=method,
        runs=len(results),
        mean_messages=float(np.mean(messages)),
        max_messages=max(messages),
        capped=sum(r.capped for r in results),
        wrong=wrong,
    )


def markdown_table(rows: Iterable[Row]) -> str:
    """Messages per method side by side, one line per family and n (capped runs marked)."""
    by_key: dict[tuple[str, int], dict[str, Row]] = {}
    for row in rows:
        by_key.setdefault((row.family, row.n), {})[row.method] = row
    head = "| family | n | " + " | ".join(f"{m} messages" for m in METHODS) + " | wrong |"
    lines = [head, "|" + "---|" * (3 + len(METHODS))]
    for (family, n), cells in by_key.items():
        shown = []
        for m in METHODS:
            r = cells[m]
            text = f"{r.mean_messages:.0f}"
            if r.capped:
                text = f">= {text} (capped {r.capped}/{r.runs})"
            shown.append(text)
        wrong = ", ".join(f"{m}: {cells[m].wrong}" for m in METHODS if cells[m].wrong) or "0"
        lines.append(f"| {family} | {n} | " + " | ".join(shown) + f" | {wrong} |")
    return "\n".join(lines)


def write_outputs(rows: Sequence[Row], out_dir: str | Path) -> list[Path]:
    """Write ``messages.csv``, ``messages.md`` and ``messages.png`` into ``out_dir``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise MjswarmError(f"cannot create {out} ({exc.strerror})") from None
    csv_path, md_path, png_path = out / "messages.csv", out / "messages.md", out / "messages.png"
    with csv_path.open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(Row.__dataclass_fields__)
        writer.writerows(
            [r.family, r.n, r.method, r.runs, f"{r.mean_messages:.1f}", r.max_messages,
             r.capped, r.wrong]
            for r in rows
        )
    md_path.write_text(markdown_table(rows) + "\n")
    fig, axes = plt.subplots(1, len(FAMILIES), figsize=(15, 4.2), sharey=True)
    for ax, family in zip(axes, FAMILIES):
        for method in METHODS:
            mine = [r for r in rows if r.family == family and r.method == method]
            ns = [r.n for r in mine]
            ax.plot(ns, [r.mean_messages for r in mine], label=method, **_STYLE[method])
            capped = [r for r in mine if r.capped]
            if capped:
                ax.scatter([r.n for r in capped], [r.mean_messages for r in capped],
                           marker="x", s=80, color="black", zorder=3)
        ax.set_yscale("log")
        ax.set_xlabel("robots n")
        ax.set_title(f"{family} teams")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("messages to decision (x: capped, lower bound)")
    axes[0].legend()
    fig.tight_layout()
    fig.savefig(png_path, dpi=120)
    plt.close(fig)
    return [csv_path, md_path, png_path]
