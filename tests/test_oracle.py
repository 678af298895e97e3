"""The clairvoyant yardstick: its space-time search (verdicts, T*, clearance of its trajectory) and its drive."""

import math

import numpy as np
import pytest

from swarmnav.controllers.oracle_search import OracleSettings, search
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.scenario_generator import GeneratorOptions, generate
from swarmnav.sim.episode import EpisodeSpec, run_episode

BASE = """
name = "oracle-case"
seed = 0
time_limit_s = {limit}
arena = {{ width_m = 6.0, height_m = 6.0, walls = false }}
robot = {{ radius_m = 0.15, max_speed_m_s = 0.2 }}
start = {{ x = 1.0, y = 3.0, heading_deg = 0.0 }}
goal = {{ x = 5.0, y = 3.0, tolerance_m = 0.1 }}
planner = {{ name = "straight", params = {{}} }}
sim = {{ cell_m = 0.1 }}
"""


def case(obstacles: str = "", limit: float = 60.0):
    return parse_scenario(BASE.format(limit=limit) + obstacles)


def test_an_empty_arena_takes_the_straight_drive_at_the_lattice_speed():
    plan = search(case())
    settings = OracleSettings()
    straight_s = 4.0 / (settings.speed_fraction * 0.2)  # the goal's own cell (within half the tolerance)
    assert plan.solvable and plan.reason == ""
    assert plan.arrival_s == pytest.approx(straight_s, abs=plan.tick_s)
    assert np.allclose(plan.poses[0, :2], (1.0, 3.0)) and math.dist(plan.poses[-1, :2], (5.0, 3.0)) <= 0.05


def test_a_crosser_on_the_line_costs_time_and_the_trajectory_clears_its_true_motion():
    crosser = """
[[obstacles]]
x = 3.0
y = 2.0
radius_m = 0.4
motion = { kind = "linear", speed_m_s = 0.1, heading_deg = 90.0, at_edge = "stop" }
"""
    free, hit = search(case()), search(case(crosser))
    assert hit.solvable and hit.arrival_s > free.arrival_s
    ob = case(crosser).obstacles[0]
    times = np.arange(len(hit.poses)) * hit.tick_s
    centres = ob.trajectory().positions_at(times)
    gap = np.hypot(*(hit.poses[:, :2] - centres).T) - ob.radius_m - 0.15
    assert gap.min() >= OracleSettings().margin_m - 1e-9


def test_a_wall_of_obstacles_driving_at_the_robot_is_unsolvable():
    wall = "".join(f"""
[[obstacles]]
x = {5.9 - 0.0}
y = {y:.2f}
radius_m = 0.3
motion = {{ kind = "linear", speed_m_s = 0.4, heading_deg = 180.0, at_edge = "stop" }}
""" for y in np.arange(0.3, 6.0, 0.5))
    plan = search(case(wall, limit=40.0))
    assert not plan.solvable and plan.reason in ("trapped", "time_limit") and plan.arrival_s is None


def test_a_start_inside_an_obstacle_is_blocked():
    onto = """
[[obstacles]]
x = 1.5
y = 3.0
radius_m = 0.3
motion = { kind = "linear", speed_m_s = 0.3, heading_deg = 180.0, at_edge = "stop" }
"""
    plan = search(case(onto), OracleSettings(margin_m=0.2))
    assert not plan.solvable and plan.reason == "start_blocked"


def test_bad_settings_name_the_field():
    with pytest.raises(ConfigError, match="speed_fraction"):
        search(case(), OracleSettings(speed_fraction=1.5))


def test_the_oracle_drives_its_trajectory_in_physics_and_arrives_at_t_star():
    scenario = parse_scenario(generate("crossing", 3, GeneratorOptions(obstacles=3, arena_m=6.0)))
    plan = search(scenario)
    episode = run_episode(EpisodeSpec(scenario, navigator="oracle"))
    assert plan.solvable
    assert episode.result.success, episode.result.summary()
    assert episode.result.sim_time_s == pytest.approx(plan.arrival_s, abs=1.0)
    again = run_episode(EpisodeSpec(scenario, navigator="oracle")).result
    assert np.array_equal(again.poses, episode.result.poses)
