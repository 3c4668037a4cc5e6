"""Connectivity awareness on moving embodied robots: tables kept up to
date over the radio while robots explore, checked against networkx on ground truth."""

from __future__ import annotations

import rerun as rr

from mjswarm.arena import load_arena
from mjswarm.experiments.awareness import truth
from mjswarm.cli import main
from mjswarm.experiments.exploration import EmbodiedConfig, EmbodiedExploration
from mjswarm.experiments.minds import make_minds


def test_tables_follow_the_moving_radio_graph():
    config = EmbodiedConfig(speed_m_s=0.1, radio_range_m=1.5)
    run = EmbodiedExploration(load_arena("arena2"), make_minds("incidence-dfs", 4), config, 0)
    seen = set()
    while run.declared is None and run.sim.time_s < 1200:
        run.step()
        if run.sim.step_count % 10 == 0:
            seen.update(truth(run.world.radio.graph(), 0, range(1, 4)).values())
    result = run.result()
    assert result.completed
    assert seen == {"biconnected", "not"}  # the truth changed while they moved
    assert result.radio_belief_agreement > 0.98  # beliefs lag the truth by a few ticks
    for robot in run.robots:  # robots stand still (their tables keep ticking) ...
        robot.declared = True
    for _ in range(100):
        run.step()
    assert run.world.radio.last_batch == 0  # ... and once the radio is quiet, tables are exact
    beliefs = {i: "biconnected" if run.robots[i].table.is_doubly_connected() else "not"
               for i in range(1, 4)}
    assert beliefs == truth(run.world.radio.graph(), 0, range(1, 4))


def test_recording_shows_radio_graph_and_beliefs(tmp_path, capsys):
    rrd = tmp_path / "radio.rrd"
    assert main(["explore", "--arena", "fig9", "--robots", "2", "--speed", "0.15",
                 "--radio-range", "1.2", "--record", str(rrd)]) == 0
    out = capsys.readouterr().out
    assert "radio:" in out and "beliefs matched the truth" in out
    paths = {chunk.entity_path for chunk in rr.chunk.RrdReader(rrd).stream()}
    assert {"/radio/graph", "/radio/links", "/radio/truth"} <= paths


def test_radio_range_must_be_positive(capsys):
    assert main(["explore", "--arena", "fig9", "--robots", "2", "--radio-range", "0"]) == 2
    assert "--radio-range must be a finite number > 0" in capsys.readouterr().err
