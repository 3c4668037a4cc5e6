"""What a Spark V navigator knows of its own body and of the arena marks.

Calibration (wheel radius, track, sensor mounting) comes from the robot's model, arena
conventions from :mod:`mjswarm.arena.geometry`: the robot knows its own body and the
kind of marks it is built to read, never the arena's graph or anybody's ground-truth
pose. The navigators themselves (:mod:`algorithms.navigation`) run in controllers.
"""

from __future__ import annotations

from algorithms.navigation import ArenaConventions, RobotCalibration
from mjswarm.arena import geometry
from mjswarm.core.robot import RobotGeometry


def calibration(geom: RobotGeometry) -> RobotCalibration:
    """The robot's knowledge of its own body, from its model."""
    return RobotCalibration(
        wheel_radius_m=geom.wheel_radius_m,
        track_m=geom.track_m,
        line_ahead_m=geom.line_sensor_ahead_m,
        max_speed_m_s=geom.max_speed_m_s,
        line_floor_m=geom.line_sensor_height_m,
        body_radius_m=geom.body_radius_m,
        line_spacing_m=geom.line_sensor_spacing_m,
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
        strip_width_m=geometry.STRIP_WIDTH_M,
    )
