"""``mjswarm sweep``: the grid, the results file, resuming, both backends."""

from __future__ import annotations

import json

import pytest

from mjswarm.arena import load_arena
from mjswarm.cli import main
from mjswarm.errors import MjswarmError
from mjswarm.experiments.graph_exploration import explore_world
from mjswarm.worlds.graphworld import GraphWorld
from mjswarm.experiments.sweep import CELL_KEYS, Cell, ResultsFile, grid, run_cell, sweep

ARGS = ["sweep", "--arenas", "fig9,tree1", "--robots", "2-3", "--strategies",
        "incidence-dfs,mr-dfs", "--seeds", "0,1"]


def test_local_sweep_writes_every_cell_and_resumes(tmp_path, capsys):
    out = tmp_path / "results.jsonl"
    assert main([*ARGS, "--out", str(out), "--workers", "2"]) == 0
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    assert len(rows) == 16
    assert {(r["arena"], r["robots"], r["strategy"], r["seed"]) for r in rows} == {
        (a, k, s, seed) for a in ("fig9", "tree1") for k in (2, 3)
        for s in ("incidence-dfs", "mr-dfs") for seed in (0, 1)}
    assert "16 ran" in capsys.readouterr().out
    # each record is the graph world's own result for that cell
    row = next(r for r in rows if r["arena"] == "fig9" and r["robots"] == 2
               and r["strategy"] == "incidence-dfs" and r["seed"] == 0)
    direct = explore_world(GraphWorld(load_arena("fig9").graph(), "v1"), 2, "incidence-dfs",
                           seed=0)
    assert row["makespan"] == direct.makespan and row["map_correct"]
    # a second run skips everything, an extended grid runs only the new cells
    assert main([*ARGS, "--out", str(out)]) == 0
    assert "0 ran" in capsys.readouterr().out
    assert main([*ARGS[:-1], "0-2", "--out", str(out)]) == 0
    assert "8 ran" in capsys.readouterr().out
    assert len(out.read_text().splitlines()) == 24


def test_csv_results_resume(tmp_path):
    out = tmp_path / "r.csv"
    cells = grid("graph", ["fig9"], [2], ["incidence-dfs", "bfs"], [0])
    assert sweep(cells, out, workers=1) == (2, 0)
    assert sweep(cells, out, workers=1) == (0, 2)
    assert len(ResultsFile(out).read()) == 2


def test_ray_backend_on_a_local_two_cpu_instance(tmp_path):
    pytest.importorskip("ray")
    out = tmp_path / "ray.jsonl"
    cells = grid("graph", ["fig9"], [2, 3], ["incidence-dfs"], [0, 1])
    assert sweep(cells, out, backend="ray", workers=2) == (4, 0)
    local = {c.key: run_cell(c)["makespan"] for c in cells}
    for r in ResultsFile(out).read():
        assert r["makespan"] == local[tuple(r[k] for k in CELL_KEYS)]


@pytest.mark.slow  # the connected MuJoCo team is held by tests/test_connected_exploration.py
def test_embodied_cell_runs_with_a_constraint():
    """An embodied cell of the connected-exploration grid: the MuJoCo robots on their tether."""
    record = run_cell(Cell("embodied", "arena1", 2, "incidence-dfs", 0, 3.0, "connected"))
    assert record["completed"] and record["collisions"] == 0 and "sim_time_s" in record
    assert record["connectivity"] == "connected" and record["cut_ticks"] == 0


@pytest.mark.parametrize("argv,message", [
    (["--world", "moon"], "unknown world"),
    (["--arenas", "atlantis"], "unknown arena"),
    (["--strategies", "teleport"], "unknown strategy"),
    (["--robots", "0"], "robot counts must be >= 1"),
    (["--seeds", "x"], "--seeds takes whole numbers"),
    (["--backend", "slurm"], "unknown backend"),
    (["--out", "/nonexistent/dir/r.jsonl"], "output directory does not exist"),
    (["--out", "results.txt"], "must end in .jsonl or .csv"),
    (["--robots", "1", "--radio-ranges", "2", "--connectivity", "biconnected"],
     "needs at least 2 robots"),
])
def test_bad_sweeps_are_one_line(tmp_path, capsys, argv, message):
    args = ["sweep", "--arenas", "fig9", "--robots", "2", "--out", str(tmp_path / "r.jsonl")]
    for flag, value in zip(argv[::2], argv[1::2]):
        if flag in args:
            args[args.index(flag) + 1] = value
        else:
            args += [flag, value]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1


def test_grid_rejects_nothing_to_do():
    with pytest.raises(MjswarmError, match="at least one"):
        grid("graph", ["fig9"], [2], ["incidence-dfs"], [])


def test_a_sweep_over_radio_ranges_and_constraints(tmp_path):
    """The connected-exploration grid: ranges x constraints in the graph world, each cell its own run."""
    out = tmp_path / "radio.csv"
    cells = grid("graph", ["arena2"], [4], ["incidence-dfs"], [0], [1.0, 50.0],
                 ["none", "connected", "biconnected"])
    assert sweep(cells, out, workers=1) == (6, 0)
    rows = ResultsFile(out).read()
    assert {(float(r["radio_range_m"]), r["connectivity"]) for r in rows} == {
        (r, c) for r in (1.0, 50.0) for c in ("none", "connected", "biconnected")}
    assert all(r["cut_ticks"] == "0" for r in rows if r["connectivity"] != "none")
    assert sweep(cells, out, workers=1) == (0, 6)  # CSV keys read back: nothing to redo


@pytest.mark.parametrize("kwargs,message", [
    ({"ranges": [1.0], "connectivities": ["triconnected"]}, "unknown connectivity"),
    ({"ranges": [None], "connectivities": ["connected"]}, "needs radio ranges"),
    ({"ranges": [-1.0]}, "must be positive"),
])
def test_bad_radio_grids_are_refused(kwargs, message):
    with pytest.raises(MjswarmError, match=message):
        grid("graph", ["arena2"], [2], ["incidence-dfs"], [0], **kwargs)
