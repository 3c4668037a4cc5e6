"""The robustness stress grid and the noise grid (mjswarm.experiments.stress):
a fast representative of each failure class and of each noise by default, the whole grids
with ``-m slow``."""

from __future__ import annotations

import pytest

from mjswarm.experiments.faults import parse_fault
from mjswarm.experiments.stress import (
    MAX_HEADING_ERROR_DEG,
    NOISE_ARENAS,
    NOISES,
    SAMPLE_SPEEDS_M_S,
    SAMPLE_TEAMS,
    Noise,
    StressRun,
    DEAD_SPEEDS_M_S,
    PHYSICS,
    dead_grid,
    dense_grid,
    grid,
    main,
    noise_grid,
    noise_table,
    passed,
    run_grid,
    table,
)


@pytest.mark.parametrize("run", [
    # 1. a vertex with edges 67.5 degrees apart: the approach was captured by a
    #    neighbouring spoke's inner end
    StressRun("narrow-fan", 1, 0.05, 0),
    # 1. the validator's minimum, 45 degrees, at the top speed
    StressRun("fan:3:45@17", 1, 0.2, 0),
    # 2. 0.15 m/s: the speed rule's sudden stop pitched the body onto a phantom lane
    StressRun("fig9", 2, 0.15, 0),
    # 3. robots waiting on vertex centres stopped others by the speed rule for ever
    StressRun("arena2", 4, 0.2, 1),
], ids=str)
def test_failure_class_representatives(run):
    result = run.run(max_sim_time_s=1200.0)
    assert passed(result), (result.ended_because, result.collisions, result.stopped_robots)
    assert result.ended_because == "completed"


def test_grid_leaves_out_teams_larger_than_the_arena():
    runs = grid(arenas=("narrow-fan",), speeds=(0.1,), teams=(1, 4, 10))
    assert [r.robots for r in runs] == [1]  # 3 edges


def test_table_counts_what_it_ran():
    rows = run_grid([StressRun("narrow-fan", 1, 0.2, 0)], workers=1)
    text = table(rows)
    assert "| `narrow-fan` | 1 | 1 | 1 | 0 | 0 |" in text


#: Dense teams at the top speed, one robot for every 4 to 7 edges, where a robot on its lane
#: could stop for good (speed rule, beta = 0) for one standing on the centre of the vertex
#: beyond the next, which waits for the vertex the first holds. The rule takes bearings
#: in the lane's frame (the navigator's lane_bearings), so a nose turned a few degrees off
#: the lane does not bring such a robot into the cone.
DENSE = [StressRun("lattice:5x5", 10, 0.2, 0), StressRun("lattice:6x6", 12, 0.2, 1),
         StressRun("lattice:8x8", 16, 0.2, 2)]


@pytest.mark.slow
@pytest.mark.parametrize("run", DENSE, ids=str)
def test_dense_teams_at_top_speed_complete(run):
    result = run.run(max_sim_time_s=2400.0)
    assert passed(result), (result.ended_because, result.collisions, result.stopped_robots)


def test_a_dense_team_at_top_speed_completes():
    """The dense-team grid's fast representative: one robot for every 4 edges of a 4x4
    lattice at 0.2 m/s (about 20 s of CPU time)."""
    result = StressRun("lattice:4x4", 6, 0.2, 0).run(max_sim_time_s=1200.0)
    assert passed(result), (result.ended_because, result.collisions, result.stopped_robots)


def test_the_dense_grid_gives_one_robot_for_every_7_5_and_4_edges():
    runs = dense_grid(arenas=("lattice:6x6",), speeds=(0.2,), seeds=(0,))
    assert [r.robots for r in runs] == [60 // 7, 60 // 5, 60 // 4]


@pytest.mark.parametrize("argv,message", [
    (["--sample"], "--sample needs --noise or --dense"),
    (["--dense", "--noise"], "choose one of --noise, --dense and --dead"),
    (["--dead", "--dense"], "choose one of --noise, --dense and --dead"),
    (["--dense", "--only-slip"], "--slip and --only-slip need --noise"),
])
def test_stress_flags_that_do_not_go_together_are_refused(capsys, argv, message):
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2 and message in capsys.readouterr().err


def test_the_dead_grid_spreads_faults_over_robots_times_speeds_and_tiers():
    runs = dead_grid(arenas=("tree3", "lattice:4x4"))
    faults = [parse_fault(r.fault) for r in runs]
    assert all(0 <= f.robot < r.robots for f, r in zip(faults, runs))
    assert {r.robots for r in runs} == {2, 4, 8}
    assert {r.physics for r in runs} == set(PHYSICS)
    assert {r.speed_m_s for r in runs} == set(DEAD_SPEEDS_M_S)
    times = [f.at_s for f in faults]
    assert min(times) == 0.0 and max(times) > 100.0 and len(set(times)) > len(times) // 3


@pytest.mark.slow
def test_the_dead_robot_grid_passes():
    """The dead-robot grid: every run completes the true map or the reachable part
    (a closed root included), no contact, nobody stopped but the failed robot."""
    rows = run_grid(dead_grid(), workers=2)
    failures = [(r, res.ended_because, res.collisions, res.stopped_robots)
                for r, res, _ in rows if not passed(res)]
    assert failures == []


@pytest.mark.slow
@pytest.mark.parametrize("make", [grid, dense_grid], ids=["stress", "dense"])
def test_the_whole_grid_passes(make):
    rows = run_grid(make(), workers=2)
    failures = [(r, res.ended_because, res.collisions, res.stopped_robots)
                for r, res, _ in rows if not passed(res)]
    assert failures == []


@pytest.mark.slow
@pytest.mark.parametrize("arena,robots,speed", [
    ("arena2", 4, 0.2), ("arena2", 4, 0.15), ("fig9", 2, 0.15), ("lattice:10x10", 10, 0.05),
])
def test_issue_13_reports_pass_with_default_seeds(arena, robots, speed):
    """Runs of the main arenas and a big lattice, as the CLI runs them (no seed)."""
    result = StressRun(arena, robots, speed, None).run()
    assert passed(result), (result.ended_because, result.collisions, result.stopped_robots)


@pytest.mark.slow
def test_a_lone_robot_keeps_its_heading_over_384_legs():
    """Odometry heading error stays within 5 degrees over a 300+ leg run (the 384 legs of
    lattice:12x12)."""
    result = StressRun("lattice:12x12", 1, 0.2, None).run(max_sim_time_s=20000.0)
    assert passed(result) and result.total_traversals >= 300
    assert result.heading_error_deg < 5.0


@pytest.mark.parametrize("run", [
    # 0.5 mm of line noise: a fixed threshold would find phantom spokes (the dynamic
    # tier's floor reads 0.46 mm below the calibration, 0.54 mm from that threshold)
    StressRun("fan:3:45@17", 1, 0.2, 0, Noise(line_m=0.0005), "dynamic"),
    StressRun("fig9", 2, 0.15, 0, Noise(ir_m=0.002), "kinematic"),
    StressRun("fig9", 2, 0.15, 0, Noise(bearing_deg=2.0), "kinematic"),
    # slip 0.05: the first scan over-read a turn to 380 degrees, beyond the 20 degrees
    # that told the first spoke coming round
    StressRun("fan:3:45@17", 1, 0.2, 0, Noise(wheel_slip=0.05), "dynamic"),
    StressRun("fan:3:45@17", 1, 0.2, 1, NOISES[-1], "kinematic"),
    # line noise 0.5 mm, 45 degree junction: leaving r3, the left sensor found the corner
    # of the neighbouring edge's lane first and the robot followed it (lost)
    StressRun("wheel:4@8", 1, 0.1, 0, Noise(line_m=0.0005), "kinematic"),
    # every noise, 0.1 m/s: leaving v3, R4's line window went 7, 9, 7, 9 tick by tick (its
    # noise estimate at 7's limit), its new lane's centre turned on and off, and it took
    # the lane for ended (lost at 218.3 s, four edges unreachable)
    StressRun("random-planar:8:1", 4, 0.1, 0, NOISES[-1], "kinematic"),
], ids=str)
def test_noise_representatives(run):
    result = run.run(max_sim_time_s=1200.0)
    assert passed(result, MAX_HEADING_ERROR_DEG), (
        result.ended_because, result.collisions, result.stopped_robots,
        result.heading_error_deg)


def test_leaving_a_45_degree_junction_under_every_noise_keeps_off_a_neighbours_spoke():
    """The noise grid's ``wheel:4@8``, 4 robots, 0.1 m/s, every noise with slip 0.05,
    kinematic, seed 1: leaving ``r2``, R1's right sensor finds the outer end of the spoke
    45 degrees to the left, 9 cm short of its lane's start, and must not follow it off the
    vertex. The heading is the slip's (slip 0.05 does not meet the heading criterion,
    ``docs/exploration.md``), not asserted here."""
    result = StressRun("wheel:4@8", 4, 0.1, 1, NOISES[-1], "kinematic").run(max_sim_time_s=1200.0)
    assert passed(result), (result.ended_because, result.collisions, result.stopped_robots)


def test_noise_grid_covers_every_noise_alone_and_together_in_both_tiers():
    runs = noise_grid(arenas=("fig9",), speeds=(0.1,), teams=(2,), seeds=(0,))
    assert {(r.noise, r.physics) for r in runs} == {
        (n, t) for n in NOISES for t in ("dynamic", "kinematic")}
    together = NOISES[-1]
    assert (together.line_m, together.ir_m, together.bearing_deg, together.wheel_slip) == (
        0.0005, 0.002, 2.0, 0.05)


def test_the_sample_covers_every_class_noise_and_tier_at_both_ends_of_the_speeds():
    """``--noise --sample``: every arena class under every noise (alone and together), in
    both tiers, at 0.05 and 0.2 m/s, once."""
    runs = noise_grid(speeds=SAMPLE_SPEEDS_M_S, teams=SAMPLE_TEAMS, seeds=(0,))
    cells = {(r.arena, r.speed_m_s, r.noise, r.physics) for r in runs}
    assert len(cells) == len(runs) == len(NOISE_ARENAS) * 2 * len(NOISES) * 2
    assert {r.speed_m_s for r in runs} == {0.05, 0.2}


def test_noise_table_counts_the_heading_criterion():
    run = StressRun("narrow-fan", 1, 0.2, 0, Noise(ir_m=0.002), "kinematic")
    rows = [(run, run.run(), 1.0)]
    assert "| IR 2 mm | kinematic | 1 | 1 | 1 | 0 | 0 |" in noise_table(rows)


@pytest.mark.slow
def test_the_whole_noise_grid_passes():
    rows = run_grid(noise_grid(), workers=2)
    failures = [(r, res.ended_because, res.collisions, res.stopped_robots,
                 res.heading_error_deg)
                for r, res, _ in rows if not passed(res, MAX_HEADING_ERROR_DEG)]
    assert failures == []
