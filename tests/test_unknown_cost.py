"""knowledge.unknown_cost (planners/unknown_cost.py): with the map unknown, never-seen cells priced for the grid
searches astar and dijkstra; free (the straight route) at 0 or a small cost, avoided when the detour through
space seen free is cheaper."""

import numpy as np
import pytest

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import load_scenario, parse_scenario
from swarmnav.models.world import OccupancyGrid, Pose2D, Rect
from swarmnav.planners.problem import Problem
from swarmnav.planners.registry import make_planner
from swarmnav.sim.episode import EpisodeSpec, run_episode


def corridor_problem(cost: float) -> Problem:
    """A 10 x 4 m empty arena, start (0.5, 2) and goal (9.5, 2); everything unknown but a band seen free at
    y 3.2-3.8 and the strips x < 1 and x > 9 that join it to the endpoints."""
    cell = 0.1
    unknown = np.ones((40, 100), dtype=bool)
    unknown[32:38, :] = False
    unknown[:, :10] = False
    unknown[:, 90:] = False
    return Problem(start=Pose2D(0.5, 2.0, 0.0), goal=Pose2D(9.5, 2.0, 0.0), bounds=Rect(0.0, 0.0, 10.0, 4.0),
                   obstacles=(), robot_radius_m=0.15, cell_m=cell,
                   unknown_cells=OccupancyGrid(unknown, cell, (0.0, 0.0)), unknown_cost=cost)


@pytest.mark.parametrize("planner", ["astar", "dijkstra"])
def test_grid_searches_go_straight_through_cheap_unknown_cells_and_round_costly_ones(planner):
    rng = np.random.default_rng(0)
    free = make_planner(planner).plan(corridor_problem(0.0), rng)
    cheap = make_planner(planner).plan(corridor_problem(0.1), rng)
    costly = make_planner(planner).plan(corridor_problem(5.0), rng)
    assert free.stats.length_m == pytest.approx(9.0) and cheap.stats.length_m == pytest.approx(9.0, abs=0.05)
    assert costly.waypoints[:, 1].max() > 3.1            # through the band seen free
    assert 10.2 < costly.stats.length_m < 13.0           # up, along and down: not a wander
    assert costly.stats.extra["unknown_cost"] == 5.0


def test_planners_that_do_not_price_unknown_cells_ignore_it():
    path = make_planner("theta_star").plan(corridor_problem(5.0), np.random.default_rng(0))
    assert path.stats.length_m == pytest.approx(9.0)


def test_unknown_cost_is_read_from_the_scenario_and_checked():
    text = load_scenario("gwo-scenario-1").source_text.replace(
        "planner = ", 'knowledge = { map = "unknown", unknown_cost = -1.0 }\nplanner = ', 1)
    with pytest.raises(ConfigError, match="knowledge.unknown_cost"):
        parse_scenario(text)


def test_a_run_with_costly_unknown_cells_reaches_the_goal_and_its_planners_see_the_unknown_cells():
    text = load_scenario("gwo-scenario-1").source_text.replace(
        "planner = ", 'knowledge = { map = "unknown", unknown_cost = 2.0 }\nplanner = ', 1)
    scenario = parse_scenario(text)
    episode = run_episode(EpisodeSpec(scenario, navigator="replan"))
    assert episode.result.success and episode.result.replans >= 1
    problem = episode.navigator.setup.plan_problem  # what its last replan planned on
    assert problem.unknown_cost == 2.0 and problem.unknown_cells.occupied.mean() > 0.5
