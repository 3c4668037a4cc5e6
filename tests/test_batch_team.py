"""The batched robot type against the per-robot one on the same observations: Nagavarapu et al.'s
speed rule over pair arrays, the bench's team, the radio's batched send and receive, and
the batched loop (``mjswarm bench``'s) at 1000 robots."""

from __future__ import annotations

import numpy as np
import pytest

from algorithms.batch_collision import BatchCollisionRule
from algorithms.collision import CollisionRule, epsilons

S = 0.05


def bearing_streams(seed: int, n: int, ticks: int) -> list[dict[int, dict[int, float]]]:
    """Random bearings, tick by tick, ``{k: {p: beta}}`` (p sorted): pairs come into and
    leave the view at random; each follows a constant bearing (a collision course), a
    slow or a fast drift, near 0 (the same lane) or off axis, with or without noise, and
    sometimes across +-pi (unwrapping)."""
    rng = np.random.default_rng(seed)
    tracks = {}
    out = []
    for _ in range(ticks):
        for pair in list(tracks):
            if rng.random() < 0.02:
                del tracks[pair]
        for _ in range(rng.poisson(n / 8)):
            k, p = rng.choice(n, 2, replace=False).tolist()
            start = rng.choice([0.0, rng.uniform(-0.05, 0.05), rng.uniform(-1, 1), np.pi - 0.01])
            rate = rng.choice([0.0, 0.0, rng.normal(0, 0.0003), rng.normal(0, 0.01)])
            noise = rng.choice([0.0, 0.0, 0.002, 0.03])
            tracks.setdefault((k, p), [start, rate, noise])
        tick: dict[int, dict[int, float]] = {}
        for (k, p), track in sorted(tracks.items()):
            track[0] += track[1]
            beta = track[0] + (rng.normal(0, track[2]) if track[2] else 0.0)
            tick.setdefault(k, {})[p] = float(np.remainder(beta + np.pi, 2 * np.pi) - np.pi)
        out.append(tick)
    return out


@pytest.mark.parametrize("seed", range(4))
def test_batched_rule_speeds_equal_the_per_robot_rule(seed):
    """Per robot, per tick: the same speed, to the bit, on 40 robots' random streams
    (constant, drifting, noisy, wrapping bearings; pairs coming and going)."""
    n, eps = 40, epsilons(40)
    rules = [CollisionRule(S, e) for e in eps]
    batch = BatchCollisionRule(S, np.array(eps))
    robots = np.arange(n)
    for tick in bearing_streams(seed, n, 400):
        expected = [rules[i].update(tick.get(i, {})) for i in range(n)]
        pairs = [(k, p, b) for k, seen in sorted(tick.items()) for p, b in seen.items()]
        k, p, b = (np.array(x) for x in zip(*pairs)) if pairs else (np.empty(0, int),) * 3
        got = batch.update(robots, k.astype(int), p.astype(int), b.astype(float))
        assert got.tolist() == expected
    assert sum(r.activations for r in rules) > 50  # the streams reach every case


def test_batched_rule_steps_only_the_robots_it_is_given():
    """A robot not stepped in a tick keeps its bearing histories, as its own rule would."""
    eps = epsilons(3)
    rules = [CollisionRule(S, e) for e in eps]
    batch = BatchCollisionRule(S, np.array(eps))
    for t in range(60):
        robots = [0, 1, 2] if t % 3 else [0, 2]
        seen = {0: {1: 0.3}, 1: {2: 0.01 * t}, 2: {0: 0.0}}
        expected = [rules[i].update(seen[i]) for i in robots]
        k = np.array(robots)
        got = batch.update(k, k, np.array([next(iter(seen[i])) for i in robots]),
                           np.array([next(iter(seen[i].values())) for i in robots]))
        assert got.tolist() == expected


def run_bench_loop(n: int, ticks: int, physics: str, batched: bool) -> tuple:
    """Poses, commanded speeds and radio counters after ``ticks`` of the bench's loop."""
    from mjswarm.experiments.bench import bench_loop
    from mjswarm.worlds.bench import bench_world

    loop = bench_loop(bench_world(n, physics=physics), batched)
    loop.run(max_ticks=ticks)
    world = loop.world
    heard = (loop.team.heard.tolist() if batched
             else [loop.controllers[i].heard for i in range(n)])
    return (world.true_poses().tobytes(), world.commanded_speeds().tobytes(),
            world.radio.sent, world.radio.received, heard)


@pytest.mark.parametrize("physics", ["dynamic", "kinematic"])
def test_bench_team_runs_the_bench_robots_run(physics):
    """The batched bench (one BenchTeam, arrays through the world) and the per-robot one
    (a BenchRobot each) run the same trajectory, bit for bit, and hear the same messages."""
    batched = run_bench_loop(40, 60, physics, True)
    assert batched == run_bench_loop(40, 60, physics, False)
    assert sum(batched[4]) > 0 and len(set(np.frombuffer(batched[1]).tolist())) > 1


def test_bench_team_through_the_per_robot_adapter():
    """A world without arrays of its own (:class:`World`'s default ``observe_all`` and
    ``act_all``, robot by robot through Observation and Command) runs the team alike."""
    from mjswarm.experiments.bench import bench_loop
    from mjswarm.worlds.bench import bench_world
    from mjswarm.worlds.loop import World

    loops = [bench_loop(bench_world(12, physics="kinematic")) for _ in range(2)]
    world = loops[1].world
    world.observe_all = lambda robots: World.observe_all(world, robots)
    world.act_all = lambda robots, commands: World.act_all(world, robots, commands)
    for loop in loops:
        loop.run(max_ticks=40)
    a, b = (loop.world for loop in loops)
    assert a.true_poses().tobytes() == b.true_poses().tobytes()
    assert a.radio.received == b.radio.received
    assert loops[0].team.heard.tolist() == loops[1].team.heard.tolist()


def test_bench_team_is_deterministic_at_1000_robots():
    """Kinematic, 1000 robots, a few ticks: the same run twice, bit for bit."""
    first = run_bench_loop(1000, 5, "kinematic", True)
    assert first == run_bench_loop(1000, 5, "kinematic", True)
    assert sum(first[4]) > 1000


def drive_radio(radio, seed: int, ticks: int, names: list, batched: bool) -> list:
    """A random run in which the whole team reads and broadcasts at once (``batched``:
    ``receive_all`` and ``send_all``), else robot by robot; what every robot read."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0, 3, (len(names), 2))
    log = []
    for tick in range(ticks):
        xy += rng.normal(0, 0.2, xy.shape)
        radio.step(dict(zip(names, xy)))
        if rng.random() < 0.1 and len(radio.present) > 2:
            radio.remove(names[rng.integers(len(names))])
        if rng.random() < 0.1:
            radio.restore(names[rng.integers(len(names))])
        readers = [r for r in radio.present if rng.random() < 0.9]  # some skip a tick
        if batched:
            messages, copy, bounds = radio.receive_all(readers)
            inboxes = [[messages[c] for c in copy[lo:hi]] for lo, hi in zip(bounds, bounds[1:])]
        else:
            inboxes = [radio.receive(r) for r in readers]
        log += [(tick, r, [tuple(m) for m in inbox]) for r, inbox in zip(readers, inboxes)]
        senders = [r for r in radio.present if rng.random() < 0.8]
        if batched:
            radio.send_all(senders, ("beat", tick))
        else:
            for r in senders:
                radio.send(r, ("beat", tick))
        if rng.random() < 0.2 and len(radio.present) > 2:  # a sender leaves before delivery
            radio.remove(names[rng.integers(len(names))])
        log.append((tick, radio.last_batch, radio.dropped, radio.pending, dict(radio.sent)))
    return log


@pytest.mark.parametrize("seed", range(6))
def test_radio_batched_send_and_receive_equal_the_old_delivery(seed):
    """``send_all`` and ``receive_all`` against copy-by-copy delivery robot by robot (the
    reference of tests/test_radio_arrays.py): the same inboxes, in order, and counters."""
    from mjswarm.core.radio import Radio
    from test_radio_arrays import CopyRadio

    names = list(range(12)) if seed % 2 else [f"r{i}" for i in range(11)]
    drop = 0.3 if seed % 3 == 0 else 0.0
    batched = Radio(names, range_m=1.2, drop_prob=drop, rng=seed)
    reference = CopyRadio(names, range_m=1.2, drop_prob=drop, rng=seed)
    log = drive_radio(batched, seed, 60, names, True)
    assert log == drive_radio(reference, seed, 60, names, False)
    assert batched.received == reference.ref_received and batched.dropped == reference.dropped
    assert sum(batched.received.values()) > 100


def test_bench_team_commands_what_each_bench_robot_would():
    """On the same random readings (line sensors about the threshold, some NaN; bearing
    streams; inboxes), BenchTeam's row ``r`` is BenchRobot's command for the observation
    view of row ``r``, to the bit, and they count the same messages."""
    from algorithms.batch import Readings
    from algorithms.bench_robot import BenchRobot, BenchTeam
    from algorithms.navigation.percept import LINE_THRESHOLD_M
    from algorithms.robot import Message

    n, height, eps = 30, 0.02, epsilons(30)
    team = BenchTeam(BatchCollisionRule(S, np.array(eps)), height)
    robots = [BenchRobot(CollisionRule(S, e), height) for e in eps]
    rng = np.random.default_rng(7)
    ids = np.arange(n)
    for t, tick in enumerate(bearing_streams(3, n, 200)):
        line = height - LINE_THRESHOLD_M + rng.choice([-1e-3, 1e-3, np.nan], (n, 3))
        pairs = [(k, p, b) for k, seen in sorted(tick.items()) for p, b in seen.items()]
        k, p, b = (np.array(x) for x in zip(*pairs)) if pairs else (np.empty(0, int),) * 3
        counts = rng.integers(0, 3, n)
        inbox = [Message(("beat", t), None, int(s)) for s in rng.integers(0, n, counts.sum())]
        readings = Readings(ids, t * 0.02, line, np.full((n, 3), np.nan), np.zeros((n, 2)),
                            np.zeros((n, 2)), np.full(n, 7.4), k.astype(int), p.astype(int),
                            b.astype(float), inbox, np.arange(len(inbox)),
                            np.concatenate([[0], np.cumsum(counts)]))
        batch = team.step_all(readings)
        for r, robot in enumerate(robots):
            c = robot.step(readings.observation(r))
            assert (c.v_m_s, c.omega_rad_s, c.messages) == batch.command(r)
    assert team.heard.tolist() == [r.heard for r in robots]


def test_compiled_remainder_and_fsum_are_pythons():
    """The compiled rule's ``math.remainder(x, 2 pi)`` and ``math.fsum``, bit for bit, on
    random values, odd multiples of pi (the ties) and sums that cancel."""
    import math

    from algorithms.batch_collision import PARTIALS, _fsum, _remainder_2pi

    rng = np.random.default_rng(5)
    xs = [*rng.normal(0, 30, 2000).tolist(), *(k * math.pi for k in range(-41, 42)),
          *(math.pi * k + d for k in range(-9, 10, 2) for d in (-1e-15, 0.0, 1e-15))]
    assert [_remainder_2pi(x) for x in xs] == [math.remainder(x, 2 * math.pi) for x in xs]
    partials = np.empty(PARTIALS)
    for _ in range(300):
        w = int(rng.integers(1, 81))
        v = rng.normal(0, 1, w) * 10.0 ** rng.integers(-20, 20, w)
        v = np.concatenate([v, -v[: int(rng.integers(0, w + 1))] * (1 + 1e-16)])
        assert _fsum(v, partials) == math.fsum(v.tolist())


def test_batched_rule_decides_as_the_per_robot_rule_at_its_thresholds():
    """Bearings whose fitted rate lies within a few ulps of ``zero_rate``, on and off the
    lane: where plain sums could tip a decision, the compiled rule sums exactly, so every
    robot's speed is its own rule's, tick by tick."""
    from algorithms.collision import ZERO_RATE_RAD_S

    n, dt = 120, 0.02
    eps = epsilons(n)
    rules = [CollisionRule(S, e) for e in eps]
    batch = BatchCollisionRule(S, np.array(eps))
    robots = np.arange(n)
    per_tick = ZERO_RATE_RAD_S * dt * (1.0 + np.arange(-60, 60) * 2e-16)  # rad a tick
    start = np.where(robots % 2, 0.3, 0.01) + robots * 1e-3
    stopped = 0
    for t in range(30):
        beta = start + np.where(robots % 4 < 2, 1, -1) * per_tick * t
        expected = [rules[i].update({(i + 1) % n: float(beta[i])}) for i in range(n)]
        got = batch.update(robots, robots, (robots + 1) % n, beta)
        assert got.tolist() == expected
        stopped = max(stopped, sum(s < S for s in expected))
    assert 0 < stopped < n  # both sides of the threshold are reached
