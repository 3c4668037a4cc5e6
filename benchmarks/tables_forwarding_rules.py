"""Le et al.'s forwarding rule (Algorithm 1 line 7) against ours and forward-two.

Builds connectivity tables on 500 connected random geometric teams (n = 5..30, mean degree
4, seed 0) under three rules and counts the robots whose "two disjoint access paths"
belief is wrong, the team verdicts that differ from ``networkx.is_biconnected``, and the
table-building messages. The printed rule ("forward a path only if it is disjoint from
every stored path") is swapped in by replacing ``ConnectivityTable._accepts``.

    python benchmarks/tables_forwarding_rules.py
"""

import sys
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import networkx as nx  # noqa: E402
import numpy as np

from algorithms.connectivity.tables import ConnectivityTable, interior
from mjswarm.experiments.connectivity import drive, run_check
from mjswarm.experiments.connectivity.comparison import connected_draw, geometric_range, random_team


def literal(self, p):
    """Algorithm 1 line 7 as printed: disjoint with every other stored path."""
    return all(not (interior(p) & interior(q)) for q in self._paths if q != p)


def compare_rules(n_teams: int = 500) -> list[tuple[str, int, int, int, int, int]]:
    """Per rule: (name, robots' beliefs wrong, robots, team verdicts wrong, teams,
    table-building messages)."""
    ours = ConnectivityTable._accepts
    rng = np.random.default_rng(0)
    teams = [connected_draw(lambda n=n: (random_team(n, rng), geometric_range(n, 4.0)), "team")
             for n in rng.integers(5, 31, n_teams)]
    rows = []
    try:
        for name, rule, method in [("literal line 7", literal, "tables"),
                                   ("ours", ours, "tables"),
                                   ("forward-two", ours, "tables-2")]:
            ConnectivityTable._accepts = rule
            robots = robot_err = team_err = msgs = 0
            for team, r in teams:
                g = team.graph(r)
                ref = team.ids[0]
                radio = team.radio(r)
                tables = {v: ConnectivityTable(v, ref,
                                               max_forwards=2 if method == "tables-2" else None)
                          for v in g}
                drive(radio, tables, lambda radio=radio: radio.last_batch == 0)
                msgs += radio.total_sent
                blocks = [c for c in nx.biconnected_components(g) if ref in c and len(c) >= 3]
                for v in g:
                    if v == ref:
                        continue
                    robots += 1
                    robot_err += tables[v].is_doubly_connected() != any(v in c for c in blocks)
                team_err += run_check(team, method, range_m=r).biconnected != nx.is_biconnected(g)
            rows.append((name, robot_err, robots, team_err, len(teams), msgs))
    finally:
        ConnectivityTable._accepts = ours
    return rows


if __name__ == "__main__":
    for name, robot_err, robots, team_err, teams, msgs in compare_rules():
        print(f"{name:15s} robots wrong {robot_err}/{robots}, team verdicts wrong "
              f"{team_err}/{teams}, table-building messages {msgs}")
