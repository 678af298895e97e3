"""Inverse kinematics and the PTP controller, on known cases and in physics."""

import math

import numpy as np
import pytest

from swarmnav.controllers.goal import GoalChecker
from swarmnav.controllers.kinematics import DriveGeometry, body_twist, wheel_speeds
from swarmnav.controllers.point_to_point import PointToPointController
from swarmnav.planners.problem import Path
from swarmnav.models.world import Pose2D

GEOMETRY = DriveGeometry(wheel_radius_m=0.04, track_m=0.22, max_wheel_speed_rad_s=10.0)


def test_ik_straight_and_spin_are_exact():
    s = wheel_speeds(0.2, 0.0, GEOMETRY)
    assert (s.left_rad_s, s.right_rad_s) == (5.0, 5.0)
    s = wheel_speeds(0.0, 1.0, GEOMETRY)
    assert s.right_rad_s == pytest.approx(0.11 / 0.04) and s.left_rad_s == pytest.approx(-0.11 / 0.04)


def test_ik_arc_matches_the_formula():
    v, w = 0.15, 0.5
    s = wheel_speeds(v, w, GEOMETRY)
    assert s.right_rad_s == pytest.approx((v + w * 0.11) / 0.04)
    assert s.left_rad_s == pytest.approx((v - w * 0.11) / 0.04)
    assert body_twist(s, GEOMETRY) == pytest.approx((v, w))


def test_saturation_scales_both_wheels_and_keeps_curvature():
    v, w = 0.5, 2.0
    s = wheel_speeds(v, w, GEOMETRY)
    assert max(abs(s.left_rad_s), abs(s.right_rad_s)) == pytest.approx(10.0)
    v2, w2 = body_twist(s, GEOMETRY)
    assert v2 / w2 == pytest.approx(v / w)
    assert v2 < v


def test_controller_turns_in_place_toward_a_waypoint_behind():
    c = PointToPointController(GEOMETRY, max_speed_m_s=0.2)
    c.reset(Path.from_waypoints(np.array([[0.0, 0.0], [-1.0, 0.0]]), 0.0))
    cmd = c.command(Pose2D(0.0, 0.0, 0.0))
    assert cmd.linear_m_s == 0.0 and abs(cmd.angular_rad_s) == pytest.approx(c.max_angular_rad_s)
    assert cmd.wheels.left_rad_s == pytest.approx(-cmd.wheels.right_rad_s)


def test_controller_switches_waypoints_and_slows_down_before_the_last():
    c = PointToPointController(GEOMETRY, max_speed_m_s=0.2)
    c.reset(Path.from_waypoints(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), 0.0))
    assert c.command(Pose2D(0.0, 0.0, 0.0)).waypoint_index == 1
    assert c.command(Pose2D(0.9, 0.0, 0.0)).waypoint_index == 1
    assert c.command(Pose2D(0.97, 0.0, 0.0)).waypoint_index == 2
    far = c.command(Pose2D(1.0, 0.5, math.pi / 2))
    near = c.command(Pose2D(1.0, 0.95, math.pi / 2))
    assert far.linear_m_s == pytest.approx(0.2) and 0.0 < near.linear_m_s < far.linear_m_s


def test_drift_and_corner_limits_slow_a_fast_robot_and_are_off_for_the_papers_controller():
    """controllers/point_to_point.py: at 2 m/s, a 20 degree heading error is driven at the speed whose sideways
    drift stays within max_drift_m, and a right-angle corner 0.5 m ahead is approached at the braking speed; the
    paper's controller (limits off, the disc robot's) drives cos(e) x 2 m/s in both cases."""
    fast = dict(max_speed_m_s=2.0, max_angular_rad_s=4.0)
    limited = PointToPointController(GEOMETRY, max_drift_m=0.05, max_deceleration_m_s2=2.0, **fast)
    paper = PointToPointController(GEOMETRY, **fast)
    e = math.radians(20.0)
    for c in (limited, paper):
        c.reset(Path.from_waypoints(np.array([[0.0, 0.0], [5.0, 0.0]]), 0.0))
    rate = min(limited.heading_gain * e, 4.0)
    assert limited.command(Pose2D(0.0, 0.0, e)).linear_m_s == pytest.approx(0.05 * rate / e ** 2)
    assert paper.command(Pose2D(0.0, 0.0, e)).linear_m_s == pytest.approx(2.0 * math.cos(e))
    for c in (limited, paper):
        c.reset(Path.from_waypoints(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), 0.0))
    assert limited.command(Pose2D(0.5, 0.0, 0.0)).linear_m_s == pytest.approx(math.sqrt(2.0 * 2.0 * 0.5))
    assert paper.command(Pose2D(0.5, 0.0, 0.0)).linear_m_s == pytest.approx(2.0)


def test_the_goal_checker_alone_decides_arrival():
    goal = GoalChecker(1.0, 1.0, 0.1)
    assert goal.reached(Pose2D(1.0, 0.95)) and goal.reached(Pose2D(1.07, 1.07))
    assert not goal.reached(Pose2D(1.0, 0.85)) and not goal.reached(Pose2D(1.08, 1.08))


@pytest.mark.parametrize("target", [(3.0, 1.0), (1.0, 3.0)])
def test_controller_drives_the_robot_in_physics_to_a_waypoint_2_m_away(target):
    from swarmnav.models.scenario import parse_scenario
    from swarmnav.sim.episode import EpisodeSpec, run_episode

    scenario = parse_scenario(f"""
name = "two-metres"
time_limit_s = 30.0
arena = {{ width_m = 4.0, height_m = 4.0 }}
start = {{ x = 1.0, y = 1.0, heading_deg = 0.0 }}
goal = {{ x = {target[0]}, y = {target[1]}, tolerance_m = 0.05 }}
""")
    result = run_episode(EpisodeSpec(scenario, "straight")).result
    assert result.reached, result.summary()
    final = result.poses[-1, :2]
    assert math.dist(final, target) <= 0.05
    # A 2 m drive at 0.2 m/s, plus turning and slowing down at the end.
    assert 10.0 <= result.sim_time_s <= 20.0
    assert result.collisions == 0
