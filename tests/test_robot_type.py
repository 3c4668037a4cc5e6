"""The robot type and the one loop: what an observation may hold, that worlds fill it
from sensors only, the radio's one tick of latency through the loop, and the hooks."""

from __future__ import annotations

import gc
import math

import numpy as np
import pytest

from algorithms.robot import Command, Controller, Message, Observation
from mjswarm.worlds.bench import bench_world
from mjswarm.errors import MjswarmError
from mjswarm.worlds.loop import Loop, LoopFunctions
from mjswarm.worlds.openfloor import PointWorld
from mjswarm.core.radio import Radio
from mjswarm.worlds.sparkworld import SparkWorld

#: Everything an observation may hold: the robot's own id and clock, its own sensors,
#: what its exteroceptive sensors and radio report, the beacon it stands on. A field
#: added here must be something a real robot could have (algorithms/robot.py).
ALLOWED_FIELDS = ("robot", "time_s", "line_m", "ir_m", "encoder_rad", "wheel_speed_rad_s",
                  "battery_v", "pose", "bearings", "detections", "inbox", "neighbors",
                  "beacon", "vertex", "leg")


def test_an_observation_holds_only_what_a_robot_could_sense():
    assert Observation._fields == ALLOWED_FIELDS
    assert Command._fields == ("v_m_s", "omega_rad_s", "velocity_m_s", "messages", "signal",
                               "edge_rad", "events")


class Recorder(Controller):
    """Keeps every observation; sends ``say(tick)`` as a broadcast when it gives one."""

    def __init__(self, say=None) -> None:
        self.seen: list[Observation] = []
        self.say = say

    def step(self, observation: Observation) -> Command:
        self.seen.append(observation)
        words = self.say(len(self.seen) - 1) if self.say else None
        return Command(messages=(Message(words),) if words is not None else ())


def test_the_point_worlds_pose_is_its_sensor_and_detections_match_brute_force():
    rng = np.random.default_rng(5)
    for case in range(20):
        n = int(rng.integers(2, 9))
        xy = rng.uniform(-2, 2, (n, 2))
        w = PointWorld([tuple(p) for p in xy], seed=case, position_noise_m=0.01,
                       detection_range_m=1.5)
        for i in range(n):
            w.place(i, tuple(xy[i]), float(rng.uniform(-math.pi, math.pi)))
            w.show(i, f"robot {i}")
        truth = w.true_poses()
        for i in range(n):
            obs = w.observe(i)
            assert obs.pose is not None and not np.allclose(obs.pose[:2], truth[i, :2])
            expected = {}
            for k in range(n):
                d = math.dist(truth[i, :2], truth[k, :2])
                if k != i and d <= 1.5:
                    b = math.atan2(truth[k, 1] - truth[i, 1], truth[k, 0] - truth[i, 0])
                    expected[k] = (d, math.remainder(b - truth[i, 2], 2 * math.pi))
            assert set(obs.detections) == set(expected)
            for k, (d, b) in expected.items():
                got = obs.detections[k]
                assert got.range_m == pytest.approx(d) and got.bearing_rad == pytest.approx(b)
                assert got.signal == f"robot {k}"


def test_spark_robots_observe_their_own_sensors_and_no_pose():
    sim = bench_world(4)
    world = SparkWorld(sim)
    obs = world.observe(2)
    r = sim.readings()[2]
    assert obs.pose is None and obs.beacon is None and obs.robot == 2
    assert list(obs.line_m) == r["line"].tolist() and obs.battery_v == r["battery"]


def test_a_message_sent_in_one_tick_is_read_in_the_next():
    world = PointWorld([(0.0, 0.0), (0.5, 0.0), (5.0, 0.0)])
    world.attach_radio(Radio(range(3), range_m=1.0))
    robots = {0: Recorder(lambda t: f"hello {t}" if t < 2 else None),
              1: Recorder(), 2: Recorder()}
    Loop(world, robots).run(max_ticks=4)
    heard = [[m.payload for m in o.inbox] for o in robots[1].seen]
    assert heard == [[], ["hello 0"], ["hello 1"], []]
    assert all(not o.inbox for o in robots[2].seen)  # out of range
    assert robots[1].seen[1].inbox[0].sender == 0
    assert robots[1].seen[0].neighbors == frozenset({0})
    assert world.radio.total_sent == 2


def test_hooks_run_in_order_and_stop_the_loop():
    calls = []

    class Trace(LoopFunctions):
        def initialize(self, loop):
            calls.append("initialize")

        def before_step(self, loop):
            calls.append("before")

        def after_step(self, loop):
            calls.append(f"after {loop.stepped}")

        def should_stop(self, loop):
            return loop.ticks == 2

        def result(self, loop):
            return loop.ticks

    world = PointWorld([(0.0, 0.0), (1.0, 0.0)])
    assert Loop(world, {0: Recorder(), 1: Recorder()}, [Trace()]).run() == [2]
    assert calls == ["initialize"] + ["before", "after [0, 1]"] * 2
    assert world.time_s == pytest.approx(0.2)


class Logged(PointWorld):
    """A point world that logs the loop's calls."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.log: list[str] = []

    def observe(self, i):
        self.log.append(f"observe {i}")
        return super().observe(i)

    def act(self, i, command):
        self.log.append(f"act {i}")
        super().act(i, command)

    def step(self):
        self.log.append("step")
        super().step()


class Counting(Recorder):
    def __init__(self) -> None:
        super().__init__()
        self.resets = 0

    def reset(self) -> None:
        self.resets += 1
        self.seen.clear()


def test_the_loop_senses_all_then_controls_all_then_acts_all_then_steps():
    """ARGoS's phases: no robot acts before every robot has sensed."""
    world = Logged([(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)])
    Loop(world, {i: Recorder() for i in range(3)}).run(max_ticks=2)
    tick = ["observe 0", "observe 1", "observe 2", "act 0", "act 1", "act 2", "step"]
    assert world.log == tick * 2


def test_the_loop_resets_a_controller_when_its_robot_enters_the_floor():
    world = PointWorld([(0.0, 0.0), (1.0, 0.0)], present=[True, False])
    robots = {0: Counting(), 1: Counting()}
    loop = Loop(world, robots)
    loop.run(max_ticks=2)
    assert (robots[0].resets, robots[1].resets) == (1, 0)  # before its first step only
    world.place(1, (1.0, 0.0))
    loop.run(max_ticks=3)
    assert (robots[0].resets, robots[1].resets) == (1, 1) and len(robots[1].seen) == 1
    world.place(1, None)  # taken off the floor, then put back: a new episode
    loop.run(max_ticks=4)
    world.place(1, (1.0, 0.0))
    loop.run(max_ticks=5)
    assert robots[1].resets == 2 and len(robots[1].seen) == 1


def test_a_message_without_a_radio_is_an_error():
    world = PointWorld([(0.0, 0.0)])
    with pytest.raises(MjswarmError, match="no radio"):
        Loop(world, {0: Recorder(lambda t: "hi")}).step()


def test_a_run_freezes_the_collector_while_it_runs_and_leaves_it_as_it_found_it():
    seen = []

    class Probe(LoopFunctions):
        def after_step(self, loop):
            seen.append(gc.get_freeze_count())
            if loop.ticks == 3:
                raise RuntimeError("a hook failed")

    world = PointWorld([(0.0, 0.0)])
    assert gc.get_freeze_count() == 0
    with pytest.raises(RuntimeError, match="a hook failed"):
        Loop(world, {0: Recorder()}, [Probe()]).run(max_ticks=5)
    assert seen[0] > 0 and gc.get_freeze_count() == 0  # frozen in the run, thawed after
    gc.freeze()  # a caller's own freeze is left alone
    try:
        Loop(world, {0: Recorder()}).run(max_ticks=2)
        assert gc.get_freeze_count() > 0  # not thawed by the run
    finally:
        gc.unfreeze()
