"""``iaco_local``'s options for crowds that do not see the robot (issue 35; beyond Gong et al. 2022, off by
default): ``turn_in_place_deg``, ``wait_guard`` and ``rejoin_m``.  The MuJoCo runs are CrowdNav validation cases
(500-999: the cases the options were diagnosed on; the test cases 0-499 are never used here), robot invisible."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from swarmnav.controllers.navigator import DetectedObstacle
from swarmnav.controllers.navigators.iaco_local import IacoLocalNavigator
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.scenario_generator import GeneratorOptions, generate
from swarmnav.models.world import OccupancyGrid
from swarmnav.sim.episode import EpisodeSpec, run_episode

H30 = {"drive": "pulled", "evade": True, "evade_trigger_s": 3, "horizon_cells": 30}


def _run(case: int, **options):
    scenario = parse_scenario(generate("crowdnav_circle", case, GeneratorOptions()), f"<crowdnav {case}>")
    return run_episode(EpisodeSpec(scenario, navigator="iaco_local", navigator_params={**H30, **options})).result


def test_turn_in_place_deg_lets_the_robot_drive_back_to_its_path_instead_of_standing_in_the_crowd():
    # Case 515: after the evasion the controller stopped to turn back (error >= 25 deg) and a person walked into it.
    assert _run(515).collisions >= 1
    assert _run(515, turn_in_place_deg=60.0).success


def test_rejoin_m_plans_again_round_people_who_stopped_near_the_path():
    # Case 590: the evasion took the robot far off its path; it drove back towards it and stood behind people who
    # had reached their goals there until the time limit.
    options = {"turn_in_place_deg": 60.0, "wait_guard": True}
    stuck = _run(590, **options)
    assert stuck.outcome == "timeout" and not stuck.reached
    assert _run(590, rejoin_m=1.0, **options).success


def _waiting_robot(wait_guard: bool) -> IacoLocalNavigator:
    """A navigator on a straight row of 0.1 m cells along y = 0.05, as after its reset (no MuJoCo)."""
    nav = IacoLocalNavigator(wait_guard=wait_guard, horizon_cells=20)
    nav.grid = OccupancyGrid(np.zeros((1, 40), dtype=bool), 0.1, (0.0, 0.0))
    nav.walker = SimpleNamespace(cells=[(0, c) for c in range(40)])
    nav.step_s, nav.speed_m_s, nav.inflation_m = 0.1, 1.0, 0.3
    return nav


def _person(x_m: float, vx_m_s: float) -> SimpleNamespace:
    return SimpleNamespace(detections=(DetectedObstacle(track_id=1, x_m=x_m, y_m=0.05, vx_m_s=vx_m_s, vy_m_s=0.0,
                                                        radius_m=0.3),))


@pytest.mark.parametrize("x_m, vx_m_s, unsafe", [(3.0, -1.0, True),     # walks at the robot standing on cell 5
                                                 (3.0, 1.0, False),     # walks away
                                                 (10.0, -1.0, False)])  # reaches it after the horizon (2.8 s)
def test_wait_guard_refuses_a_wait_cell_a_sensed_obstacle_will_reach(x_m, vx_m_s, unsafe):
    assert _waiting_robot(True)._wait_unsafe(_person(x_m, vx_m_s), 5) is unsafe
    assert _waiting_robot(False)._wait_unsafe(_person(x_m, vx_m_s), 5) is False  # the paper's wait: no check
    assert math.isclose(_waiting_robot(True)._path_xy(5)[0, 0], 0.55)
