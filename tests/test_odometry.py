"""Pose from odometry (controllers/odometry.py, knowledge.pose = "odometry"): the dead reckoning itself, and a
run whose navigator sees it while the log keeps both poses."""

import math

import numpy as np
import pytest
from mcap.reader import make_reader

from swarmnav.controllers.odometry import WheelOdometry
from swarmnav.models.scenario import load_scenario
from swarmnav.models.world import Pose2D
from swarmnav.sim.episode import EpisodeSpec, run_episode
from swarmnav.log.writer import McapRecorder


def test_equal_wheel_speeds_drive_straight_and_opposite_ones_turn_in_place():
    odo = WheelOdometry(Pose2D(1.0, 2.0, math.pi / 2), wheel_radius_m=0.05, track_m=0.2)
    for _ in range(50):
        odo.update(4.0, 4.0, 0.02)  # 0.2 m/s for 1 s
    assert odo.pose.x_m == pytest.approx(1.0) and odo.pose.y_m == pytest.approx(2.2)
    for _ in range(50):
        odo.update(-2.0, 2.0, 0.02)  # omega = 0.05 * 4 / 0.2 = 1 rad/s for 1 s
    assert odo.pose.heading_rad == pytest.approx(math.pi / 2 + 1.0) and odo.pose.y_m == pytest.approx(2.2)


def test_encoder_noise_is_drawn_from_the_world_seed():
    def drive(seed):
        odo = WheelOdometry(Pose2D(0.0, 0.0), 0.05, 0.2, encoder_noise=0.05, world_seed=seed)
        for _ in range(100):
            odo.update(4.0, 4.0, 0.02)
        return odo.pose
    assert drive(3) == drive(3) and drive(3) != drive(4)


def test_an_odometry_run_logs_odom_beside_the_true_pose_and_reports_its_drift(tmp_path):
    scenario = load_scenario("gwo-scenario-1").with_knowledge(pose_source="odometry")
    out = tmp_path / "odom.mcap"
    result = run_episode(EpisodeSpec(scenario, navigator="replan"), [McapRecorder(str(out))],
                         time_limit_s=10.0).result
    error = result.summary()
    assert 0.0 < error["pose_error_m"] <= error["max_pose_error_m"]
    with out.open("rb") as stream:
        counts = {}
        for _, channel, _ in make_reader(stream).iter_messages(topics=["/odom", "/robot/pose"]):
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
    assert counts["/odom"] == counts["/robot/pose"] == result.steps + 1


def test_the_default_run_reports_no_pose_error():
    result = run_episode(EpisodeSpec(load_scenario("gwo-scenario-1")), time_limit_s=1.0).result
    assert "pose_error_m" not in result.summary()


def test_a_burger_with_a_270_ray_laser_no_map_and_odometry_reaches_dense_field_30(tmp_path):
    """The issue's run: laser, map unknown, odometry pose; /map and /odom logged, a small non-zero drift."""
    from dataclasses import replace
    from swarmnav.models.robots import ROBOTS
    burger = ROBOTS["turtlebot3_burger"]
    base = load_scenario("dense-field-30")
    scenario = replace(base, robot_model=burger.name, robot_radius_m=burger.planning_radius_m,
                       max_speed_m_s=burger.max_speed_m_s, sensor_count=270, sensor_fov_deg=270.0,
                       sensor_range_m=10.0, goal_tolerance_m=0.3).with_knowledge("unknown", "odometry")
    out = tmp_path / "burger.mcap"
    episode = run_episode(EpisodeSpec(scenario, navigator="replan"), [McapRecorder(str(out))])
    summary = episode.result.summary()
    assert episode.result.success
    assert 0.0 < summary["pose_error_m"] < 0.03 * episode.result.path_length_m
    with out.open("rb") as stream:
        topics = {channel.topic for _, channel, _ in make_reader(stream).iter_messages(topics=["/map", "/odom"])}
    assert topics == {"/map", "/odom"}
