"""``mjswarm explore`` and ``mjswarm compare exploration`` on shipped arenas."""

from __future__ import annotations

import json

import pytest

from algorithms.exploration import STRATEGIES
from mjswarm.arena import load_arena
from mjswarm.cli import main

REQUIRED_KEYS = {
    "completed", "makespan", "total_traversals", "traversals_per_robot", "declared_by",
    "declared_at", "map_edges", "strategy", "robots", "arena",
}


def test_explore_fig9_json_to_stdout(capsys):
    assert main(["explore", "--world", "graph", "--arena", "fig9", "--robots", "2",
                 "--json", "-"]) == 0
    out = json.loads(capsys.readouterr().out)  # nothing but JSON on stdout
    assert REQUIRED_KEYS <= out.keys()
    assert (out["makespan"], out["declared_by"], out["declared_at"]) == (8, 1, "v8")
    assert out["traversals_per_robot"] == [8, 8] and out["total_traversals"] == 16
    spec = load_arena("fig9")
    assert {frozenset(e) for e in out["map_edges"]} == {frozenset(e) for e in spec.edges}
    assert out["strategy"] == "incidence-dfs" and out["robots"] == 2 and out["arena"] == "fig9"


@pytest.mark.parametrize("strategy", list(STRATEGIES))
def test_explore_every_strategy_on_arena2_writes_json_file(strategy, tmp_path, capsys):
    path = tmp_path / "run.json"
    assert main(["explore", "--world", "graph", "--arena", "arena2", "--robots", "4",
                 "--strategy", strategy,
                 "--seed", "3", "--json", str(path)]) == 0
    text = capsys.readouterr().out
    assert "completed: R" in text and "equal to the arena's" in text
    data = json.loads(path.read_text())
    assert data["completed"] and data["map_correct"] and data["seed"] == 3
    assert data["strategy"] == strategy


def test_explore_root_and_edge_time_options(capsys):
    assert main(["explore", "--world", "graph", "--arena", "lattice:4x4", "--robots", "5",
                 "--root", "v0_1",
                 "--edge-time", "length", "--json", "-"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["root"] == "v0_1" and out["edge_time"] == "length" and out["makespan"] == 10


@pytest.mark.parametrize("argv, words", [
    (["--robots", "0"], "--robots must be a whole number >= 1"),
    (["--robots", "2", "--strategy", "teleport"], "unknown strategy 'teleport'"),
    (["--robots", "2", "--arena", "atlantis"], "unknown arena 'atlantis'"),
    (["--robots", "2", "--root", "v99"], "root 'v99'"),
    (["--robots", "2", "--world", "moon"], "unknown world 'moon'"),
])
def test_explore_bad_input_is_one_line_and_exit_2(argv, words, capsys):
    argv = ["explore", "--arena", "fig9", *argv]
    if argv.count("--arena") == 2:
        argv = argv[:1] + argv[3:]
    assert main(argv) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("mjswarm: error:") and words in lines[0]
    assert captured.out == ""


def test_explore_help_gives_units(capsys):
    with pytest.raises(SystemExit):
        main(["explore", "--help"])
    text = capsys.readouterr().out
    assert "--edge-time" in text and "time units" in text and "incidence-dfs" in text


def test_compare_exploration_quick(tmp_path, capsys):
    out_dir = tmp_path / "cmp"
    assert main(["compare", "exploration", "--quick", "--seeds", "1", "--out", str(out_dir)]) == 0
    table = (out_dir / "results.md").read_text()
    for heading in ("Fig. 8", "Fig. 17", "4 x 4 lattice"):
        assert heading in table
    assert "| lattice:4x4 | v0_1 | 5 |" in table
    for png in ("fig8.png", "fig17.png"):
        assert (out_dir / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = json.loads((out_dir / "results.json").read_text())["rows"]
    assert rows and all(r["failures"] == 0 and r["runs"] == 2 for r in rows)
    fig8 = [r for r in rows if r["figure"] == "fig8" and r["strategy"] == "incidence-dfs"]
    assert all(r["worst"] <= r["edges"] for r in fig8)  # Proposition 2
    assert "wrote" in capsys.readouterr().out


def test_compare_rejects_negative_seeds(capsys):
    assert main(["compare", "exploration", "--seeds", "-1"]) == 2
    assert "--seeds" in capsys.readouterr().err
