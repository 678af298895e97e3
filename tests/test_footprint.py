"""The box chassis on ``dstar_replan``'s grid (issue 34: BARN's Jackal): the footprint's geometry
(:mod:`controllers.footprint`) and a real run through a passage the circumscribed circle cannot pass."""

from types import SimpleNamespace

import numpy as np
import pytest

from swarmnav.controllers.footprint import box_hits, cell_penalty, free_ahead_m, turn_blocked
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.world import Pose2D
from swarmnav.sim.episode import EpisodeSpec, run_episode
from tests.jackal_gap import jackal_gap

JACKAL_BOX = (-0.254, -0.215, 0.254, 0.215)


def discs(*xyr):
    arr = np.array(xyr, dtype=float).reshape(-1, 3)
    return SimpleNamespace(disc_centres_m=arr[:, :2], disc_radii_m=arr[:, 2], box_array_m=np.zeros((0, 4)))


def test_turning_on_the_spot_is_blocked_only_towards_the_obstacle_a_corner_would_sweep():
    # A cylinder beside the front-left corner (55 degrees, 0.39 m out): clear of the box now, inside the
    # corner's 0.333 m circle when the robot turns left, never reached turning right.
    problem = discs((0.39 * np.cos(np.radians(55)), 0.39 * np.sin(np.radians(55)), 0.075))
    pose = Pose2D(0.0, 0.0, 0.0)
    assert not box_hits(problem, pose, np.array([0.0]), JACKAL_BOX)[0]
    assert turn_blocked(problem, pose, +1.0, JACKAL_BOX)
    assert not turn_blocked(problem, pose, -1.0, JACKAL_BOX)


def test_free_distance_ahead_counts_only_what_the_chassis_corridor_meets():
    problem = discs((1.0, 0.1, 0.075), (0.5, 0.4, 0.075))  # the second is beside the corridor (0.215 + 0.075)
    assert free_ahead_m(problem, Pose2D(0.0, 0.0, 0.0), 0.254, 0.215) == pytest.approx(1.0 - 0.075 - 0.254)
    assert free_ahead_m(problem, Pose2D(0.0, 0.0, np.pi), 0.254, 0.215) == np.inf


def test_cell_penalty_is_highest_beside_blocked_cells_and_zero_beyond_its_reach():
    occupied = np.zeros((5, 20), dtype=bool)
    occupied[:, 0] = True
    pen = cell_penalty(occupied, 0.05, 10.0, 0.3)
    assert pen[2, 1] == pytest.approx(10.0 * (1 - 0.05 / 0.3) ** 2, abs=1e-3) and pen[2, 7] == 0.0
    assert np.all(np.diff(pen[2, 1:7]) < 0) and cell_penalty(occupied, 0.05, 0.0, 0.3) is None


GAP = jackal_gap("jackal-gap", 14.0,  # a row of BARN's cylinders with a 0.75 m free passage, x in (2.125, 2.875)
                 [0.55 + 0.15 * k for k in range(11)] + [2.95 + 0.15 * k for k in range(11)])


def test_the_box_footprint_passes_a_barn_passage_the_circumscribed_circle_cannot():
    scenario = parse_scenario(GAP, "<jackal gap>")
    circle = run_episode(EpisodeSpec(scenario, navigator="dstar_replan")).result
    box = run_episode(EpisodeSpec(scenario, navigator="dstar_replan", navigator_params={
        "footprint": "box", "cost_weight": 10.0, "max_decel_m_s2": 2.0})).result
    assert not circle.reached and circle.collisions == 0  # 0.75 m < 2 x 0.333 m (+ the cells): no path
    assert box.reached and box.collisions == 0
