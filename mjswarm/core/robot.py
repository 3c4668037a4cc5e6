"""The Spark V robot model: loading ``models/spark_v.xml`` and the geometry it defines.

The MJCF is the single source of truth for the robot's dimensions: wheel radius,
track width, top speed and sensor mounting heights are read from the compiled model,
never written twice. Loading errors (missing file, malformed XML, a model without the
named parts mjswarm drives) become one-line :class:`~mjswarm.errors.MjswarmError` s.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from pathlib import Path

import mujoco

from mjswarm.errors import MjswarmError, one_line

MODELS_DIR = Path(__file__).resolve().parents[2] / "models"
DEFAULT_ROBOT_XML = MODELS_DIR / "spark_v.xml"

#: The root body every robot model must name (an unnamed root silently drops
#: actuators and sensors when attached with a prefix).
ROOT_BODY = "spark_v"
LINE_SENSORS = ("line_left", "line_centre", "line_right")
IR_SENSORS = ("ir_left", "ir_front", "ir_right")
ENCODERS = ("enc_left", "enc_right")
WHEEL_SPEED_SENSORS = ("encvel_left", "encvel_right")
ACTUATORS = ("wheel_left", "wheel_right")
SENSOR_NAMES = LINE_SENSORS + IR_SENSORS + ENCODERS + WHEEL_SPEED_SENSORS


@dataclass(frozen=True)
class RobotGeometry:
    """Dimensions of the robot, read from its compiled model (SI units).

    Attributes:
        wheel_radius_m: driven wheel radius.
        track_m: distance between the two driven wheels' contact points.
        max_wheel_speed_rad_s: actuator ctrl limit (wheel angular speed).
        body_radius_m: chassis radius (robots collide at twice this distance).
        line_sensor_height_m: rangefinder reading of a line sensor over bare floor.
        line_sensor_ahead_m: how far ahead of the axle the line sensors look.
        line_sensor_spacing_m: lateral distance between neighbouring line sensors.
        ir_range_m: IR proximity cutoff (beyond it: "nothing").
        ir_side_offset_m: lateral distance from the robot's centre to the side IR sensors.
    """

    wheel_radius_m: float
    track_m: float
    max_wheel_speed_rad_s: float
    body_radius_m: float
    line_sensor_height_m: float
    line_sensor_ahead_m: float
    line_sensor_spacing_m: float
    ir_range_m: float
    ir_side_offset_m: float

    @property
    def max_speed_m_s(self) -> float:
        """Top forward speed (m/s): both wheels at their ctrl limit."""
        return self.max_wheel_speed_rad_s * self.wheel_radius_m


def load_robot_spec(path: str | Path = DEFAULT_ROBOT_XML) -> mujoco.MjSpec:
    """Load and check a robot MJCF; raise :class:`MjswarmError` with one line on failure."""
    path = Path(path)
    if not path.is_file():
        raise MjswarmError(f"robot model not found: {path}")
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except ValueError as exc:  # MuJoCo reports parse errors as multi-line ValueErrors
        raise MjswarmError(f"malformed robot model {path}: {one_line(exc)}") from None
    if spec.body(ROOT_BODY) is None:
        raise MjswarmError(f"robot model {path} has no root body named '{ROOT_BODY}'")
    sensors = {s.name for s in spec.sensors}
    actuators = {a.name for a in spec.actuators}
    missing = [n for n in SENSOR_NAMES if n not in sensors]
    missing += [n for n in ACTUATORS if n not in actuators]
    if missing:
        raise MjswarmError(f"robot model {path} lacks required elements: {', '.join(missing)}")
    return spec


def measure_geometry(model: mujoco.MjModel, prefix: str = "") -> RobotGeometry:
    """Dimensions of the robot named by ``prefix`` in a compiled model standing on z = 0.

    Works on the bare robot model (``prefix=""``) and on a world (``prefix="r0/"``): all
    quantities come from model constants relative to the robot's root body, whose
    height above the floor equals the wheel radius.
    """
    wheel = model.geom(prefix + "wheel_left")
    left, right = (model.body(prefix + f"wheel_{side}") for side in ("left", "right"))
    line = [model.site(prefix + name).pos for name in LINE_SENSORS]
    root_height = float(model.body(prefix + ROOT_BODY).pos[2])
    return RobotGeometry(
        wheel_radius_m=float(wheel.size[0]),
        track_m=float(abs(left.pos[1] - right.pos[1])),
        max_wheel_speed_rad_s=float(model.actuator(prefix + ACTUATORS[0]).ctrlrange[1]),
        body_radius_m=float(model.geom(prefix + "chassis").size[0]),
        line_sensor_height_m=root_height + float(line[1][2]),
        line_sensor_ahead_m=float(line[1][0]),
        line_sensor_spacing_m=float(abs(line[0][1] - line[1][1])),
        ir_range_m=float(model.sensor(prefix + IR_SENSORS[0]).cutoff[0]),
        ir_side_offset_m=float(model.site(prefix + IR_SENSORS[0]).pos[1]),
    )


@cache
def spark_v_geometry() -> RobotGeometry:
    """The shipped robot's dimensions (``models/spark_v.xml``), for worlds without a
    MuJoCo model of their own (the kinematic point world) and for defaults: the one home
    of the top speed and every other body constant."""
    return measure_geometry(load_robot_spec().compile())
