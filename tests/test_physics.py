"""Physics regression for the Spark V model: speeds, turns, sensors, contacts, stability."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mjswarm.errors import MjswarmError
from mjswarm.core.robot import load_robot_spec
from mjswarm.core.simulation import Simulation
from mjswarm.core.world import FloorStrip, Pose2D, WallSegment, world_spec

SETTLE_S = 1.0


def drive(sim: Simulation, v: float, omega: float, seconds: float) -> None:
    sim.set_velocity(np.full(sim.n, v), np.full(sim.n, omega))
    sim.step(round(seconds / sim.control_dt_s))


@pytest.mark.parametrize("speed", [0.05, 0.20])
def test_straight_drive_speed_and_heading(one_robot, speed):
    drive(one_robot, speed, 0.0, SETTLE_S)
    start, t0 = one_robot.poses()[0].copy(), one_robot.time_s
    while np.hypot(*(one_robot.poses()[0, :2] - start[:2])) < 1.0:
        one_robot.step()
    end = one_robot.poses()[0]
    measured = np.hypot(*(end[:2] - start[:2])) / (one_robot.time_s - t0)
    assert measured == pytest.approx(speed, rel=0.05)
    assert abs(math.degrees(math.remainder(end[2] - start[2], 2 * math.pi))) < 2.0
    assert abs(end[1] - start[1]) < 0.035  # 2 degrees over 1 m


def test_command_above_top_speed_is_capped(one_robot):
    drive(one_robot, 0.5, 0.0, SETTLE_S)
    x0, t0 = one_robot.poses()[0, 0], one_robot.time_s
    drive(one_robot, 0.5, 0.0, 2.0)
    measured = (one_robot.poses()[0, 0] - x0) / (one_robot.time_s - t0)
    assert one_robot.geometry.max_speed_m_s == pytest.approx(0.20)
    assert 0.19 <= measured <= 0.2001


@pytest.mark.parametrize("omega", [-1.5, 0.8])
def test_turn_in_place_matches_kinematics(one_robot, omega):
    drive(one_robot, 0.0, omega, SETTLE_S)
    t0 = one_robot.time_s
    total = 0.0
    for _ in range(100):
        previous = one_robot.poses()[0, 2]
        one_robot.step()
        total += math.remainder(one_robot.poses()[0, 2] - previous, 2 * math.pi)
    rate = total / (one_robot.time_s - t0)
    assert rate == pytest.approx(omega, rel=0.05)
    assert np.hypot(*one_robot.poses()[0, :2]) < 0.01  # turned on the spot


def strip_world(offset_m: float) -> Simulation:
    """A robot facing +x whose line sensors sit ``offset_m`` left of a strip along y = 0."""
    strip = FloorStrip((-1.0, 0.0), (1.0, 0.0))
    return Simulation(world_spec([Pose2D(0.0, offset_m, 0.0)], strips=[strip]))


def test_line_sensor_sees_a_strip_with_margin():
    on = strip_world(0.0)
    off = strip_world(0.3)
    on.step(10)
    off.step(10)
    height = on.geometry.line_sensor_height_m
    floor = off.readings()["line"][0]
    centred = on.readings()["line"][0]
    # bare floor reads the mounting height everywhere
    np.testing.assert_allclose(floor, height, atol=0.001)
    # the 2 mm strip: centre sensor shorter by 2 mm, its neighbours see floor
    assert floor[1] - centred[1] == pytest.approx(0.002, abs=2e-4)
    assert abs(centred[0] - floor[0]) < 1e-4 and abs(centred[2] - floor[2]) < 1e-4


@pytest.mark.parametrize("offset,sensor", [(0.022, 2), (-0.022, 0)])
def test_side_line_sensors_respond_to_offset(offset, sensor):
    sim = strip_world(offset)  # robot left of the strip: the right sensor is over it
    sim.step(10)
    line = sim.readings()["line"][0]
    assert line[1] - line[sensor] == pytest.approx(0.002, abs=2e-4)


@pytest.mark.parametrize("gap_m", [0.02, 0.035, 0.05, 0.07, 0.09])
def test_ir_reads_wall_distance(gap_m):
    sim = Simulation(world_spec([Pose2D(0.0, 0.0, 0.0)], walls=[]))
    rim = sim.model.site("r0/ir_left").pos[1]  # the sensor's lateral offset from the centre
    wall_y = rim + gap_m + 0.01  # wall centre line; its face is 1 cm nearer
    sim = Simulation(world_spec([Pose2D(0.0, 0.0, 0.0)],
                                walls=[WallSegment((-0.5, wall_y), (0.5, wall_y))]))
    sim.step(10)
    ir = sim.readings()["ir"][0]
    assert ir[0] == pytest.approx(gap_m, abs=0.005)
    assert np.isnan(ir[1]) and np.isnan(ir[2])


@pytest.mark.parametrize("gap_m", [0.105, 0.3])
def test_ir_reads_nothing_beyond_range(gap_m):
    wall_x = 0.071 + gap_m + 0.01
    sim = Simulation(world_spec([Pose2D(0.0, 0.0, 0.0)],
                                walls=[WallSegment((wall_x, -0.5), (wall_x, 0.5))]))
    sim.step(10)
    assert np.isnan(sim.readings()["ir"][0]).all()


@pytest.mark.parametrize("speed", [0.1, 0.2])
def test_a_sudden_stop_does_not_pitch_the_line_sensors_onto_a_strip(one_robot, speed):
    """The motor ramp keeps the line sensors within 0.5 mm of their bare-floor reading
    when a robot is told to stop dead from cruising (an instant stop would dip them by the
    2 mm of a strip, and robots would follow phantom lanes)."""
    for _ in range(100):
        one_robot.set_velocity(speed, 0.0)
        one_robot.step()
    floor = one_robot.readings()["line"][0].min()  # cruising over bare floor
    lowest = floor
    for _ in range(50):
        one_robot.set_velocity(0.0, 0.0)
        one_robot.step()
        lowest = min(lowest, one_robot.readings()["line"][0].min())
    assert floor - lowest < 0.0005


def test_wheel_slip_makes_encoders_over_read_and_is_seeded():
    """--wheel-slip: the encoders advance by more than the wheels rolled, by a seeded
    random share; the physics is untouched."""
    def drive(slip, seed):
        sim = Simulation(world_spec([Pose2D(0.0, 0.0, 0.0)], margin_m=2.0), seed=seed,
                         wheel_slip=slip)
        for _ in range(50):
            sim.set_velocity(0.1, 0.0)
            sim.step()
        return sim.readings()["encoder"][0].copy(), sim.poses()[0].copy()
    clean, pose = drive(0.0, 0)
    slipped, slipped_pose = drive(0.05, 0)
    again, _ = drive(0.05, 0)
    other, _ = drive(0.05, 1)
    assert np.array_equal(pose, slipped_pose)
    assert np.all(slipped > clean) and np.all(slipped < clean * 1.1)
    assert np.array_equal(slipped, again) and not np.array_equal(slipped, other)
    with pytest.raises(MjswarmError, match="wheel slip"):
        Simulation(world_spec([Pose2D(0.0, 0.0, 0.0)]), wheel_slip=-0.1)


def test_scene_xml_loads_with_the_worlds_physics_settings():
    """models/scene.xml (for the viewer) uses the timestep and integrator every world
    uses (mjswarm.core.world), and holds one robot."""
    import mujoco

    from mjswarm.core.robot import MODELS_DIR, spark_v_geometry
    from mjswarm.core.world import PHYSICS_INTEGRATOR, PHYSICS_TIMESTEP_S

    model = mujoco.MjModel.from_xml_path(str(MODELS_DIR / "scene.xml"))
    assert model.opt.timestep == PHYSICS_TIMESTEP_S
    assert model.opt.integrator == PHYSICS_INTEGRATOR
    assert world_spec([Pose2D(0, 0, 0)]).option.integrator == model.opt.integrator
    assert spark_v_geometry().max_speed_m_s == pytest.approx(0.2)


def test_ten_minutes_of_random_commands_stay_stable():
    """Like menagerie's model tests: no NaN, no warning, upright, on the floor."""
    walls = [WallSegment(a, b) for a, b in [((-1, -1), (1, -1)), ((1, -1), (1, 1)),
                                               ((1, 1), (-1, 1)), ((-1, 1), (-1, -1))]]
    poses = [Pose2D(-0.4, -0.4, 0.3), Pose2D(0.4, 0.0, 2.0), Pose2D(-0.3, 0.5, -1.0)]
    sim = Simulation(world_spec(poses, walls=walls))
    rng = np.random.default_rng(7)
    min_up, heights = 1.0, []
    for _ in range(600):  # one new command per simulated second
        # beyond the top speed and turn rate: set_velocity scales each down to the limit
        sim.set_velocity(rng.uniform(-0.3, 0.3, sim.n), rng.uniform(-8.0, 8.0, sim.n))
        sim.step(round(1.0 / sim.control_dt_s))
        bodies = sim.robot_bodies
        min_up = min(min_up, sim.data.xmat[bodies][:, 8].min())  # cosine of the tilt
        heights.append(sim.data.xpos[bodies][:, 2].copy())  # axle heights (m)
    assert sim.time_s == pytest.approx(600.0)
    assert np.isfinite(sim.data.qpos).all() and np.isfinite(sim.data.qvel).all()
    assert sim.warnings() == {}
    assert min_up > math.cos(math.radians(10))
    assert np.all(np.abs(np.array(heights) - 0.025) < 0.005)
    assert np.all(np.abs(sim.poses()[:, :2]) < 1.0)


def test_head_on_robots_register_one_collision_event():
    sim = Simulation(world_spec([Pose2D(-0.3, 0.0, 0.0), Pose2D(0.3, 0.0, math.pi)]))
    drive(sim, 0.1, 0.0, 4.0)
    assert sim.collisions.count == 1
    _, i, j = sim.collisions.events[0]
    assert (i, j) == (0, 1)


def test_robots_side_by_side_never_collide():
    sim = Simulation(world_spec([Pose2D(0.0, 0.0, 0.0), Pose2D(0.0, 0.2, 0.0)]))
    drive(sim, 0.2, 0.0, 3.0)
    assert sim.collisions.count == 0


def qpos_history(seed: int) -> np.ndarray:
    sim = Simulation(world_spec([Pose2D(0.0, 0.0, 0.0), Pose2D(0.5, 0.3, 1.0)]),
                     seed=seed, line_noise_m=0.0005, ir_noise_m=0.001)
    rng = np.random.default_rng(seed)
    history = []
    for _ in range(100):
        sim.set_velocity(rng.uniform(-0.2, 0.2, sim.n), rng.uniform(-3.0, 3.0, sim.n))
        sim.step()
        history.append(np.concatenate([sim.data.qpos, sim.readings()["line"].ravel()]))
    return np.array(history)


def test_same_seed_same_trajectory_bit_for_bit():
    a, b = qpos_history(3), qpos_history(3)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, qpos_history(4))


def test_missing_model_file_is_one_clear_error(tmp_path):
    with pytest.raises(MjswarmError, match="robot model not found"):
        load_robot_spec(tmp_path / "nope.xml")


def test_malformed_model_file_is_one_clear_error(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco><worldbody><body")
    with pytest.raises(MjswarmError, match="malformed robot model") as info:
        load_robot_spec(bad)
    assert "\n" not in str(info.value)


def test_model_without_sensors_is_rejected(tmp_path):
    bare = tmp_path / "bare.xml"
    bare.write_text('<mujoco><worldbody><body name="spark_v"><freejoint/>'
                    '<geom size="0.05"/></body></worldbody></mujoco>')
    with pytest.raises(MjswarmError, match="lacks required elements: line_left"):
        load_robot_spec(bare)


def test_control_rate_must_divide_physics_rate():
    with pytest.raises(MjswarmError, match="must divide"):
        Simulation(world_spec([Pose2D(0, 0)]), control_hz=33.0)


def test_geom_groups_follow_menagerie():
    """Visual geoms (no contacts) in group 2, everything that collides in
    COLLISION_GROUP (robots, walls, floor), floor marks in STRIP_GROUP."""
    import mujoco

    from mjswarm.core.world import COLLISION_GROUP, STRIP_GROUP, FloorStrip

    sim = Simulation(world_spec([Pose2D(0, 0, 0)], strips=[FloorStrip((0, 0), (1, 0))],
                                walls=[WallSegment((0, 0.3), (1, 0.3))]))
    m = sim.model
    collides = (m.geom_contype != 0) | (m.geom_conaffinity != 0)
    robot = sim.geom_robot >= 0
    assert set(m.geom_group[robot & ~collides]) == {2}
    assert set(m.geom_group[collides]) == {COLLISION_GROUP}
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) for g in range(m.ngeom)]
    assert m.geom_group[names.index("strip0")] == STRIP_GROUP
    assert {"floor", "wall0", "r0/battery", "r0/chassis"} <= {
        n for n, c in zip(names, collides) if c}
    # models/scene.xml (for the viewer) groups its floor and strip as the worlds do
    from mjswarm.core.robot import MODELS_DIR

    scene = mujoco.MjModel.from_xml_path(str(MODELS_DIR / "scene.xml"))
    assert scene.geom("floor").group == COLLISION_GROUP and scene.geom("strip").group == STRIP_GROUP
    # the groups decide no rangefinder reading (MuJoCo's rangefinders test every group):
    # the same world with every geom in one group reads the same, bit for bit
    regrouped = Simulation(world_spec([Pose2D(0, 0, 0)], strips=[FloorStrip((0, 0), (1, 0))],
                                      walls=[WallSegment((0, 0.3), (1, 0.3))]), sensing="mujoco")
    regrouped.model.geom_group[:] = 5
    saw_wall = saw_strip = False
    for _ in range(150):  # a 0.2 m circle: over the strip, into the wall
        for s in (sim, regrouped):
            s.set_velocity(np.full(s.n, 0.1), np.full(s.n, 0.5))
            s.step()
        assert sim.readings().tobytes() == regrouped.readings().tobytes()
        saw_wall |= bool(np.isfinite(sim.readings()["ir"]).any())
        saw_strip |= bool((sim.readings()["line"] < 0.019).any())
    assert saw_wall and saw_strip
