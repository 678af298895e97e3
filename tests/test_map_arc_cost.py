"""The total arc cost priced on the map as given (planners/map_arc_cost.py): one field for IMMAS and MMAS, so
Hasan et al. (2023)'s cost claims compare two tours by the same measure (issue 31)."""

from __future__ import annotations

import numpy as np
import pytest

from swarmnav.models.scenario import load_scenario
from swarmnav.planners.map_arc_cost import cost_to_goal, map_arc_cost
from swarmnav.planners.problem import scenario_problem
from swarmnav.planners.registry import make_planner


def test_cost_to_goal_is_the_octile_route_with_diagonals_of_1_4_and_no_corner_cutting():
    free = np.zeros((3, 3), dtype=bool)
    k = cost_to_goal(free, (0, 0))
    assert k[2, 2] == pytest.approx(2.8) and k[0, 2] == pytest.approx(2.0) and k[2, 1] == pytest.approx(2.4)
    wall = free.copy()
    wall[1, 1] = True                      # the diagonals through the centre are cut corners now
    k = cost_to_goal(wall, (0, 0))
    assert np.isinf(k[1, 1]) and k[2, 2] == pytest.approx(4.0) and k[1, 2] == pytest.approx(3.0)
    closed = np.zeros((3, 3), dtype=bool)
    closed[:, 1] = True                    # the right column is cut off from the goal
    assert np.isinf(cost_to_goal(closed, (0, 0))[:, 2]).all()
    assert map_arc_cost(wall, (0, 0), [(2, 2), (2, 1), (2, 0), (1, 0), (0, 0)]) == pytest.approx(3 + 2 + 1 + 0)


@pytest.mark.parametrize("planner", ["immas", "mmas"])
def test_both_planners_price_their_tour_on_the_same_field(planner):
    scenario = load_scenario("immas-env1-scattered")
    problem = scenario_problem(scenario)
    params = dict(scenario.planner_params) if planner == "immas" else {"iterations": 5, "ants": 10}
    extra = make_planner(planner, params).plan(problem, np.random.default_rng(3)).stats.extra
    grid = problem.grid
    goal = grid.cell_of(problem.goal.x_m, problem.goal.y_m)
    k = cost_to_goal(grid.occupied, goal)
    cells = [tuple(c) for c in extra["raw_cells"]]
    assert extra["map_arc_cost"] == pytest.approx(sum(k[c] for c in cells[1:]))
    if planner == "immas":
        # IMMAS's own sum prices by its field after closing cells (never cheaper) and counts the cut loops
        assert extra["total_arc_cost"] >= extra["map_arc_cost"]
