"""The embodied adapter between :class:`~mjswarm.simulation.Simulation` and the robots'
navigators (:mod:`algorithms.navigation`).

Each control tick it turns every robot's own sensor record into a
:class:`~algorithms.navigation.Percept` (line sensors thresholded into "strip / no
strip", IR as distance or NaN, encoders), lets each robot's navigator answer with
``(v, omega)``, and applies the commands. Calibration (wheel radius, track, sensor
mounting) comes from the robot's model, arena conventions from
:mod:`mjswarm.arena.geometry`: the robot knows its own body and the kind of marks it is
built to read, never the arena's graph or anybody's ground-truth pose.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from algorithms.navigation import ArenaConventions, Navigator, Percept, RobotCalibration
from mjswarm.arena import geometry
from mjswarm.robot import RobotGeometry
from mjswarm.simulation import Simulation

#: A line sensor sees a strip when its reading is this much (m) below the bare-floor
#: reading: half the 2 mm strip thickness.
LINE_THRESHOLD_M = 0.001


def calibration(geom: RobotGeometry) -> RobotCalibration:
    """The robot's knowledge of its own body, from its model."""
    return RobotCalibration(
        wheel_radius_m=geom.wheel_radius_m,
        track_m=geom.track_m,
        line_ahead_m=geom.line_sensor_ahead_m,
        max_speed_m_s=geom.max_speed_m_s,
    )


def conventions(geom: RobotGeometry) -> ArenaConventions:
    """The arena marks the robots read (:mod:`mjswarm.arena.geometry`), and where the
    corridor wall appears to a robot of this geometry on its lane."""
    wall_face = geometry.CORRIDOR_HALF_WIDTH_M - geometry.WALL_THICKNESS_M / 2
    return ArenaConventions(
        lane_offset_m=geometry.LANE_OFFSET_M,
        spoke_inner_radius_m=geometry.SPOKE_INNER_RADIUS_M,
        spoke_radius_m=geometry.SPOKE_RADIUS_M,
        wall_distance_m=wall_face - geometry.LANE_OFFSET_M - geom.ir_side_offset_m,
    )


def percepts(sim: Simulation) -> list[Percept]:
    """Every robot's reading of this tick as a :class:`Percept`."""
    readings = sim.readings()
    on_line = (sim.geometry.line_sensor_height_m - readings["line"]) > LINE_THRESHOLD_M
    return [
        Percept(tuple(bool(b) for b in on_line[i]), tuple(float(d) for d in readings["ir"][i]),
                tuple(float(e) for e in readings["encoder"][i]))
        for i in range(sim.n)
    ]


class NavigationDriver:
    """Steps a simulation with one navigator per robot.

    Args:
        sim: the world.
        headings: each robot's initial heading in its own reference frame (rad): the
            compass reading it starts with.
        speed_m_s: cruising speed of every navigator.
    """

    def __init__(self, sim: Simulation, headings: Sequence[float], speed_m_s: float,
                 turn_rate_rad_s: float = 1.0) -> None:
        self.sim = sim
        cal, conv = calibration(sim.geometry), conventions(sim.geometry)
        self.navigators = [Navigator(cal, conv, h, speed_m_s, turn_rate_rad_s) for h in headings]
        self._v = np.zeros(sim.n)
        self._w = np.zeros(sim.n)

    def step(self) -> None:
        """One control tick: sense, decide, act, simulate."""
        for i, (nav, percept) in enumerate(zip(self.navigators, percepts(self.sim))):
            self._v[i], self._w[i] = nav.update(percept)
        self.sim.set_velocity(self._v, self._w)
        self.sim.step()
