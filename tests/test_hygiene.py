"""Hygiene that the types enforce: nothing a robot observes or hears
reaches the world's ground truth. Every Observation handed out and every Message
delivered in a short run of each experiment is walked (attributes and containers, to a
bounded depth) and must not reference a World, a Simulation, a beacon store (a dict of
beacons), the Radio, MuJoCo's model or data, or a robot's controller. And the other way
round: an experiment's loop functions reach a controller only through the Controller
protocol (a :class:`Sealed` controller fails on anything else)."""

from __future__ import annotations

import math
import sys

import mujoco
import numpy as np
import pytest

from algorithms.exploration.base import Beacon, BeaconHandle, ExpiredBeacon
from algorithms.robot import Controller, Observation
from mjswarm.arena import load_arena
from mjswarm.core.radio import Radio
from mjswarm.core.simulation import Simulation
from mjswarm.worlds.loop import Loop, World

FORBIDDEN = (World, Simulation, Radio, Controller, mujoco.MjModel, mujoco.MjData)
MAX_DEPTH, MAX_NODES = 8, 20000


def offences(root) -> list[str]:
    """What in ``root``'s object graph is forbidden (a path for each)."""
    found, seen, stack, nodes = [], set(), [(root, "observation", 0)], 0
    while stack and nodes < MAX_NODES:
        obj, path, depth = stack.pop()
        if id(obj) in seen or depth > MAX_DEPTH:
            continue
        seen.add(id(obj))
        nodes += 1
        if isinstance(obj, FORBIDDEN):
            found.append(f"{path}: {type(obj).__name__}")
            continue
        if obj is None or isinstance(obj, (str, bytes, int, float, complex, np.ndarray)):
            continue
        if isinstance(obj, dict):
            if obj and all(isinstance(v, Beacon) for v in obj.values()):
                found.append(f"{path}: a beacon store")
            children = [*((k, f"{path}[key]") for k in obj),
                        *((v, f"{path}[{k!r}]") for k, v in obj.items())]
        elif isinstance(obj, (tuple, list, set, frozenset)):
            children = [(v, f"{path}[{i}]") for i, v in enumerate(obj)]
        elif hasattr(obj, "items") and callable(obj.items):  # a read-only mapping
            children = [(v, f"{path}[{k!r}]") for k, v in obj.items()]
        else:
            names = list(getattr(obj, "__dict__", {}))
            for cls in type(obj).__mro__:
                names += [s for s in getattr(cls, "__slots__", ()) if isinstance(s, str)]
            children = [(getattr(obj, n), f"{path}.{n}") for n in names if hasattr(obj, n)]
        stack += [(c, p, depth + 1) for c, p in children]
    return found


@pytest.fixture
def watched(monkeypatch):
    """Every observation of every loop run in the test is walked; the offences found."""
    found: list[str] = []
    counted = {"observations": 0, "messages": 0}
    step = Loop.step

    def watching_step(self):
        world = self.world
        if "observe" not in vars(world):
            observe = world.observe

            def checked(i):
                o = observe(i)
                counted["observations"] += 1
                counted["messages"] += len(o.inbox)
                found.extend(offences(o))
                return o
            world.observe = checked
        step(self)

    monkeypatch.setattr(Loop, "step", watching_step)
    return found, counted


def test_the_walker_finds_what_is_forbidden():
    spec = load_arena("fig9")
    bad = Observation(0, 0.0, beacon={v: Beacon() for v in spec.vertices})
    assert [o.split(": ")[1] for o in offences(bad)] == ["a beacon store"]
    assert offences(Observation(0, 0.0, inbox=((Controller,),))) == []


def test_a_beacon_handle_works_only_in_its_tick():
    beacon = Beacon()
    handle = BeaconHandle(beacon)
    handle.id, handle.data = "a1", {"x": 1}
    assert (beacon.id, beacon.data) == ("a1", {"x": 1}) and handle.id == "a1"
    handle.expire()
    with pytest.raises(ExpiredBeacon):
        handle.data
    with pytest.raises(ExpiredBeacon):
        handle.id = "b1"


def _clean(watched, least_messages: int = 0):
    found, counted = watched
    assert counted["observations"] > 0 and counted["messages"] >= least_messages
    assert found == [], found[:5]


def test_embodied_exploration_hands_out_nothing_forbidden(watched):
    from mjswarm.experiments.runs import run_exploration
    from mjswarm.experiments.exploration import EmbodiedConfig

    run_exploration(load_arena("fig9"), 2, world="embodied", seed=0, max_time=40.0,
                    config=EmbodiedConfig(speed_m_s=0.15))
    _clean(watched, 1)  # the stations' replies


def test_connected_embodied_exploration_hands_out_nothing_forbidden(watched):
    from mjswarm.experiments.runs import run_exploration
    from mjswarm.experiments.exploration import EmbodiedConfig

    run_exploration(load_arena("lattice:1x5:0.75"), 3, world="embodied", seed=0,
                    max_time=80.0, radio_range_m=1.2, connectivity="connected",
                    config=EmbodiedConfig(speed_m_s=0.1))
    _clean(watched, 100)


def test_graph_world_exploration_hands_out_nothing_forbidden(watched):
    from mjswarm.experiments.runs import run_exploration

    result = run_exploration(load_arena("fig9"), 3, world="graph", seed=0)
    assert result.completed
    _clean(watched)


@pytest.mark.parametrize("connectivity", ["connected", "biconnected"])
def test_radio_graph_world_exploration_hands_out_nothing_forbidden(watched, connectivity):
    """Tethered robots, relays, the base and the docked robot on the loop: observations
    and delivered messages hold values only (a relay request names a leg by beacon id)."""
    from mjswarm.experiments.runs import run_exploration

    result = run_exploration(load_arena("lattice:4x4"), 5, world="graph", seed=0,
                             radio_range_m=1.3, connectivity=connectivity)
    assert result.messages > 0 and (result.completed or result.reason is not None)
    _clean(watched, 1000)


def test_old_beacon_handles_raise_in_the_graph_world():
    """A controller that keeps its handle finds it dead at its next call."""
    from mjswarm.worlds.graphworld import GraphWorld
    from algorithms.robot import Command

    class Hoarder(Controller):
        def __init__(self):
            self.kept, self.errors = [], 0

        def step(self, o):
            for old in self.kept:
                try:
                    old.id
                except ExpiredBeacon:
                    self.errors += 1
            self.kept.append(o.beacon)
            return Command(edge_rad=o.vertex.angles_rad[0])

    spec = load_arena("fig9")
    world = GraphWorld(spec.graph(), spec.root)
    world.reset(1)
    robot = Hoarder()
    Loop(world, {0: robot}).run(max_ticks=3)
    assert robot.errors == 0 + 1 + 2


def test_coverage_hands_out_nothing_forbidden(watched):
    from mjswarm.experiments.coverage import CoverageRun

    CoverageRun(2.0, "heuristic", "point", seed=0).run(3)
    _clean(watched, 100)  # the add / remove protocol's messages


def test_patrol_hands_out_nothing_forbidden(watched):
    from mjswarm.experiments.patrol import run_trial

    run_trial(6, 0, "point", steps=60)
    _clean(watched, 100)


class Sealed(Controller):
    """A controller nobody may look into: only the Controller protocol (reset, perceive,
    step, telemetry) reaches the robot inside; reading or writing anything else fails."""

    PROTOCOL = frozenset({"reset", "perceive", "step", "telemetry"})

    def __init__(self, inner: Controller) -> None:
        object.__setattr__(self, "_inner", inner)

    def __getattribute__(self, name):
        if name in Sealed.PROTOCOL or (name.startswith("__") and name.endswith("__")):
            return object.__getattribute__(self, name)
        raise AssertionError(f"something read the controller's {name!r}")

    def __setattr__(self, name, value):
        raise AssertionError(f"something wrote the controller's {name!r}")

    def _inside(self) -> Controller:
        return object.__getattribute__(self, "_inner")

    def reset(self):
        Sealed._inside(self).reset()

    def perceive(self, observation):
        Sealed._inside(self).perceive(observation)

    def step(self, observation):
        return Sealed._inside(self).step(observation)

    def telemetry(self):
        return Sealed._inside(self).telemetry()


def test_a_sealed_controller_refuses_its_attributes():
    from algorithms.maintenance.roles import Role, RoleParams, RoleSwitchingRobot

    robot = Sealed(RoleSwitchingRobot(1, Role.EXPLORER, RoleParams()))
    assert robot.telemetry()["role"] == Role.EXPLORER.value
    with pytest.raises(AssertionError, match="read the controller's 'role'"):
        robot.role
    with pytest.raises(AssertionError, match="wrote the controller's 'target'"):
        robot.target = None


def test_the_patrol_experimenter_talks_to_robots_only_through_the_protocol(watched,
                                                                           monkeypatch):
    """Targets go to the base station as messages, roles and connections come back as
    signals and events: the mission runs on sealed robots."""
    from algorithms.maintenance.roles import RoleSwitchingRobot
    from mjswarm.experiments import patrol

    monkeypatch.setattr(patrol, "RoleSwitchingRobot",
                        lambda *a, **k: Sealed(RoleSwitchingRobot(*a, **k)))
    result = patrol.run_trial(10, 0, "point", steps=600)
    assert result.targets_reached >= 1 and result.aat_robots["tests_per_robot_step"] > 0
    _clean(watched, 100)


@pytest.mark.parametrize("method", ["stamps", "tables", "tables-2"])
def test_the_connectivity_checks_hand_out_nothing_forbidden(watched, method):
    from mjswarm.experiments.connectivity.harness import run_check
    from mjswarm.experiments.connectivity.team import Team

    ring = Team(positions={f"r{i}": (math.cos(i * math.pi / 4), math.sin(i * math.pi / 4))
                           for i in range(8)})
    result = run_check(ring, method, range_m=0.9)
    assert result.connected and result.biconnected
    _clean(watched, 8)


class SealedMind:
    """A robot's mind that only the robot's own software (code of ``algorithms``) may
    look into: an experiment reading it fails."""

    def __init__(self, inner) -> None:
        object.__setattr__(self, "_inner", inner)

    def __getattribute__(self, name):
        caller = sys._getframe(1).f_globals.get("__name__", "")
        if not caller.startswith("algorithms."):
            raise AssertionError(f"{caller} read the mind's {name!r}")
        return getattr(object.__getattribute__(self, "_inner"), name)


@pytest.fixture
def sealed(monkeypatch):
    """Every loop of the test runs sealed controllers (:class:`Sealed`)."""
    init = Loop.__init__

    def sealing_init(self, world, controllers, *args, **kwargs):
        init(self, world, {i: Sealed(c) for i, c in controllers.items()}, *args, **kwargs)

    monkeypatch.setattr(Loop, "__init__", sealing_init)


def test_every_experiment_runs_on_sealed_controllers(sealed, monkeypatch):
    """Coverage (adds and a dismissal), the connectivity checks, embodied, graph and
    radio-graph exploration learn of their robots from telemetry and events only."""
    from mjswarm.experiments.connectivity import harness
    from mjswarm.experiments.connectivity.team import Team
    from mjswarm.experiments.coverage import CoverageRun
    from mjswarm.experiments.exploration import EmbodiedConfig
    from mjswarm.experiments.runs import run_exploration

    episodes = CoverageRun(2.0, "heuristic", "point", seed=0).run(3).episodes
    assert {e.action for e in episodes} == {"add", "remove"}
    checkers = harness._checkers
    monkeypatch.setattr(harness, "_checkers", lambda *a: {
        r: SealedMind(m) for r, m in checkers(*a).items()})
    ring = Team(positions={f"r{i}": (math.cos(i * math.pi / 4), math.sin(i * math.pi / 4))
                           for i in range(8)})
    for method in ("stamps", "tables"):
        check = harness.run_check(ring, method, range_m=0.9)
        assert check.connected and check.biconnected
    assert check.articulation_points == []
    run_exploration(load_arena("fig9"), 2, world="embodied", seed=0, max_time=8.0,
                    config=EmbodiedConfig(speed_m_s=0.15))
    assert run_exploration(load_arena("fig9"), 3, world="graph", seed=0).completed
    result = run_exploration(load_arena("lattice:3x3"), 4, world="graph", seed=0,
                             radio_range_m=1.3, connectivity="biconnected")
    assert result.messages > 0


def test_the_world_never_calls_a_loop_function(monkeypatch):
    """While the world senses, acts, steps or switches a robot off, no loop function's
    code runs: loop functions hand the world the beacons and the faults in their hooks."""
    from mjswarm.experiments.exploration import EmbodiedConfig
    from mjswarm.experiments.faults import parse_fault
    from mjswarm.experiments.runs import run_exploration
    from mjswarm.worlds.loop import LoopFunctions
    from mjswarm.worlds.sparkworld import SparkWorld

    inside = []

    def world_code(method):
        def run(self, *args, **kwargs):
            inside.append(method.__name__)
            try:
                return method(self, *args, **kwargs)
            finally:
                inside.pop()
        return run

    def experiment_code(cls, method):
        def run(*args, **kwargs):
            assert not inside, f"the world's {inside[-1]} called {cls.__name__}.{method.__name__}"
            return method(*args, **kwargs)
        return run

    for name in ("observe", "act", "step", "power_off"):
        monkeypatch.setattr(SparkWorld, name, world_code(getattr(SparkWorld, name)))
    classes = [LoopFunctions]
    while classes:
        cls = classes.pop()
        classes += cls.__subclasses__()
        for name, method in list(vars(cls).items()):
            if callable(method) and not name.startswith("__"):
                monkeypatch.setattr(cls, name, experiment_code(cls, method))
    result = run_exploration(load_arena("fig9"), 2, world="embodied", seed=0, max_time=12.0,
                             config=EmbodiedConfig(speed_m_s=0.15,
                                                   faults=(parse_fault("robot:2@6"),)))
    assert any(f["fired"] for f in result.faults)
