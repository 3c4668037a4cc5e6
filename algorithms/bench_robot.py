"""The benchmark's robot: a line follower with Nagavarapu et al.'s speed rule and a radio
heartbeat, the per-tick work of a team that senses, decides and talks every tick
(:mod:`mjswarm.experiments.bench`), as one robot (:class:`BenchRobot`) and as a batched
team (:class:`BenchTeam`) that commands what every one of its robots would."""

from __future__ import annotations

import numpy as np

from algorithms.batch import BatchCommand, BatchController, Readings
from algorithms.batch_collision import BatchCollisionRule
from algorithms.collision import CollisionRule
from algorithms.navigation.percept import LINE_THRESHOLD_M
from algorithms.robot import Command, Controller, Message, Observation

#: the line follower's turn rate when one side sensor sees the strip (rad/s)
TURN_GAIN_RAD_S = 0.8
#: what every robot broadcasts every tick (a heartbeat carries nothing but its sender)
HEARTBEAT = (Message("heartbeat"),)


class BenchRobot(Controller):
    """The bench's controller: hears its inbox and broadcasts a heartbeat every tick,
    sets its speed with Nagavarapu et al.'s speed rule from its bearings and steers towards the
    darker side with a proportional line follower on its own line sensors."""

    def __init__(self, rule: CollisionRule, line_sensor_height_m: float) -> None:
        self.rule = rule
        self.height_m = line_sensor_height_m
        self.heard = 0

    def step(self, observation: Observation) -> Command:
        self.heard += len(observation.inbox)
        line = observation.line_m
        turn = (TURN_GAIN_RAD_S if self.height_m - line[0] > LINE_THRESHOLD_M else 0.0) - (
            TURN_GAIN_RAD_S if self.height_m - line[2] > LINE_THRESHOLD_M else 0.0)
        return Command(self.rule.update(observation.bearings), turn, None, HEARTBEAT)


class BenchTeam(BatchController):
    """:class:`BenchRobot` for a whole team at once: the same commands, from arrays (the
    speed rule over pair arrays, :class:`~algorithms.batch_collision.BatchCollisionRule`);
    ``heard`` counts each robot's messages (by robot id)."""

    def __init__(self, rule: BatchCollisionRule, line_sensor_height_m: float) -> None:
        self.rule = rule
        self.height_m = line_sensor_height_m
        self.heard = np.zeros(rule.n, np.int64)

    def step_all(self, readings: Readings) -> BatchCommand:
        robots = readings.robots
        self.heard[robots] += readings.inbox_counts()
        dark = self.height_m - readings.line_m[:, ::2] > LINE_THRESHOLD_M  # left, right
        turn = np.where(dark[:, 0], TURN_GAIN_RAD_S, 0.0) - np.where(dark[:, 1], TURN_GAIN_RAD_S, 0.0)
        speed = self.rule.update(robots, robots[readings.bearing_row], readings.bearing_id,
                                 readings.bearing_rad)
        return BatchCommand(speed, turn, np.ones(len(robots), bool), HEARTBEAT[0].payload)
