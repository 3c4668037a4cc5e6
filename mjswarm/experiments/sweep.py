"""Parameter sweeps: a grid of exploration runs, in parallel, resumable.

A sweep is the product arenas x robot counts x strategies x seeds x radio ranges x
connectivity constraints in one world (``graph``, :mod:`mjswarm.experiments.radio_exploration`, or
``embodied``, :mod:`mjswarm.experiments.exploration` at its default speed; a range without
a constraint gives the embodied robots connectivity tables, as ``mjswarm explore`` does).
Each cell is one run of :func:`run_cell`; results are appended to one
file as they finish, one record per cell (JSON lines, or CSV with list-valued fields as
JSON text), so a sweep that is stopped and started again skips the cells already in the
file. Backends: a local process pool (default) or a Ray cluster (``backend="ray"``; the
optional extra ``pip install -e ".[ray]"``; ``ray.init`` connects to ``RAY_ADDRESS`` if
set, else starts a local instance).
"""

from __future__ import annotations

import csv
import itertools
import json
import os
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass
from pathlib import Path

from mjswarm.errors import MjswarmError
from mjswarm.experiments.minds import MAX_ROBOTS

WORLDS = ("graph", "embodied")
BACKENDS = ("local", "ray")
CELL_KEYS = ("world", "arena", "robots", "strategy", "seed", "radio_range_m", "connectivity")
#: What a results file written before radio ranges and constraints existed holds.
CELL_DEFAULTS = {"radio_range_m": None, "connectivity": "none"}


@dataclass(frozen=True)
class Cell:
    """One run of a sweep."""

    world: str
    arena: str
    robots: int
    strategy: str
    seed: int
    radio_range_m: float | None = None
    connectivity: str = "none"

    @property
    def key(self) -> tuple:
        return tuple(getattr(self, k) for k in CELL_KEYS)


def grid(world: str, arenas: Iterable[str], robots: Iterable[int], strategies: Iterable[str],
         seeds: Iterable[int], ranges: Iterable[float | None] = (None,),
         connectivities: Iterable[str] = ("none",)) -> list[Cell]:
    """Every combination, validated up front (unknown world / arena / strategy /
    constraint, K < 1, a range that is not positive, a constraint without a range)."""
    from algorithms.exploration import STRATEGIES
    from mjswarm.arena import load_arena
    from mjswarm.experiments.radio_exploration import CONNECTIVITY, need_robots

    ranges, connectivities = list(ranges), list(connectivities)
    for c in connectivities:
        if c not in CONNECTIVITY:
            raise MjswarmError(f"unknown connectivity '{c}' (choose from {', '.join(CONNECTIVITY)})")
    if any(r is not None and not r > 0 for r in ranges):
        raise MjswarmError("radio ranges must be positive (m)")
    if None in ranges and any(c != "none" for c in connectivities):
        raise MjswarmError("a connectivity constraint needs radio ranges (--radio-ranges)")
    if world not in WORLDS:
        raise MjswarmError(f"unknown world '{world}' (choose from {', '.join(WORLDS)})")
    arenas, robots, strategies, seeds = list(arenas), list(robots), list(strategies), list(seeds)
    for name in arenas:
        load_arena(name)
    for s in strategies:
        if s not in STRATEGIES:
            raise MjswarmError(f"unknown strategy '{s}' (choose from {', '.join(STRATEGIES)})")
    if not robots or min(robots) < 1:
        raise MjswarmError("robot counts must be >= 1")
    if max(robots) > MAX_ROBOTS:
        raise MjswarmError(f"robot counts must be <= {MAX_ROBOTS} (got {max(robots)}; "
                           "mjswarm bench measures up to 1000 robots)")
    for c in connectivities:
        need_robots(c, min(robots))
    if not (arenas and strategies and seeds):
        raise MjswarmError("a sweep needs at least one arena, strategy and seed")
    return [Cell(world, a, k, s, seed, r, c) for a, k, s, seed, r, c in
            itertools.product(arenas, robots, strategies, seeds, ranges, connectivities)]


def run_cell(cell: Cell) -> dict:
    """Run one cell; the record written to the results file."""
    from mjswarm.arena import load_arena

    from mjswarm.experiments.runs import run_exploration

    result = run_exploration(load_arena(cell.arena), cell.robots, cell.strategy,
                             world=cell.world, seed=cell.seed,
                             radio_range_m=cell.radio_range_m, connectivity=cell.connectivity)
    record = result.to_dict()
    record.pop("paths", None)
    return {**asdict(cell), **{k: v for k, v in record.items() if k not in CELL_KEYS}}


class ResultsFile:
    """Append-only results, JSON lines (``.jsonl``/``.json``) or CSV (``.csv``)."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        if self.path.suffix not in (".jsonl", ".json", ".csv"):
            raise MjswarmError(f"results file must end in .jsonl or .csv, got {self.path}")
        if not self.path.parent.is_dir():
            raise MjswarmError(f"output directory does not exist: {self.path.parent}")
        self.csv = self.path.suffix == ".csv"

    def done(self) -> set[tuple]:
        """Keys of the cells already in the file."""
        if not self.path.exists():
            return set()
        return {tuple(_coerce(r.get(k, CELL_DEFAULTS.get(k))) for k in CELL_KEYS)
                for r in self.read()}

    def read(self) -> list[dict]:
        if not self.path.exists():
            return []
        with self.path.open(newline="") as f:
            if self.csv:
                return list(csv.DictReader(f))
            try:
                return [json.loads(line) for line in f if line.strip()]
            except json.JSONDecodeError as exc:
                raise MjswarmError(f"{self.path} is not a JSON-lines results file: {exc}") from None

    def append(self, record: dict) -> None:
        if not self.csv:
            with self.path.open("a") as f:
                f.write(json.dumps(record) + "\n")
            return
        row = {k: json.dumps(v) if isinstance(v, (list, dict)) else v for k, v in record.items()}
        new = not self.path.exists() or self.path.stat().st_size == 0
        with self.path.open("a", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(row))
            if new:
                writer.writeheader()
            writer.writerow(row)


def _coerce(value):
    """CSV cells come back as text: numbers to int or float where they are, empty to None."""
    if not isinstance(value, str):
        return value
    if value == "":
        return None
    if value.lstrip("-").isdigit():
        return int(value)
    try:
        return float(value)
    except ValueError:
        return value


def sweep(cells: list[Cell], out: str | Path, backend: str = "local", workers: int | None = None,
          on_result: Callable[[dict], None] | None = None) -> tuple[int, int]:
    """Run the cells not yet in ``out``; return ``(ran, skipped)``."""
    if backend not in BACKENDS:
        raise MjswarmError(f"unknown backend '{backend}' (choose from {', '.join(BACKENDS)})")
    if workers is not None and workers < 1:
        raise MjswarmError(f"workers must be >= 1, got {workers}")
    results = ResultsFile(out)
    done = results.done()
    todo = [c for c in cells if c.key not in done]
    runner = _ray_results if backend == "ray" else _local_results
    for record in runner(todo, workers):
        results.append(record)
        if on_result is not None:
            on_result(record)
    return len(todo), len(cells) - len(todo)


def _local_results(cells: list[Cell], workers: int | None) -> Iterator[dict]:
    if not cells:
        return
    with ProcessPoolExecutor(max_workers=workers or os.cpu_count()) as pool:
        futures = [pool.submit(run_cell, c) for c in cells]
        for future in as_completed(futures):
            yield future.result()


def _ray_results(cells: list[Cell], workers: int | None) -> Iterator[dict]:
    try:
        import ray
    except ModuleNotFoundError:
        raise MjswarmError('the Ray backend needs Ray: pip install -e ".[ray]"') from None
    if not cells:
        return
    started = not ray.is_initialized()
    if started:
        ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
    try:
        remote = ray.remote(run_cell)
        pending = [remote.remote(c) for c in cells]
        while pending:
            ready, pending = ray.wait(pending, num_returns=1)
            yield ray.get(ready[0])
    finally:
        if started:
            ray.shutdown()
