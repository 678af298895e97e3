"""``dstar_replan``'s options for CrowdNav's ORCA humans (off by default, docs/navigation.md):
``blocked_horizon_s``, ``corner_merge_m`` (its own) and ``evade_still_m_s``, ``evade_reverse``,
``evade_turn_cost_m_s_rad`` (the safety layer's evasion, offered by ``dstar_replan`` alone).  The MuJoCo runs are CrowdNav validation cases (500-999, where the options were diagnosed;
the test cases 0-499 are never run here)."""

import math

import numpy as np
import pytest

from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.evasion import Evasion
from swarmnav.controllers.kinematics import DriveGeometry, WheelSpeeds
from swarmnav.controllers.navigator import DetectedObstacle
from swarmnav.controllers.navigators import make_driver, navigator_table
from swarmnav.controllers.prediction import LocalObstacles
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.scenario_generator import GeneratorOptions, generate
from swarmnav.models.world import Pose2D
from swarmnav.sim.episode import EpisodeSpec, run_episode

GEOMETRY = DriveGeometry(wheel_radius_m=0.05, track_m=0.3, max_wheel_speed_rad_s=40.0)
NO_MAP = LocalObstacles(np.zeros((0, 2)), np.zeros(0), np.zeros((0, 4)))
FORWARD = ControlCommand(WheelSpeeds(20.0, 20.0), 1.0, 0.0, 1)


def _evasion(**options) -> Evasion:
    return Evasion(GEOMETRY, robot_radius_m=0.3, max_speed_m_s=1.0, local=NO_MAP, trigger_s=2.0, **options)


def _run(case: int, visible: bool = False, stop: bool = False, navigator: str = "dstar_replan", **params):
    scenario = parse_scenario(generate("crowdnav_circle", case, GeneratorOptions(robot_visible=visible)),
                              f"<crowdnav {case}>")
    return run_episode(EpisodeSpec(scenario, navigator=navigator, navigator_params=params),
                       stop_on_collision=stop).result


def test_evade_still_m_s_leaves_a_standing_person_to_the_planner():
    # A person who reached their goal, 0.3 m beyond the robot's grown disc, jittering at 0.01 m/s (RVO2's
    # perturbation): the robot driving at it triggers the evasion unless such a speed counts as standing.
    standing = (DetectedObstacle(1.0, 0.0, 0.3, 0.01, 0.0, 0),)
    pose = Pose2D(0.0, 0.0, 0.0)
    out, started = _evasion().apply(pose, FORWARD, standing)
    assert started and out is not FORWARD
    out, started = _evasion(still_m_s=0.05).apply(pose, FORWARD, standing)
    assert out is FORWARD and not started
    walking = (DetectedObstacle(1.0, 0.0, 0.3, -0.5, 0.0, 0),)  # faster than the threshold: evaded as before
    assert _evasion(still_m_s=0.05).apply(pose, FORWARD, walking)[1]


def test_evade_reverse_backs_toward_an_escape_behind_instead_of_turning_round():
    rng = np.random.default_rng(3)
    backed = ahead = 0
    for _ in range(300):
        person = DetectedObstacle(*rng.uniform(0.8, 1.6, 1), *rng.uniform(-0.6, 0.6, 1), 0.3,
                                  *rng.uniform(-1.2, -0.3, 1), *rng.uniform(-0.3, 0.3, 1), 0)
        plain, reverse = _evasion(), _evasion(reverse=True)
        out, _ = plain.apply(Pose2D(0.0, 0.0, 0.0), FORWARD, (person,))
        back, _ = reverse.apply(Pose2D(0.0, 0.0, 0.0), FORWARD, (person,))
        if out is FORWARD:
            assert back is FORWARD
            continue
        x, y = plain.chosen_m_s
        assert np.array_equal(reverse.chosen_m_s, plain.chosen_m_s)  # the same choice, driven differently
        off_rear = abs(math.atan2(y, -x))
        if x < 0.0 and off_rear < math.radians(60.0):  # behind, within the turn-in-place angle of the rear
            assert out.linear_m_s == 0.0 and back.linear_m_s < 0.0  # turned on the spot vs backed at once
            backed += 1
        elif x > 0.0:
            assert (back.linear_m_s, back.angular_rad_s) == (out.linear_m_s, out.angular_rad_s)
            ahead += 1
    assert backed and ahead


def test_evade_reverse_gets_through_validation_case_563_where_turning_round_is_run_into():
    # Case 563, robot invisible: the evasion's escape lay behind; turning to it on the spot (88 -> -26 deg in
    # 1.7 s) the robot was walked into at 4.9 s.
    assert _run(563, stop=True).collisions >= 1
    result = _run(563, evade_reverse=True)
    assert result.success, result.summary()


CROWD = {"evade_still_m_s": 0.1, "blocked_horizon_s": 1.0, "evade_turn_cost_m_s_rad": 0.3, "corner_merge_m": 0.3,
         "evade_trigger_s": 3.0}  # the arm dstar_replan+crowd (docs/navigation.md)


def test_evade_reverse_backs_out_of_the_centre_where_dstar_replan_crowd_is_pinched_in_case_739():
    # Case 739, robot invisible: at 3.6 s D* Lite's repaired path leads back, away from the humans converging on
    # the centre; with the robot's command a turn on the spot, the evasion (every candidate's cost its distance to
    # a standing robot, the least turn winning the tie) drove on into the centre at 0.24 m/s, where two humans
    # pinched it at 6.8 s.  Backing toward the escape, it leaves the centre and reaches the goal.
    assert _run(739, stop=True, **CROWD).collisions >= 1
    result = _run(739, **CROWD, evade_reverse=True)
    assert result.success, result.summary()


def test_the_evasions_options_get_immas_stepwise_out_of_a_turn_on_the_spot_walked_into_in_case_744():
    # Case 744, robot invisible, immas_stepwise driving through its walk with the evasion (its best configuration
    # on the 50-case sample): from 2.8 s the evasion turned the robot on the spot, at 1.2 rad/s one way then the
    # other, for 2.4 s, until a human walked into it at 5.2 s.  Backing toward an escape behind, the least turn
    # winning a tie and standing humans left to the walk, it reaches the goal.
    drive = {"evade": True, "evade_trigger_s": 4.0, "lookahead_cells": 6, "predict_s": 1.0}
    assert _run(744, stop=True, navigator="immas_stepwise", **drive).collisions >= 1
    result = _run(744, navigator="immas_stepwise", **drive, evade_reverse=True, evade_turn_cost_m_s_rad=0.3,
                  evade_still_m_s=0.1)
    assert result.success, result.summary()


def test_blocked_horizon_s_keeps_the_robot_moving_where_the_sweeps_close_every_way():
    # Case 545, robot invisible (the collision every earlier dstar_replan configuration had): the 3 s sweeps of
    # the humans converging on the centre leave no path, the robot stands there and is pinched at 7.6 s.
    assert _run(545, stop=True).collisions >= 1
    result = _run(545, blocked_horizon_s=1.0)
    assert result.success, result.summary()


def test_evade_still_m_s_ends_the_tug_of_war_beside_a_standing_person_in_validation_case_892():
    # Case 892, robot visible: from 11 s on the robot stood 0.1 m from a person at their goal, the evasion
    # switching on and off with the person's jitter and the controller turning back, until the time limit.
    assert _run(892, visible=True).outcome == "timeout"
    result = _run(892, visible=True, evade_still_m_s=0.1)
    assert result.success, result.summary()


def test_corner_merge_m_turns_a_staircase_of_corners_into_one_turn():
    from swarmnav.controllers.navigators.dstar_replan import _merged
    stairs = np.array([(0.1, 0.0), (0.1, 0.1), (0.2, 0.1), (0.2, 0.2), (1.5, 1.0), (1.6, 1.0), (3.0, 3.0)])
    assert np.array_equal(_merged(stairs, (0.0, 0.0), 0.3), np.array([(1.5, 1.0), (3.0, 3.0)]))  # all < 0.3 m on
    assert np.array_equal(_merged(stairs, (0.0, 0.0), 0.05), stairs)  # every corner farther apart than that


def test_corner_merge_m_gets_through_validation_case_717_where_the_staircase_times_out():
    # Case 717, robot invisible: a path string-pulled round sweeps into corners 0.1 m apart between two people
    # standing at their goals; the robot turned on the spot at each (and the evasion fired at the people's
    # 0.01 m/s jitter) until the time limit.
    assert _run(717).outcome == "timeout"
    result = _run(717, corner_merge_m=0.3)
    assert result.success, result.summary()


def test_evade_turn_cost_m_s_rad_breaks_the_tie_toward_the_candidate_needing_least_turn():
    # The robot waits (a stop), a person comes straight at it: every admissible candidate of the slowest speed costs
    # the same; without the turn cost the first in the robot-frame order (from -180 deg) wins.
    stop = ControlCommand.stop(1)
    person = (DetectedObstacle(1.2, 0.0, 0.3, -1.0, 0.0, 0),)
    plain, turning = _evasion(), _evasion(turn_cost_m_s_rad=0.3)
    plain.apply(Pose2D(0.0, 0.0, 0.0), stop, person)
    turning.apply(Pose2D(0.0, 0.0, 0.0), stop, person)
    angle = lambda v: abs(math.atan2(v[1], v[0]))  # noqa: E731
    assert angle(turning.chosen_m_s) < angle(plain.chosen_m_s)


def test_the_options_are_bounded_and_offered_by_dstar_replan_alone():
    rows = {row["name"]: row for row in navigator_table("dstar_replan")}
    assert rows["blocked_horizon_s"]["default"] == 0.0 and rows["blocked_horizon_s"]["range"] == "[0, 600]"
    assert rows["evade_still_m_s"]["default"] == 0.0 and rows["evade_still_m_s"]["range"] == "[0, 5]"
    assert rows["evade_reverse"]["default"] is False
    assert rows["corner_merge_m"]["default"] == 0.0 and rows["evade_turn_cost_m_s_rad"]["range"] == "[0, 10]"
    with pytest.raises(ConfigError, match=r"navigator\.params\.corner_merge_m: must be in \[0, 100\], got -0.1"):
        make_driver("dstar_replan", {"corner_merge_m": -0.1})
    with pytest.raises(ConfigError, match=r"navigator\.params\.evade_turn_cost_m_s_rad: must be in \[0, 10\]"):
        make_driver("dstar_replan", {"evade_turn_cost_m_s_rad": 11})
    with pytest.raises(ConfigError, match=r"navigator\.params\.blocked_horizon_s: must be in \[0, 600\], got -1"):
        make_driver("dstar_replan", {"blocked_horizon_s": -1})
    with pytest.raises(ConfigError, match=r"navigator\.params\.evade_still_m_s: must be in \[0, 5\], got 6"):
        make_driver("dstar_replan", {"evade_still_m_s": 6})
    for other in ("replan", "velocity_obstacle", "mppi"):
        names = {row["name"] for row in navigator_table(other)}
        assert not names & {"evade_still_m_s", "evade_reverse", "evade_turn_cost_m_s_rad", "blocked_horizon_s",
                            "corner_merge_m"}, other
        with pytest.raises(ConfigError, match=r"evade_reverse: unknown parameter"):
            make_driver(other, {"evade_reverse": True})
    for paper_navigator in ("iaco_local", "immas_stepwise", "dwa"):  # the evasion's options, not dstar_replan's own
        names = {row["name"] for row in navigator_table(paper_navigator)}
        assert {"evade_still_m_s", "evade_reverse", "evade_turn_cost_m_s_rad"} <= names, paper_navigator
        assert not names & {"blocked_horizon_s", "corner_merge_m"}, paper_navigator
        _, layer = make_driver(paper_navigator, {"evade": True, "evade_reverse": True, "evade_still_m_s": 0.1})
        assert (layer.evade, layer.evade_reverse, layer.evade_still_m_s) == (True, True, 0.1)
        with pytest.raises(ConfigError, match=r"navigator\.params\.evade_still_m_s: must be in \[0, 5\], got 6"):
            make_driver(paper_navigator, {"evade_still_m_s": 6})
    _, layer = make_driver("dstar_replan", {"evade_still_m_s": 0.1, "evade_reverse": True})
    assert (layer.evade_still_m_s, layer.evade_reverse) == (0.1, True)
