"""``iaco_local``'s ``arc_cap`` (issue 35, beyond Gong et al. 2022, off by default; docs/navigation.md).
The MuJoCo runs are CrowdNav validation cases from the suite's own scenes (``load_suite("crowdnav", seed_offset=500)``,
where the options were diagnosed; the test cases 0-499 are never used here), robot invisible."""

import math

import pytest

from swarmnav.controllers.kinematics import DriveGeometry
from swarmnav.controllers.navigators import make_driver, navigator_table
from swarmnav.controllers.point_to_point import PointToPointController
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.suites import load_suite
from swarmnav.models.world import Pose2D
from swarmnav.planners.problem import Path
from swarmnav.sim.episode import EpisodeSpec, run_episode

# iaco_local+crowd+reverse (docs/navigation.md), the configuration the option was added to.
CROWD = {"drive": "pulled", "evade": True, "evade_trigger_s": 3, "horizon_cells": 30, "rejoin_m": 1,
         "turn_in_place_deg": 60, "wait_guard": True, "evade_reverse": True, "evade_turn_cost_m_s_rad": 0.3,
         "evade_still_m_s": 0.1}


def _run(case: int, **options):
    scene = next(s for s in load_suite("crowdnav", None, 500).scenes
                 if s.group == "circle-invisible" and s.seed == case)
    scenario = parse_scenario(scene.text(), f"<{scene.name}>")
    return run_episode(EpisodeSpec(scenario, navigator="iaco_local", navigator_params={**CROWD, **options})).result


def test_arc_cap_ends_the_orbit_round_a_waypoint_beside_the_robot():
    # Case 568: a corner of the path lay beside the robot; driving at up to 0.5 m/s (a turn on the spot only above
    # 60 degrees) at 1.2 rad/s it circled it, never within the controller's 0.05 m, until the time limit.
    stuck = _run(568)
    assert stuck.outcome == "timeout" and stuck.collisions == 0
    assert _run(568, arc_cap=True).success


def test_arc_cap_holds_the_speed_to_an_arc_through_the_waypoint():
    geometry = DriveGeometry(wheel_radius_m=0.05, track_m=0.3, max_wheel_speed_rad_s=40.0)
    pose = Pose2D(0.0, 0.0, 0.0)
    waypoint = (0.3 * math.cos(math.radians(45)), 0.3 * math.sin(math.radians(45)))  # 0.3 m away, 45 deg off
    speeds = []
    for cap in (False, True):
        controller = PointToPointController(geometry, max_speed_m_s=1.0, turn_in_place_rad=math.radians(60),
                                            arc_cap=cap)
        controller.reset(Path.from_waypoints([(0.0, 0.0), waypoint, (2.0, 2.0)], 0.0))
        speeds.append(controller.command(pose).linear_m_s)
    assert speeds[0] == pytest.approx(math.cos(math.radians(45)))
    assert speeds[1] == pytest.approx(1.2 * 0.3 / (2 * math.sin(math.radians(45))))  # radius v / 1.2 = 0.212 m
    ahead = PointToPointController(geometry, max_speed_m_s=1.0, arc_cap=True)
    ahead.reset(Path.from_waypoints([(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)], 0.0))
    assert ahead.command(pose).linear_m_s == 1.0  # straight ahead: no cap


def test_arc_cap_is_off_by_default_and_a_boolean():
    rows = {row["name"]: row for row in navigator_table("iaco_local")}
    assert rows["arc_cap"]["default"] is False
    with pytest.raises(ConfigError, match=r"navigator\.params\.arc_cap: expected true or false, got 2"):
        make_driver("iaco_local", {"arc_cap": 2})
    assert PointToPointController(DriveGeometry(0.05, 0.3, 40.0)).arc_cap is False
