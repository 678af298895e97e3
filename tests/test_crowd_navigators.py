"""The local navigators at CrowdNav's 1 m/s: dwa's speed lattice fine enough for its window, and mppi's
``reference_speed_m_s`` (its noise and carrot scaled with the top speed)."""

import numpy as np
import pytest

from swarmnav.controllers.goal import GoalChecker
from swarmnav.controllers.kinematics import DriveGeometry
from swarmnav.controllers.navigator import NavigationSetup
from swarmnav.controllers.navigators import make_navigator
from swarmnav.controllers.point_to_point import PointToPointController
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.scenario_generator import GeneratorOptions, generate
from swarmnav.sim.episode import EpisodeSpec, plan_episode, run_episode, static_problem


def _one_human(seconds: float):
    """CrowdNav's circle crossing (1 m/s robot, 8 m from start to goal) with one human, cut to ``seconds``."""
    return parse_scenario(generate("crowdnav_circle", 3, GeneratorOptions(humans=1, time_limit_s=seconds)))


def _speed_m_s(result) -> float:
    driven = np.linalg.norm(np.diff(result.poses[:, :2], axis=0), axis=1).sum()
    return float(driven / result.sim_time_s)


def test_dwa_leaves_standing_at_a_top_speed_of_1_m_s():
    # Before the fix its 7 speeds were 0.167 m/s apart, the +-0.125 m/s window from standing held 0 alone,
    # and the robot never moved.
    result = run_episode(EpisodeSpec(_one_human(6.0), navigator="dwa")).result
    assert _speed_m_s(result) > 0.5, result.summary()


def test_mppi_reference_speed_lets_a_1_m_s_robot_drive_fast_and_changes_nothing_at_that_speed():
    scenario = _one_human(6.0)
    plain = run_episode(EpisodeSpec(scenario, navigator="mppi")).result
    scaled = run_episode(EpisodeSpec(scenario, navigator="mppi", navigator_params={"reference_speed_m_s": 0.2})).result
    assert _speed_m_s(plain) < 0.4 < 0.7 < _speed_m_s(scaled), (_speed_m_s(plain), _speed_m_s(scaled))
    same = run_episode(EpisodeSpec(scenario, navigator="mppi", navigator_params={"reference_speed_m_s": 1.0})).result
    assert np.array_equal(plain.poses, same.poses)


@pytest.mark.parametrize("top_speed_m_s, speeds", [(0.2, 7), (1.0, 17)])
def test_dwa_lattice_is_the_7_speeds_at_dyn300s_speed_and_fine_enough_for_the_window_at_1_m_s(top_speed_m_s, speeds):
    scenario = _one_human(2.0)
    episode = plan_episode(EpisodeSpec(scenario, navigator="dwa"))
    geometry = DriveGeometry(wheel_radius_m=0.05, track_m=0.3, max_wheel_speed_rad_s=40.0)
    setup = NavigationSetup(episode.path, episode.problem, None, np.random.default_rng(0),
                            PointToPointController(geometry, max_speed_m_s=top_speed_m_s),
                            GoalChecker(scenario.goal.x_m, scenario.goal.y_m, 0.3), 0.02, top_speed_m_s,
                            known_problem=static_problem(scenario))
    nav = make_navigator("dwa")
    nav.reset(setup)
    assert np.allclose(nav.speeds, np.linspace(0.0, top_speed_m_s, speeds))
    window = nav.accel_m_s2 * nav.window_s
    assert np.count_nonzero(nav.speeds <= window + 1e-9) >= 2  # from standing, a speed above 0 is reachable
