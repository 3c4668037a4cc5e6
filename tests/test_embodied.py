"""Embodied exploration: the graph strategies on MuJoCo robots with their own
sensors and Nagavarapu et al.'s collision rule. Fast checks by default; the 20-scenario sweeps
(with and without collision avoidance) are marked slow."""

from __future__ import annotations

import json
import subprocess

import pytest
from embodied_scenarios import scenarios

from mjswarm.arena import load_arena
from mjswarm.cli import main
from mjswarm.experiments.exploration import EmbodiedConfig, explore_embodied
from mjswarm.outputs.recording import rerun_command


def truth(arena: str) -> list[tuple[str, str]]:
    return sorted(tuple(sorted(e)) for e in load_arena(arena).edges)


@pytest.mark.parametrize("arena,robots", [("arena1", 2), ("arena2", 4)])
def test_paper_arenas_complete_with_the_true_map(arena, robots):
    """Nagavarapu et al. Sec. 5: arena 1 with two robots, arena 2 with four, at 5 cm/s."""
    result = explore_embodied(load_arena(arena), robots, seed=0)
    assert result.completed
    assert result.map_edges == truth(arena) and result.map_correct
    assert result.collisions == 0
    assert result.stopped_robots == []
    assert result.ended_because == "completed"
    assert result.makespan <= result.total_traversals


def test_same_seed_same_run():
    config = EmbodiedConfig(speed_m_s=0.1, launch_order=[1, 0])
    a = explore_embodied(load_arena("arena1"), 2, config=config, seed=3)
    b = explore_embodied(load_arena("arena1"), 2, config=config, seed=3)
    assert a.paths == b.paths and a.sim_time_s == b.sim_time_s
    assert a.speed_changes == b.speed_changes


def test_without_avoidance_two_robots_collide():
    """The check has teeth: the same run without the rule and vertex entry crashes."""
    config = EmbodiedConfig(speed_m_s=0.1, collision_avoidance=False, max_sim_time_s=300)
    result = explore_embodied(load_arena("fig9"), 2, config=config, seed=0)
    assert result.collisions > 0


@pytest.mark.slow
def test_twenty_seeded_scenarios_never_collide():
    results = [(s, s.run()) for s in scenarios()]
    failures = [(s, r.collisions, r.completed) for s, r in results
                if r.collisions or not r.completed or not r.map_correct]
    assert failures == []


@pytest.mark.slow
def test_without_avoidance_a_clear_share_collide():
    results = [s.run(collision_avoidance=False, max_sim_time_s=600) for s in scenarios()]
    share = sum(r.collisions > 0 for r in results) / len(results)
    assert share >= 0.5


def test_cli_embodied_json_and_recording(tmp_path, capsys):
    rrd = tmp_path / "fig9.rrd"
    code = main(["explore", "--arena", "fig9", "--robots", "2", "--speed", "0.15",
                 "--record", str(rrd), "--json", "-"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0 and out["completed"] and out["world"] == "embodied"
    for key in ("makespan", "total_traversals", "traversals_per_robot", "declared_by",
                "declared_at", "map_edges", "collisions", "sim_time_s", "wall_time_s",
                "realtime_factor", "speed_changes"):
        assert key in out
    assert out["collisions"] == 0 and out["sim_time_s"] > 0
    verify = subprocess.run([*rerun_command(), "rrd", "verify", str(rrd)],
                            capture_output=True, text=True, timeout=120, check=False)
    assert verify.returncode == 0, verify.stderr
    events = _texts(rrd)
    assert "run ended: completed" in events["/events"]
    assert f"R{out['declared_by']} declared completion at {out['declared_at']}" in (
        events["/events"])
    assert any(" speed " in t and "m/s" in t for key in ("/events/R1", "/events/R2")
               for t in events.get(key, []))
    assert any(t.startswith("R1 at ") for t in events["/events/R1"])


def _texts(rrd) -> dict[str, list[str]]:
    """Entity -> the TextLog lines of a recording."""
    import rerun as rr

    texts: dict[str, list[str]] = {}
    for chunk in rr.chunk.RrdReader(rrd).stream():
        batch = chunk.to_record_batch()
        if "TextLog:text" in batch.schema.names:
            texts.setdefault(chunk.entity_path, []).extend(
                row[0] for row in batch.column("TextLog:text").to_pylist() if row)
    return texts


@pytest.mark.parametrize(
    "argv,message",
    [
        (["--speed", "0"], "--speed must be a finite number > 0"),
        (["--speed", "0.5"], "exceeds the robot's top speed"),
        (["--launch-order", "1,1"], "--launch-order must name each of R1..R2 once"),
        (["--launch-order", "a,b"], "--launch-order takes robot numbers"),
        (["--world", "moon"], "unknown world"),
        (["--robots", "0"], "--robots must be a whole number >= 1"),
        (["--fault", "quake@3"], "bad fault 'quake@3'"),
        (["--fault", "robot:7@3"], "there are robots 1..2"),
        (["--fault", "beacon:v99@3"], "'v99' is not a vertex"),
        (["--fault", "radio-blackout@3-9"], "needs robots with radios"),
        (["--stall-timeout", "0"], "--stall-timeout must be a finite number > 0"),
        (["--wheel-slip", "-0.1"], "--wheel-slip must be a finite number >= 0"),
        (["--wheel-slip", "1"], "wheel slip must be in [0, 1)"),
        (["--line-noise", "-1"], "--line-noise must be a finite number >= 0"),
    ],
)
def test_cli_embodied_bad_input_is_one_line(capsys, argv, message):
    """Each bad option: exit 2 and one line naming the problem."""
    base = ["explore", "--arena", "fig9", "--robots", "2"]
    args = base + argv
    if "--robots" in argv:
        args = ["explore", "--arena", "fig9", *argv]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1


def test_vertex_entry_is_a_counted_exchange_with_the_stations():
    """Every departure is a request, a grant and a 'left', plus at most one
    'clear' each; each robot may be on one more edge than it finished when the run ends."""
    result = explore_embodied(load_arena("arena1"), 2, seed=0)
    assert result.completed and result.collisions == 0
    finished, robots = result.total_traversals, 2
    assert 3 * finished <= result.station_messages <= 4 * (finished + robots)
    free = explore_embodied(load_arena("arena1"), 2, seed=0, config=EmbodiedConfig(
        collision_avoidance=False))
    assert free.station_messages == 0  # no stations without vertex entry
