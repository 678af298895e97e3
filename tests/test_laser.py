"""The 2-D laser (sim/runtime/laser.py): a fan of beams from one origin cast with mj_multiRay, its angles as a
LaserScan's, its readings the geometry's, and a replay of its log reading the same scan."""

import math
from dataclasses import replace

import mujoco
import numpy as np
import pytest

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.scenario_obstacles import Obstacle
from swarmnav.sim.episode import EpisodeSpec, run_episode
from swarmnav.sim.laser import LaserCaster
from swarmnav.log.reader import read_log
from swarmnav.log.writer import McapRecorder
from swarmnav.sim.scene import compile_scene
from swarmnav.sim.stepper import reset_data

LASER = """
name = "laser-probe"
time_limit_s = 2.0
arena = {{ width_m = 6.0, height_m = 6.0, walls = true }}
robot = {{ model = "{model}", radius_m = 0.1 }}
start = {{ x = 2.0, y = 3.0, heading_deg = {heading} }}
goal = {{ x = 5.0, y = 5.0 }}
sensors = {{ count = {count}, fov_deg = {fov}, range_m = 10.0 }}
"""


def laser(model="jackal", count=270, fov=270.0, heading=0.0):
    return parse_scenario(LASER.format(model=model, count=count, fov=fov, heading=heading))


def test_a_fan_spans_its_field_of_view_evenly_with_no_rangefinder_sensor():
    scene = compile_scene(laser())
    angles = scene.range_angles_rad
    assert len(angles) == 270 and scene.laser_site_id >= 0
    assert angles[0] == pytest.approx(-math.radians(135)) and angles[-1] == pytest.approx(math.radians(135))
    assert np.allclose(np.diff(angles), angles[1] - angles[0])
    assert len(scene.range_sensor_adr) == 0
    assert not any(scene.model.sensor_type == mujoco.mjtSensor.mjSENS_RANGEFINDER)


@pytest.mark.parametrize("model", ["jackal", "turtlebot3_burger"])
@pytest.mark.parametrize("heading", [0.0, 90.0])
def test_beams_read_the_distance_to_an_obstacle_and_the_walls(model, heading):
    scenario = laser(model, count=360, fov=360.0, heading=heading)
    # A cylinder 1.5 m along the robot's heading, radius 0.2: the beam straight ahead reads 1.3 m.
    h = math.radians(heading)
    ob = Obstacle(2.0 + 1.5 * math.cos(h), 3.0 + 1.5 * math.sin(h), 0.2, 0.5)
    scenario = replace(scenario, obstacles=(ob,))
    scene = compile_scene(scenario)
    data = reset_data(scenario, scene)
    ranges = LaserCaster(scene, data).scan(h)
    assert ranges[0] == pytest.approx(1.3, abs=1e-6)
    # The beam straight behind meets the west wall (x = 0) when heading east, the south wall (y = 0) north.
    assert ranges[180] == pytest.approx(2.0 if heading == 0.0 else 3.0, abs=1e-6)


def test_a_laser_run_logs_a_laserscan_with_the_fans_angles(tmp_path):
    scenario = laser(count=270, fov=270.0)
    out = tmp_path / "laser.mcap"
    episode = run_episode(EpisodeSpec(scenario, navigator="replan"), [McapRecorder(str(out))], time_limit_s=0.4)
    log = read_log(out)
    assert log.range_m.shape[1] == 270
    assert log.scan_angles_rad[0] == pytest.approx(-math.radians(135))
    assert log.scan_angles_rad[-1] == pytest.approx(math.radians(135))
    # The east wall is 4 m ahead: the middle beam reads it.
    assert log.range_m[0, 135] == pytest.approx(4.0, abs=1e-3)
    assert episode.result.steps == 20


@pytest.mark.parametrize("field, value, text", [("fov_deg", 0.0, "sensors.fov_deg"), ("fov_deg", 361.0,
                                                                                       "sensors.fov_deg"),
                                                ("count", 1081, "sensors.count")])
def test_bad_laser_fields_name_the_field(field, value, text):
    kwargs = {"count": 270, "fov": 270.0}
    kwargs["fov" if field == "fov_deg" else "count"] = value
    with pytest.raises(ConfigError, match=text):
        laser(**kwargs)


@pytest.mark.parametrize("text, field", [('robot = { model = "roomba" }', "robot.model"),
                                         ("sensors = { count = 12, fov_deg = 400.0 }", "sensors.fov_deg"),
                                         ("sensors = { count = 5000 }", "sensors.count"),
                                         ('knowledge = { map = "unknown", map_cell_m = 0.0001 }',
                                          "knowledge.map_cell_m")])
def test_bad_robot_laser_and_map_input_is_one_line_naming_the_field_exit_2(tmp_path, capsys, text, field):
    from swarmnav.cli.main import main
    body = LASER.format(model="jackal", count=12, fov=360.0, heading=0.0)
    key = text.split(" = ", 1)[0]
    body = "\n".join(line for line in body.splitlines() if not line.startswith(key + " ")) + "\n" + text + "\n"
    path = tmp_path / "bad.toml"
    path.write_text(body)
    code = main(["run", str(path), "--no-log"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and field in err[0] and "bad.toml" in err[0], err
