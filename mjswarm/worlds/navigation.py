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


#: How much a Spark V's odometry over-reads a turn in place with exact encoders, by
#: physics tier: the dynamic tier's wheels scrub the floor (noise-free scans measured
#: 1.0163-1.0172 on ``arena2`` at 0.05 and 0.2 m/s), the kinematic tier's roll exactly
#: (``python benchmarks/turn_over_read.py``).
TURN_OVER_READ = {"dynamic": 1.0167, "kinematic": 1.0}


def calibration(geom: RobotGeometry, physics: str = "dynamic") -> RobotCalibration:
    """The robot's knowledge of its own body, from its model, calibrated on the floor of
    the ``physics`` tier."""
    return RobotCalibration(
        wheel_radius_m=geom.wheel_radius_m,
        track_m=geom.track_m,
        line_ahead_m=geom.line_sensor_ahead_m,
        max_speed_m_s=geom.max_speed_m_s,
        line_floor_m=geom.line_sensor_height_m,
        body_radius_m=geom.body_radius_m,
        line_spacing_m=geom.line_sensor_spacing_m,
        turn_over_read=TURN_OVER_READ[physics],
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
        lane_start_m=geometry.LANE_END_RADIUS_M,
    )
