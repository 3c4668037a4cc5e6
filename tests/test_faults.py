"""Fault injection: parsing, and what each fault does to an embodied run."""

from __future__ import annotations

import json

import pytest

from mjswarm.arena import load_arena
from mjswarm.experiments.exploration import EmbodiedConfig, EmbodiedExploration, explore_embodied
from mjswarm.errors import MjswarmError
from mjswarm.experiments.faults import BeaconWipe, RadioBlackout, RobotFailure, parse_fault
from mjswarm.experiments.minds import make_minds
from mjswarm.core.radio import Radio


@pytest.mark.parametrize("text,fault", [
    ("robot:2@30", RobotFailure(1, 30.0)),
    ("robot:1@0.5", RobotFailure(0, 0.5)),
    ("beacon:v3@100", BeaconWipe("v3", 100.0)),
    ("radio-blackout@10-20.5", RadioBlackout(10.0, 20.5)),
])
def test_parse(text, fault):
    assert parse_fault(text) == fault
    assert str(parse_fault(str(fault))) == str(fault)


@pytest.mark.parametrize("text", ["robot:0@3", "robot:x@3", "beacon:@3", "radio-blackout@5",
                                  "quake@3", "robot:1@-2"])
def test_bad_fault_is_one_line(text):
    with pytest.raises(MjswarmError) as err:
        parse_fault(text)
    assert "\n" not in str(err.value)


def test_faults_are_checked_against_the_run():
    spec = load_arena("arena1")
    for fault, message in [(RobotFailure(5, 1.0), "robots 1..2"),
                           (BeaconWipe("nowhere", 1.0), "not a vertex"),
                           (RadioBlackout(1.0, 2.0), "--radio-range"),
                           (RadioBlackout(3.0, 2.0), "end after")]:
        with pytest.raises(MjswarmError, match=message):
            explore_embodied(spec, 2, config=EmbodiedConfig(faults=[fault]))


def test_radio_blackout_loses_every_copy():
    radio = Radio(range(3), edges=[(0, 1), (1, 2)])
    radio.blackout = True
    radio.send(1, "hello")
    radio.step()
    assert radio.receive(0) == [] and radio.receive(2) == [] and radio.dropped == 2
    radio.blackout = False
    radio.send(1, "again")
    radio.step()
    assert [m.payload for m in radio.receive(0)] == ["again"]


def test_a_dead_robot_stops_and_the_others_finish_with_the_true_map():
    """R3 fails half a minute in, on its first edge; the others take over the edge it had
    claimed (priority (4)'s out edges) and pass its body on the other lane."""
    config = EmbodiedConfig(speed_m_s=0.1, faults=[parse_fault("robot:3@30")])
    result = explore_embodied(load_arena("arena2"), 4, config=config, seed=0)
    assert result.completed and result.map_correct and result.collisions == 0
    assert [s["robot"] for s in result.stopped_robots] == [3]
    assert result.stopped_robots[0]["at_s"] == pytest.approx(30.0, abs=0.05)
    assert result.faults == [{"fault": "robot:3@30", "fired": True, "at_s": pytest.approx(30.0, abs=0.05)}]
    assert result.traversals_per_robot[2] == 0


def test_a_body_in_a_vertex_area_closes_it_and_the_reachable_part_is_completed():
    """R2 dies in the area of v2: v2 is closed (the run does not stall), R1
    is answered EntryBlocked when it asks for it, finishes the rest and declares completion
    of the reachable part, naming the two edges at v2."""
    config = EmbodiedConfig(speed_m_s=0.1, faults=[parse_fault("robot:2@45")],
                            stall_timeout_s=120.0)
    result = explore_embodied(load_arena("arena1"), 2, config=config, seed=0)
    assert result.completed and result.ended_because == "completed reachable part"
    assert result.map_correct and result.closed_vertices[0]["vertex"] == "v2"
    assert sorted(tuple(e["edge"]) for e in result.unreachable_edges) == [("v1", "v2"),
                                                                          ("v2", "v4")]
    assert result.collisions == 0


def test_a_robot_dead_before_launch_never_launches():
    config = EmbodiedConfig(speed_m_s=0.1, faults=[parse_fault("robot:2@0")])
    result = explore_embodied(load_arena("arena1"), 2, config=config, seed=0)
    assert result.completed and result.map_correct
    assert result.traversals_per_robot[1] == 0


def test_a_wiped_beacon_is_reported():
    """The root's beacon is wiped while R1 is away: the run says when, and the outcome
    (completed or not, map right or not) is whatever the strategy makes of it, reported
    rather than hidden."""
    config = EmbodiedConfig(speed_m_s=0.1, faults=[parse_fault("beacon:v1@40")],
                            max_sim_time_s=900)
    result = explore_embodied(load_arena("arena1"), 1, config=config, seed=0)
    assert result.faults == [{"fault": "beacon:v1@40", "fired": True, "at_s": pytest.approx(40.0, abs=0.05)}]
    assert result.ended_because in ("completed", "stalled", "all robots stopped", "max time")
    if result.completed:
        assert result.map_correct == (sorted(result.map_edges) == sorted(
            tuple(sorted(e)) for e in load_arena("arena1").edges))
    # what it makes of it here: R1 drops a second beacon at v1 and later finds no route
    # between its two names for v1; it stops, says why, and the run ends at once
    assert not result.completed and result.ended_because == "all robots stopped"
    [stopped] = result.stopped_robots
    assert stopped["robot"] == 1 and "its strategy failed" in stopped["reason"]


def test_radio_blackout_drops_table_messages():
    quiet = EmbodiedConfig(speed_m_s=0.1, radio_range_m=1.5, max_sim_time_s=60)
    dark = EmbodiedConfig(speed_m_s=0.1, radio_range_m=1.5, max_sim_time_s=60,
                          faults=[parse_fault("radio-blackout@5-40")])
    a = explore_embodied(load_arena("arena1"), 2, config=quiet, seed=0)
    b = explore_embodied(load_arena("arena1"), 2, config=dark, seed=0)
    assert [f["fault"] for f in b.faults] == ["radio-blackout@5-40", "radio back at 40"]
    assert a.paths == b.paths  # exploration does not use the radio
    assert b.radio_belief_agreement < a.radio_belief_agreement or b.radio_messages != a.radio_messages


def test_radio_blackout_silences_the_radio_for_its_interval_only():
    """The radio drops every copy from T1 to T2 and none outside it."""
    def run(faults):
        config = EmbodiedConfig(speed_m_s=0.1, radio_range_m=1.5, max_sim_time_s=60,
                                faults=faults)
        exploration = EmbodiedExploration(load_arena("arena1"),
                                          make_minds("incidence-dfs", 2, 0), config, 0)
        radio, blackout = exploration.world.radio, {}
        while exploration.sim.time_s < 60.0:
            exploration.step()
            blackout[round(exploration.sim.time_s, 2)] = radio.blackout
        return radio, blackout

    quiet, never = run([])
    dark, flags = run([parse_fault("radio-blackout@5-40")])
    assert quiet.dropped == 0 and not any(never.values())
    assert dark.dropped > 0
    # on from the tick that starts at 5 s to the one that starts at 40 s (flags are read
    # after each tick's step, 20 ms later)
    assert [t for t, on in flags.items() if on] == pytest.approx(
        [round(0.02 * k, 2) for k in range(251, 2001)], abs=1e-9)


def test_cli_reports_faults_and_stopped_robots(capsys):
    """A lone robot failing at 5 s: the run ends at once, not completed, and both the
    summary and the JSON say who stopped, why and when."""
    from mjswarm.cli import main

    argv = ["explore", "--arena", "arena1", "--robots", "1", "--fault", "robot:1@5"]
    assert main(argv) == 1
    out = capsys.readouterr().out
    assert "not completed (all robots stopped)" in out
    assert "stopped: R1 at 5.0 s: failed (fault robot:1@5)" in out
    assert main([*argv, "--json", "-"]) == 1
    result = json.loads(capsys.readouterr().out)
    assert result["ended_because"] == "all robots stopped"
    assert result["stopped_robots"] == [
        {"robot": 1, "reason": "failed (fault robot:1@5)", "at_s": 5.0}]
    assert result["faults"] == [{"fault": "robot:1@5", "fired": True, "at_s": 5.0}]
    assert result["sim_time_s"] < 6.0 and result["heading_error_deg"] >= 0.0
