"""The robot catalogue (models/robots.py, models/<robot>/): every robot compiles and steps cleanly, the box
chassis collides with its own shape (a cylinder its inscribed circle misses can touch a corner), the IK
controller's wheel radius and track come from the model, and the catalogue's robots drive dense-field-30."""

import math
from dataclasses import replace

import mujoco
import numpy as np
import pytest

from swarmnav.models.errors import ConfigError
from swarmnav.models.robots import ROBOTS
from swarmnav.models.scenario import load_scenario, parse_scenario
from swarmnav.models.scenario_obstacles import Obstacle
from swarmnav.sim.episode import EpisodeSpec, run_episode
from swarmnav.sim.scene import compile_scene
from swarmnav.sim.stepper import reset_data

EMPTY = """
name = "robot-probe"
time_limit_s = 4.0
arena = {{ width_m = 6.0, height_m = 6.0, walls = false }}
robot = {{ model = "{model}", radius_m = 0.1 }}
start = {{ x = 3.0, y = 3.0, heading_deg = {heading} }}
goal = {{ x = 5.5, y = 5.5 }}
"""


def probe(model: str, heading_deg: float = 0.0):
    return parse_scenario(EMPTY.format(model=model, heading=heading_deg))


@pytest.mark.parametrize("model", sorted(ROBOTS))
def test_every_robot_compiles_names_everything_and_steps_one_second_without_warnings(model):
    scene = compile_scene(probe(model))
    m = scene.model
    for kind, count in ((mujoco.mjtObj.mjOBJ_GEOM, m.ngeom), (mujoco.mjtObj.mjOBJ_ACTUATOR, m.nu),
                        (mujoco.mjtObj.mjOBJ_SENSOR, m.nsensor)):
        assert all(mujoco.mj_id2name(m, kind, i) for i in range(count))
    data = reset_data(probe(model), scene)
    rng = np.random.default_rng(0)
    for _ in range(500):
        data.ctrl[:] = rng.uniform(-1, 1, 2) * scene.drive.max_wheel_speed_rad_s * 0.5
        mujoco.mj_step(m, data)
    assert not any(w.number for w in data.warning)
    assert abs(data.qpos[2]) < 0.02  # still on its wheels


@pytest.mark.parametrize("model", ["jackal", "turtlebot3_burger"])
def test_driving_straight_at_a_commanded_speed_matches_it(model):
    """The controller turns (v, omega) into wheel speeds with the model's wheel radius: at steady state the
    base moves at the commanded speed (a wrong radius would scale it)."""
    scenario = probe(model)
    scene = compile_scene(scenario)
    data = reset_data(scenario, scene)
    v = 0.5 * ROBOTS[model].max_speed_m_s
    data.ctrl[:] = v / scene.drive.wheel_radius_m
    for _ in range(1500):
        mujoco.mj_step(scene.model, data)
    assert data.qvel[0] == pytest.approx(v, rel=0.03)


def test_the_box_chassis_touches_a_cylinder_that_its_inscribed_circle_misses():
    robot = ROBOTS["jackal"]
    x0, y0, x1, y1 = robot.footprint_m
    corner = math.atan2(y1, x1)
    radius = 0.05
    centre_m = robot.inscribed_radius_m + radius + 0.04  # the inscribed circle misses it by 4 cm
    assert centre_m - radius < math.hypot(x1, y1) < centre_m + radius  # the corner is inside it
    touched = {}
    side_on_deg = math.degrees(corner) - 90.0  # the obstacle straight off the robot's left side
    for heading_deg in (0.0, side_on_deg):
        scenario = probe("jackal", heading_deg)
        ob = Obstacle(3.0 + centre_m * math.cos(corner), 3.0 + centre_m * math.sin(corner), radius, 0.5)
        scenario = replace(scenario, obstacles=(ob,))
        scene = compile_scene(scenario)
        data = reset_data(scenario, scene)
        pairs = {(data.contact[k].geom1, data.contact[k].geom2) for k in range(data.ncon)}
        obstacle = scene.obstacles[0].geom_id
        touched[heading_deg] = any(obstacle in pair and scene.chassis_geom_id in pair for pair in pairs)
    assert touched == {0.0: True, side_on_deg: False}  # the corner touches it; turned side-on, the box clears it


def test_an_unknown_robot_model_names_the_field():
    with pytest.raises(ConfigError, match="robot.model"):
        parse_scenario(EMPTY.format(model="roomba", heading=0.0))


@pytest.mark.parametrize("model, speed", [("jackal", None), ("turtlebot3_burger", None)])
def test_catalogue_robots_drive_dense_field_30_with_replan(model, speed):
    """At their published top speeds (the Jackal at 2.0 m/s: 12 collisions before the PTP controller's drift and
    corner limits and the effective track)."""
    base = load_scenario("dense-field-30")
    robot = ROBOTS[model]
    scenario = replace(base, robot_model=model, robot_radius_m=robot.planning_radius_m,
                       max_speed_m_s=speed or robot.max_speed_m_s, sensor_range_m=robot.default_range_m)
    result = run_episode(EpisodeSpec(scenario, navigator="replan")).result
    assert result.reached and result.collisions == 0


@pytest.mark.parametrize("model", ["jackal", "turtlebot3_burger"])
def test_the_logged_footprint_of_a_box_robot_is_the_disc_planners_plan_for(model):
    from swarmnav.log.messages import chassis_radius_m
    assert chassis_radius_m(compile_scene(probe(model)).xml) == pytest.approx(ROBOTS[model].planning_radius_m)


@pytest.mark.parametrize("model", ["jackal", "diff_drive"])
def test_scene_draws_a_box_robot_as_its_box_and_the_disc_robot_as_its_disc(tmp_path, model):
    """/scene's footprint in base_link, read back from a real log: the Jackal's published 0.508 x 0.430 m box
    (not the 0.333 m circumscribed disc the planners plan for); the disc robot's 0.1 m disc, as before."""
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory

    from swarmnav.log.writer import McapRecorder
    from swarmnav.sim.episode import EpisodeSpec, run_episode
    out = tmp_path / "run.mcap"
    run_episode(EpisodeSpec(probe(model), navigator="follow"), [McapRecorder(str(out))], time_limit_s=0.2)
    with out.open("rb") as stream:
        scenes = [m for *_, m in make_reader(stream, decoder_factories=[DecoderFactory()])
                  .iter_decoded_messages(topics=["/scene"])]
    footprint = next(e for s in scenes for e in s.entities if e.frame_id == "base_link")
    if model == "jackal":
        assert not footprint.cylinders and len(footprint.cubes) == 1
        size = footprint.cubes[0].size
        x0, y0, x1, y1 = ROBOTS[model].footprint_m
        assert (size.x, size.y) == pytest.approx((x1 - x0, y1 - y0))
    else:
        assert not footprint.cubes and footprint.cylinders[0].size.x == pytest.approx(0.2)


def test_the_jackal_track_multiplier_is_its_effective_track_measured_on_the_spot():
    """The Jackal file's track_multiplier is the calibration of its skid-steer turn: spinning on the spot, the
    geometric track times the multiplier turns the measured wheel speeds into the measured turn rate (within
    12 % at each of three spin speeds; the file's 1.95 is their mean)."""
    model = mujoco.MjModel.from_xml_path(str(ROBOTS["jackal"].scene_xml))
    data = mujoco.MjData(model)
    multiplier = float(model.numeric("track_multiplier").data[0])
    track = float(np.linalg.norm(model.body("left_wheel").pos - model.body("right_wheel").pos))
    radius = float(model.geom("left_wheel_tyre").size[0])
    hinges = [model.joint(n).qposadr[0] for n in ("left_wheel_hinge", "left_rear_wheel_hinge",
                                                   "right_wheel_hinge", "right_rear_wheel_hinge")]
    yaw = lambda q: math.atan2(2 * (q[0] * q[3] + q[1] * q[2]), 1 - 2 * (q[2] ** 2 + q[3] ** 2))  # noqa: E731
    ratios = []
    for speed in (2.0, 5.0, 10.0):
        mujoco.mj_resetData(model, data)
        data.ctrl[:] = (-speed, speed)
        for _ in range(int(1.0 / model.opt.timestep)):
            mujoco.mj_step(model, data)
        q0, turned, last = data.qpos[hinges].copy(), 0.0, yaw(data.qpos[3:7])
        for _ in range(int(2.0 / model.opt.timestep)):
            mujoco.mj_step(model, data)
            now = yaw(data.qpos[3:7])
            turned += (now - last + math.pi) % (2 * math.pi) - math.pi
            last = now
        wheels = (data.qpos[hinges] - q0) / 2.0
        ratios.append(radius * (wheels[2:].mean() - wheels[:2].mean()) / track / (turned / 2.0))
    assert all(abs(r / multiplier - 1.0) < 0.12 for r in ratios)
    assert abs(np.mean(ratios) / multiplier - 1.0) < 0.02
