"""The line filter and the scan hold under sensor noise (pure, no physics)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from algorithms.collision import CollisionRule
from algorithms.navigation.motions import Scan, SeekLine
from algorithms.navigation.odometry import Odometry, RobotCalibration
from algorithms.navigation.percept import (
    LINE_THRESHOLD_M,
    WALL_SPREAD_M,
    LineFilter,
    WallWatch,
    percept,
)

FLOOR_M = 0.020  # the calibration's bare-floor reading
SUNK_M = 0.0195  # what the dynamic tier reads over the floor: the body sinks 0.46 mm
STRIP_M = 0.002  # strip height


def single_threshold(d: float) -> bool:
    """The plain detection: one reading against one threshold."""
    return FLOOR_M - d > LINE_THRESHOLD_M


@pytest.mark.parametrize("sigma", [0.00025, 0.0005])
def test_bare_floor_never_reads_as_a_strip(sigma):
    """The dynamic tier's floor under noise: the single threshold sees strips several
    times a second (0.25 mm leaves it 2 sigma), the filter none after its warm-up."""
    rng = np.random.default_rng(1)
    readings = SUNK_M + rng.normal(0.0, sigma, (3000, 3))
    flt = LineFilter(FLOOR_M)
    filtered = [flt(r)[0] for r in readings]
    assert sum(any(single_threshold(d) for d in r) for r in readings) > 100  # teeth
    assert not any(any(on) for on in filtered[50:])


def test_a_strip_is_seen_as_one_run_with_its_lag():
    """Floor, 30 ticks of strip, floor, at 0.5 mm: one run, of the strip's length,
    reported ``lag`` ticks late."""
    rng = np.random.default_rng(2)
    truth = [False] * 200 + [True] * 30 + [False] * 100
    flt = LineFilter(FLOOR_M)
    out = []
    for on in truth:
        d = SUNK_M - (STRIP_M if on else 0.0)
        (left, centre, right), lag = flt([d + rng.normal(0, 0.0005) for _ in range(3)])
        out.append((centre, lag))
    centre = [c for c, _ in out]
    rises = [i for i in range(1, len(centre)) if centre[i] and not centre[i - 1]]
    falls = [i for i in range(1, len(centre)) if centre[i - 1] and not centre[i]]
    assert len(rises) == len(falls) == 1
    lag = out[rises[0]][1]
    # window 7 at 0.5 mm (5 sigmas: 6.25 readings), or 9 once the estimate has been over
    # 7's limit (0.53 mm) and not since 10 % below it
    assert lag in (3, 4)
    assert abs(rises[0] - lag - 200) <= 2 and abs(falls[0] - lag - 230) <= 2


def strip_crossings(sigma: float, seed: int, strips: int = 80) -> int:
    """How many times the centre sensor turns on over ``strips`` strips (12 ticks each,
    25 of floor between) read with noise ``sigma`` (m)."""
    rng = np.random.default_rng(seed)
    flt = LineFilter(FLOOR_M)
    truth = [False] * 100 + ([True] * 12 + [False] * 25) * strips
    centre = [flt(SUNK_M - (STRIP_M if on else 0.0) + rng.normal(0.0, sigma, 3))[0][1]
              for on in truth]
    return sum(b and not a for a, b in zip(centre, centre[1:]))


def test_a_noise_at_a_window_limit_sees_each_strip_once():
    """Noises at a window's limit (0.5 and 0.54 mm about 7 readings' 0.53 mm, 0.33 mm
    about 5 readings' 0.32 mm) move the estimate across the limit again and again; a
    window that followed it tick by tick would change its mean and lag mid-strip and see
    some strips twice (a robot would take its new lane for ended). The window shrinks
    only with ``WINDOW_HYSTERESIS`` to spare: each strip once."""
    assert all(strip_crossings(sigma, seed) == 80 for sigma in (0.0005, 0.00054, 0.00033)
               for seed in range(6))


def test_noise_free_readings_pass_unfiltered():
    """Exact sensors: window 1 and no lag once the noise is known (results unchanged)."""
    flt = LineFilter(FLOOR_M)
    for _ in range(20):
        flt([FLOOR_M, FLOOR_M - STRIP_M, FLOOR_M])
    assert flt.window == 1
    assert flt([FLOOR_M - STRIP_M, FLOOR_M, FLOOR_M]) == ((True, False, False), 0)


def on_a_spoke(x, y, spokes_deg):
    """Whether the floor point (x, y) (m, from the vertex centre) is on one of the spokes:
    30 mm strips from 30 to 120 mm along each direction (``mjswarm.arena.geometry``)."""
    for s in map(math.radians, spokes_deg):
        along, across = x * math.cos(s) + y * math.sin(s), y * math.cos(s) - x * math.sin(s)
        if abs(across) < 0.015 and 0.03 <= along <= 0.12:
            return True
    return False


def scan_spokes(spokes_deg, sigma, seed, min_width, over_read=0.0, spoke_width=0.0,
                off_m=(0.0, 0.0), direction=1):
    """A robot scanning in place at 1 rad/s, 50 Hz, with its axle at ``off_m`` from the
    vertex centre, over spokes 35 degrees wide (a 30 mm strip at the sensor's 50 mm), its
    odometry reading ``1 + over_read`` times the turn; returns the Scan when done."""
    rng = np.random.default_rng(seed)
    odo = Odometry(RobotCalibration(0.025, 0.12, 0.05, 0.2))
    flt = LineFilter(FLOOR_M)
    scan = Scan(1.0, direction, min_width, spoke_width)
    theta = 0.0
    for _ in range(2000):
        true = theta / (1.0 + over_read)
        on = on_a_spoke(off_m[0] + 0.05 * math.cos(true), off_m[1] + 0.05 * math.sin(true),
                        spokes_deg)
        d = SUNK_M - (STRIP_M if on else 0.0)
        odo.theta = theta
        odo.update((0.0, 0.0))
        p = percept([d + rng.normal(0, sigma) for _ in range(3)], [math.nan] * 3, (0.0, 0.0),
                    flt)
        if scan.step(odo, p) is None:
            return scan
        theta += 0.02 * direction
    return scan


@pytest.mark.parametrize("seed", range(3))
def test_scan_finds_each_spoke_once_at_its_centre_under_noise(seed):
    spokes = [100.0, 145.0, 260.0]
    scan = scan_spokes(spokes, 0.0005, seed, math.asin(0.3))
    assert scan.full_turn == pytest.approx(2 * math.pi, abs=math.radians(2))
    found = sorted(math.degrees(m) % 360 for m in scan.mids)
    assert found == pytest.approx(spokes, abs=2.0)


@pytest.mark.parametrize("over_read", [0.0, 0.07, 0.09])
def test_an_uncalibrated_scan_that_over_reads_its_turn_still_closes_it(over_read):
    """The noise grid's "all noises" run: a first scan can read 384 degrees for one turn
    (scrub and slip 0.05), past a symmetric 22.5 degrees. Odometry never under-reads a
    turn: the window is skewed to over-reading, and spokes 45 degrees apart stay apart."""
    spokes = [100.0, 145.0, 260.0]
    scan = scan_spokes(spokes, 0.0005, 0, math.asin(0.3), over_read)
    assert scan.full_turn == pytest.approx(2 * math.pi * (1 + over_read), abs=math.radians(2))
    assert len(scan.mids) == 3


SPOKE_WIDTH = 2.0 * math.asin(0.3)  # a 30 mm strip at the sensor's 50 mm: 35 degrees


def test_a_scan_off_the_centre_tells_spokes_45_degrees_apart_under_noise():
    """``wheel:4@8``, 4 robots, 0.05 m/s, line noise 0.5 mm, dynamic: a robot standing
    6 mm across its incoming spoke at ``r3`` (spokes at 53, 98 and 143 degrees) sees the
    gap between the spokes at 98 and 143 degrees shrink to 4 readings under its sensor,
    which the line filter's 7 cannot open; one spoke per run would report one spoke at
    124 degrees, between two edges. Here 9.5 mm across: without ``spoke_width`` (one
    spoke per run) the scan merges them; with it, three spokes, within 2.5
    degrees once corrected for standing off the centre (six noise seeds)."""
    from algorithms.navigation.navigator import off_centre_correction

    spokes, incoming = [53.0, 98.0, 143.0], math.radians(53.0)
    off = (0.0095 * math.cos(incoming - math.pi / 2), 0.0095 * math.sin(incoming - math.pi / 2))
    merged = 0
    for seed in range(6):
        one_per_run = scan_spokes(spokes, 0.0005, seed, SPOKE_WIDTH / 2, off_m=off,
                                  direction=-1)
        merged += len(one_per_run.mids) < len(spokes)
        scan = scan_spokes(spokes, 0.0005, seed, SPOKE_WIDTH / 2, spoke_width=SPOKE_WIDTH,
                           off_m=off, direction=-1)
        # one scan's full turn spreads about a degree here (the worst of 60 seeds: 2.7)
        assert scan.full_turn == pytest.approx(2 * math.pi, abs=math.radians(3))
        found = off_centre_correction([m % (2 * math.pi) for m in scan.mids], incoming, 0.05)
        assert [math.degrees(a) for a in found] == pytest.approx(spokes, abs=2.5)
    assert merged >= 4  # teeth


def test_bearing_noise_neither_triggers_nor_suppresses_the_rule():
    """2 degrees of bearing noise: a robot whose bearing turns at 0.1 rad/s (passing) is
    never taken for a collision course; one at a constant bearing (a collision course)
    is, within the longest window. The 10-sample window alone (the noise-free
    rule) triggers on the passing robot."""
    rng = np.random.default_rng(3)
    noise = math.radians(2.0)
    passing = [{1: 0.4 + 0.1 * 0.02 * i + rng.normal(0, noise)} for i in range(300)]
    rule = CollisionRule(0.1, 0.2)
    assert [rule.update(b) for b in passing] == [0.1] * 300
    betas = [b[1] for b in passing]
    slopes = [np.polyfit(np.arange(10) * 0.02, betas[i:i + 10], 1)[0] for i in range(290)]
    assert sum(abs(r) < rule.zero_rate for r in slopes) > 5  # teeth: a fixed 10 triggers
    course = [{1: 0.4 + rng.normal(0, noise)} for _ in range(120)]
    rule = CollisionRule(0.1, 0.2)
    speeds = [rule.update(b) for b in course]
    assert speeds[-1] == pytest.approx(0.08) and rule.activations == 1
    short = CollisionRule(0.1, 0.2, max_window=20)  # too short to tell: suppressed
    assert [short.update(b) for b in course] == [0.1] * 120


WALL_M, TOLERANCE_M = 0.024, 0.012  # the corridor wall from the lane, the navigator's tolerance


def test_a_noisy_wall_near_the_tolerance_does_not_end_and_its_end_is_seen():
    """IR noise 2 mm on a wall read at the far edge of its spread in motion (0.031 m,
    5 mm inside the tolerance): one reading against the tolerance misses it several
    times (a vertex detected mid-wall), the debounced watch never; the wall's real end
    (nothing in range) is seen within ``confirm_ticks`` readings."""
    rng = np.random.default_rng(3)
    watch = WallWatch(WALL_M, TOLERANCE_M)
    readings = WALL_M + WALL_SPREAD_M + rng.normal(0.0, 0.002, 3000)
    seen = [watch(d) for d in readings]
    assert sum(abs(d - WALL_M) > TOLERANCE_M for d in readings) > 5  # teeth
    assert all(seen)
    assert 2 <= watch.confirm_ticks <= 4
    gone = [watch(math.nan) for _ in range(watch.confirm_ticks)]
    assert gone == [True] * (watch.confirm_ticks - 1) + [False]


def test_noise_free_wall_readings_are_judged_one_by_one():
    """Without noise (readings drifting by a fraction of a millimetre a tick, as in
    motion) one reading off the wall ends it: noise-free runs keep their results."""
    watch = WallWatch(WALL_M, TOLERANCE_M)
    for d in np.linspace(0.020, 0.030, 40):
        assert watch(d)
    assert watch.confirm_ticks == 1
    assert not watch(math.nan)


def test_the_speed_rule_sees_bearings_along_the_lane_not_the_swung_nose():
    """``arena2``, 4 robots, 0.2 m/s, 0.5 mm line noise, kinematic (the noise grid's
    sample): a robot whose nose has swung 4.4 degrees on its lane sees a robot standing on
    the vertex beyond the next one 1.3 degrees off its nose, inside the rule's 2.6 degree
    "same lane" cone; stopping for it would wait for ever, since that robot waits for the
    vertex the first holds. In the lane's frame that robot is 5.7 degrees off (slow, not stop); the lane's direction does not
    follow the nose while the robot stands."""
    from algorithms.navigation.navigator import ArenaConventions, Navigator, NavigatorState

    cal = RobotCalibration(wheel_radius_m=0.02, track_m=0.1, line_ahead_m=0.05,
                           max_speed_m_s=0.2)
    conv = ArenaConventions(lane_offset_m=0.09, spoke_inner_radius_m=0.03,
                            spoke_radius_m=0.12, wall_distance_m=0.024, strip_width_m=0.03,
                            lane_start_m=0.16)
    nav = Navigator(cal, conv, -math.pi / 2, 0.2)
    wheels = [0.0, 0.0]
    dt = 0.02

    def tick(line, moving=True):
        v, w = nav.update(percept([FLOOR_M - STRIP_M * on for on in line], (math.nan,) * 3,
                                  tuple(wheels), nav.line_filter))
        if moving:
            wheels[0] += (v - w * cal.track_m / 2) / cal.wheel_radius_m * dt
            wheels[1] += (v + w * cal.track_m / 2) / cal.wheel_radius_m * dt

    tick((False, False, False))
    nav.depart(-math.pi / 2)
    while nav.state is not NavigatorState.ON_EDGE:  # the sidestep, then the lane ahead
        tick((False, isinstance(nav._plan[0][0], SeekLine), False))
    for _ in range(50):
        tick((False, True, False))
    theta_lane = nav.odometry.theta
    for _ in range(3):  # the right sensor catches the strip's edge: a swing to the right
        tick((False, True, True))
    for _ in range(5):
        tick((False, True, False))
    swing = math.degrees(nav.odometry.theta - theta_lane)
    assert swing < -3.0
    ahead = {1: math.radians(-1.3)}  # a robot standing beyond, seen off the swung nose
    raw, along = CollisionRule(0.2, 0.2, same_lane=0.045), CollisionRule(0.2, 0.2, same_lane=0.045)
    for _ in range(20):
        raw.update(ahead)
        along.update(nav.lane_bearings(ahead))
    assert raw.speed == 0.0  # teeth: the nose's bearing stops it
    assert 0.0 < along.speed < 0.2  # the lane's: a robot off the lane, slow down
    tick((False, True, False), moving=False)  # it stops (its last move is read now)
    before = nav.lane_bearings(ahead)[1]
    for _ in range(200):  # standing, its centre sensor alone on the strip
        tick((False, True, False), moving=False)
    assert nav.lane_bearings(ahead)[1] == pytest.approx(before)


def test_the_running_median_equals_the_median_of_the_last_values():
    import statistics
    from collections import deque

    from algorithms.navigation.percept import RunningMedian

    rng = np.random.default_rng(7)
    for size in (1, 2, 5, 450):
        running, window = RunningMedian(size), deque(maxlen=size)
        for value in rng.choice([0.0, 1e-4, 2e-4, 3e-4], 2000) + rng.normal(0, 1e-4, 2000) * (
                rng.random(2000) < 0.5):
            running.append(float(value))
            window.append(float(value))
            assert running.median() == statistics.median(window)
