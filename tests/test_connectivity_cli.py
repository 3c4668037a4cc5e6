"""Team files, `mjswarm connectivity` and `mjswarm compare connectivity`."""

from __future__ import annotations

import json

import pytest

from mjswarm.cli import main
from mjswarm.experiments.connectivity import load_team, parse_team
from mjswarm.errors import MjswarmError

SQUARE = {"positions": {"a": [0, 0], "b": [1, 0], "c": [1, 1], "d": [0, 1], "e": [2, 0.5]}}


def write(tmp_path, data, name="team.json"):
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else json.dumps(data))
    return str(path)


# -- team files -----------------------------------------------------------------------


def test_team_file_round_trip(tmp_path):
    team = load_team(write(tmp_path, {**SQUARE, "walls": [[[0.5, -1], [0.5, 2]]]}))
    assert team.ids == ("a", "b", "c", "d", "e")
    assert team.positions["e"] == (2.0, 0.5)
    assert team.edges is None and len(team.walls) == 1
    links = {frozenset(e) for e in team.graph(1.2).edges}  # the wall at x = 0.5 cuts a-b, c-d
    assert links == {frozenset("ad"), frozenset("bc"), frozenset("be"), frozenset("ce")}


def test_explicit_edges_define_the_graph():
    team = parse_team({"positions": {"a": [0, 0], "b": [9, 9]}, "edges": [["a", "b"]]})
    assert set(team.graph().edges) == {("a", "b")}
    with pytest.raises(MjswarmError, match="drop the range"):
        team.graph(1.0)
    with pytest.raises(MjswarmError, match="range is needed"):
        parse_team(SQUARE).graph()


@pytest.mark.parametrize(
    ("data", "words"),
    [
        ([1, 2], "JSON object"),
        ({}, "non-empty object"),
        ({"positions": {}}, "non-empty object"),
        ({"positions": {"a": [0]}}, "two finite numbers"),
        ({"positions": {"a": [0, "x"]}}, "two finite numbers"),
        ({"positions": {"a": [0, True]}}, "two finite numbers"),
        ({"positions": {"a": [0, 0]}, "colour": 1}, "unknown key 'colour'"),
        ({"positions": {"a": [0, 0]}, "edges": {}}, "list of"),
        ({"positions": {"a": [0, 0]}, "edges": [["a"]]}, "pair of robot ids"),
        ({"positions": {"a": [0, 0]}, "edges": [["a", "z"]]}, "unknown robot 'z'"),
        ({"positions": {"a": [0, 0]}, "edges": [["a", "a"]]}, "to itself"),
        ({"positions": {"a": [0, 0], "b": [1, 1]}, "edges": [["a", "b"], ["b", "a"]]},
         "duplicate edge"),
        ({"positions": {"a": [0, 0]}, "walls": [[[0, 0]]]}, "wall"),
    ],
)
def test_bad_team_data_is_one_clear_error(data, words):
    with pytest.raises(MjswarmError, match=words):
        parse_team(data, "team.json")


def test_bad_files(tmp_path):
    with pytest.raises(MjswarmError, match="cannot read"):
        load_team(tmp_path / "missing.json")
    with pytest.raises(MjswarmError, match="not valid JSON"):
        load_team(write(tmp_path, "{positions: "))
    dup = '{"positions": {"a": [0, 0], "a": [1, 1]}}'
    with pytest.raises(MjswarmError, match="duplicate key 'a'"):
        load_team(write(tmp_path, dup))


# -- mjswarm connectivity -------------------------------------------------------------


@pytest.mark.parametrize(
    ("method", "points", "messages"),
    [("stamps", None, 114), ("tables", [], 11), ("tables-2", [], 11)],
)
def test_cli_json(tmp_path, capsys, method, points, messages):
    path = write(tmp_path, SQUARE)
    argv = ["connectivity", "--positions", path, "--range", "1.2", "--method", method]
    assert main([*argv, "--json", "-"]) == 0
    out = json.loads(capsys.readouterr().out)  # nothing but JSON on stdout
    assert out["connected"] is True and out["biconnected"] is True
    assert out["articulation_points"] == points
    assert out["messages"] == messages
    assert out["rounds"] == (6 * 5 + 2 if method == "stamps" else 2 * 5 - 1)
    assert out["capped"] is False and out["robots"] == 5 and out["initiator"] == "a"
    assert set(out) >= {"max_messages_per_robot", "deliveries", "range_m", "positions"}


def test_cli_human_output_and_json_file(tmp_path, capsys):
    path = write(tmp_path, {"positions": {"a": [0, 0], "b": [1, 0], "c": [2, 0]}})
    report = tmp_path / "out.json"
    argv = ["connectivity", "--positions", path, "--range", "1", "--method", "tables",
            "--initiator", "c", "--json", str(report)]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "biconnected:         no" in text
    assert "articulation points: b" in text
    assert "reference c" in text
    assert json.loads(report.read_text())["articulation_points"] == ["b"]


def test_cli_reports_the_cap(tmp_path, capsys):
    dense = {"positions": {f"r{i}": [0, 0.01 * i] for i in range(10)}}
    argv = ["connectivity", "--positions", write(tmp_path, dense), "--range", "1",
            "--method", "stamps", "--message-cap", "500"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "message cap (500)" in text and "connected:           unknown" in text


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--method", "flood"], "unknown method 'flood'"),
        (["--method", "tables", "--range", "0"], "--range must be a finite number > 0"),
        (["--method", "tables", "--range", "-2"], "--range must be a finite number > 0"),
        (["--method", "tables"], "range is needed"),
        (["--method", "tables", "--range", "1", "--initiator", "zz"], "initiator 'zz'"),
        (["--method", "stamps", "--range", "1", "--max-robots", "2"], "below the team size"),
        (["--method", "stamps", "--range", "1", "--drop-prob", "1.5"], "drop probability"),
    ],
)
def test_cli_bad_input_is_one_line_and_exit_2(tmp_path, capsys, extra, words):
    path = write(tmp_path, SQUARE)
    assert main(["connectivity", "--positions", path, *extra]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err


@pytest.mark.parametrize(
    ("content", "words"),
    [
        ("not json", "not valid JSON"),
        ('{"positions": {"a": [0, 0], "a": [1, 0]}}', "duplicate key 'a'"),
        ('{"positions": {"a": [0, 0]}, "edges": [["a", "b"]]}', "unknown robot 'b'"),
    ],
)
def test_cli_bad_file_is_one_line_and_exit_2(tmp_path, capsys, content, words):
    path = write(tmp_path, content)
    assert main(["connectivity", "--positions", path, "--method", "tables"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err


# -- mjswarm compare connectivity -----------------------------------------------------


def test_compare_connectivity_writes_table_and_plot(tmp_path, capsys):
    out_dir = tmp_path / "cmp"
    argv = ["compare", "connectivity", "--out", str(out_dir), "--n-min", "4", "--n-max", "8",
            "--n-step", "4", "--samples", "2", "--json", "-"]
    assert main(argv) == 0
    rows = json.loads(capsys.readouterr().out)
    assert {(r["family"], r["n"], r["method"]) for r in rows} == {
        (f, n, m) for f in ("geometric", "ring", "complete") for n in (4, 8)
        for m in ("stamps", "tables", "tables-2")
    }
    assert all(r["wrong"] == 0 for r in rows if r["method"] != "tables-2")
    complete8 = {r["method"]: r for r in rows if r["family"] == "complete" and r["n"] == 8}
    assert complete8["stamps"]["mean_messages"] > 100 * complete8["tables"]["mean_messages"]
    assert (out_dir / "messages.png").stat().st_size > 10_000
    assert "| family | n |" in (out_dir / "messages.md").read_text()
    assert (out_dir / "messages.csv").read_text().startswith("family,n,method")


def test_compare_connectivity_bad_sizes(capsys):
    assert main(["compare", "connectivity", "--n-min", "9", "--n-max", "4"]) == 2
    assert main(["compare", "connectivity", "--n-min", "2", "--n-max", "4"]) == 2
    assert capsys.readouterr().err.count("\n") == 2
