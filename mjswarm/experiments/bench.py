"""Benchmark: the full mjswarm step against bare ``mj_step`` on the same world.

For each robot count N the benchmark builds one world (:func:`mjswarm.worlds.bench.bench_world`:
robots in a grid, each on its own floor strip, walls beside every row) and measures, in the same process and run:

* ``realtime_factor``: simulated seconds per wall second of the full control loop
  (:func:`bench_loop`: one batched :class:`~algorithms.bench_robot.BenchTeam` for all robots,
  or one :class:`~algorithms.bench_robot.BenchRobot` controller per robot, the same run, in a
  :class:`~mjswarm.worlds.sparkworld.SparkWorld`, run by the one :class:`~mjswarm.worlds.loop.Loop`): every robot's line, IR, encoder and wheel-speed readings, its
  bearing sensor (+-60 degrees, 1 m, line of sight), a radio (range ``RADIO_RANGE_M``,
  links need line of sight both ways) on which every robot broadcasts a heartbeat every
  tick and reads its inbox, and per robot Nagavarapu et al.'s speed rule
  (:class:`~algorithms.batch_collision.BatchCollisionRule` over pair arrays, or
  :class:`~algorithms.collision.CollisionRule` per robot; bearing rates) setting the speed of a
  line follower that steers from the robot's own line sensors;
* ``physics_only_realtime_factor``: the same for bare ``mj_step`` on the same compiled
  model with sensors disabled and constant controls (dynamic physics in both tiers: the
  kinematic tier's ratio is to what it replaces);
* ``overhead_ratio``: their quotient (physics-only / full), i.e. how many times longer
  a full step takes than bare physics.

The two take turns in ``BLOCKS`` stretches of equal simulated time, so that the machine's
slow spells (this one is a shared virtual machine) fall on both alike.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass

import mujoco
import numpy as np

from algorithms.bench_robot import BenchRobot, BenchTeam
from algorithms.batch_collision import BatchCollisionRule
from algorithms.collision import CollisionRule, epsilons
from mjswarm.core.bearing import BearingSensor
from mjswarm.core.radio import Radio, sight_blocker
from mjswarm.core.robot import DEFAULT_ROBOT_XML
from mjswarm.core.simulation import SENSOR_OFF, Simulation
from mjswarm.errors import MjswarmError
from mjswarm.worlds.bench import bench_world
from mjswarm.worlds.loop import Loop
from mjswarm.worlds.sparkworld import SparkWorld

BENCH_SPEED_M_S = 0.1
RADIO_RANGE_M = 1.0
#: stretches in which the full loop and bare physics take turns (:func:`run_bench`)
BLOCKS = 8


@dataclass(frozen=True)
class BenchResult:
    """Figures for one robot count (rates in simulated seconds per wall second)."""

    robots: int
    physics: str
    sensing: str
    sim_seconds: float
    realtime_factor: float
    physics_only_realtime_factor: float
    overhead_ratio: float
    robot_steps_per_s: float


def bench_loop(sim: Simulation, batched: bool = True) -> Loop:
    """The full per-tick loop of N robots (module docstring) on ``sim``: one
    :class:`~algorithms.bench_robot.BenchTeam` for all (``batched``), else one
    :class:`~algorithms.bench_robot.BenchRobot` per robot (the reference: the same run)."""
    world = SparkWorld(sim, BearingSensor(sim))
    world.attach_radio(Radio(range(sim.n), range_m=RADIO_RANGE_M, blocked=sight_blocker(sim),
                             neighbours=sim.neighbours))
    height, eps = sim.geometry.line_sensor_height_m, epsilons(sim.n)
    if batched:
        rule = BatchCollisionRule(BENCH_SPEED_M_S, np.array(eps), dt=sim.control_dt_s)
        return Loop(world, {}, team=BenchTeam(rule, height))
    robots = {i: BenchRobot(CollisionRule(BENCH_SPEED_M_S, e, dt=sim.control_dt_s), height)
              for i, e in enumerate(eps)}
    return Loop(world, robots)


def run_bench(n: int, sim_seconds: float = 2.0, robot_xml: str = str(DEFAULT_ROBOT_XML),
              sensing: str = "auto", blocks: int = BLOCKS, physics: str = "dynamic",
              batched: bool = True) -> BenchResult:
    """Measure one robot count over ``sim_seconds`` of simulated time, the full loop in the
    ``physics`` tier (``batched``: the team's, else robot by robot) against bare dynamic
    physics (``mj_step``) of the same world.

    The full loop and bare physics take turns in ``blocks`` equal stretches, so a slow
    spell of the machine weighs on both alike; each rate is over all its stretches.
    """
    if sim_seconds <= 0:
        raise MjswarmError(f"benchmark duration must be positive, got {sim_seconds} s")
    if blocks < 1:
        raise MjswarmError(f"benchmark blocks must be >= 1, got {blocks}")
    sim = bench_world(n, robot_xml, sensing, physics)
    loop = bench_loop(sim, batched)
    loop.step()  # warm-up: one-time costs (loading the compiled ray loop) stay out of the timing
    bare = bench_world(n, robot_xml)
    m, d = bare.model, bare.data
    m.opt.disableflags |= SENSOR_OFF
    bare.set_velocity(np.full(n, BENCH_SPEED_M_S), np.zeros(n))

    ticks = max(blocks, round(sim_seconds / sim.control_dt_s))
    full_wall = bare_wall = 0.0
    for b in range(blocks):
        block = ticks * (b + 1) // blocks - ticks * b // blocks
        start = time.perf_counter()
        loop.run(max_ticks=loop.ticks + block)
        full_wall += time.perf_counter() - start
        start = time.perf_counter()
        mujoco.mj_step(m, d, nstep=block * bare.substeps)
        bare_wall += time.perf_counter() - start

    simulated = ticks * sim.control_dt_s
    return BenchResult(
        robots=n,
        physics=physics,
        sensing=sim.sensing,
        sim_seconds=simulated,
        realtime_factor=simulated / full_wall,
        physics_only_realtime_factor=simulated / bare_wall,
        overhead_ratio=full_wall / bare_wall,
        robot_steps_per_s=n * ticks * sim.substeps / full_wall,
    )


def as_dict(result: BenchResult) -> dict:
    return asdict(result)
