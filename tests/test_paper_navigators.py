"""The papers' own dynamic strategies: IACO's collision types (Gong et al. (2022) §4) and IMMAS's stepwise walk (Hasan et al. (2023))."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from swarmnav.controllers.controller import Twist
from swarmnav.controllers.goal import GoalChecker
from swarmnav.controllers.kinematics import DriveGeometry
from swarmnav.controllers.navigator import DetectedObstacle, NavigationSetup, Observation
from swarmnav.controllers.navigators import make_navigator
from swarmnav.controllers.navigators.collision_types import (CATCHING_UP, CROSSING, FROM_BEHIND, HEAD_ON,
                                                             NO_CONFLICT, classify, escape_offsets, precondition_x,
                                                             timing)
from swarmnav.controllers.navigators.immas_stepwise import StepwiseWalk, occupied_cells, stepwise_walk
from swarmnav.controllers.navigators.cell_path import static_grid
from swarmnav.controllers.point_to_point import PointToPointController
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import load_scenario
from swarmnav.models.world import Pose2D
from swarmnav.planners.registry import make_planner
from swarmnav.planners.pheromone_propagation import analyse_environment
from swarmnav.planners.problem import map_problem, scenario_problem
from swarmnav.sim.episode import EpisodeSpec, run_episode

CELL = 0.4
V_ROB = 0.2
EAST = (0, 1)  # (dr, dc): the robot moves along +x


def _encounter(gap_cells: float, radius_m: float, speed_m_s: float, heading_x: float, behind: bool = False,
               lateral_m: float = 0.0, conflict: bool = True):
    """A robot at the origin heading +x and an obstacle on (or beside) its line, ``gap_cells`` to its nearest cell."""
    along = (gap_cells * CELL + radius_m) * (-1 if behind else 1)
    return classify(np.zeros(2), EAST, np.array([along, lateral_m]), np.array([heading_x * speed_m_s, 0.0]),
                    radius_m, 0.2, V_ROB, CELL, conflict)


def test_obs1_head_on_odd_size_acts_now_with_two_escape_cells():
    enc = _encounter(5, 0.6, 3 * V_ROB, -1)                # Gong et al. (2022) §5.4 Obs1
    assert (enc.kind, enc.ng, enc.grid_scale) == (HEAD_ON, 5, 3)
    assert enc.step_scale == pytest.approx(3.0)
    diagonal = escape_offsets((-1, 1), enc.grid_scale)     # the figures' heading, rows downwards
    assert sorted(diagonal) == [(-2, -2), (2, 2)]          # Eq. (14)
    x = precondition_x(math.hypot(2, 2), enc.step_scale, enc.grid_scale)
    assert x == pytest.approx(5) and timing(enc.kind, enc.ng, x, enc.step_scale) == ("act", 0)


def test_an_escape_along_an_axis_costs_the_robot_its_moves():
    """Heading along x, Eq. (14)'s cell two rows aside is two straight moves: Obs1's X is the paper's 5."""
    from swarmnav.controllers.navigators.collision_types import escape_moves, precondition_x_of_moves
    enc = _encounter(5, 0.6, 3 * V_ROB, -1)
    (offset, _other) = escape_offsets(EAST, enc.grid_scale)
    assert escape_moves(EAST, offset) == 2 and escape_moves((-1, 1), (2, 2)) == 2 and escape_moves((-1, 1), (1, 2)) == 1
    x = precondition_x_of_moves(escape_moves(EAST, offset), enc.step_scale, enc.grid_scale)
    assert x == pytest.approx(5) and timing(enc.kind, enc.ng, x, enc.step_scale) == ("act", 0)


def test_obs2_head_on_even_size_has_six_escape_cells():
    enc = _encounter(3, 0.4, 2 * V_ROB, -1)                # Gong et al. (2022) §5.4 Obs2
    assert (enc.kind, enc.ng, enc.grid_scale) == (HEAD_ON, 3, 2)
    cells = escape_offsets((-1, 1), enc.grid_scale)        # Eq. (13), as (y, x) of the figures
    assert sorted(cells) == sorted([(-1, -2), (-2, -2), (-2, -1), (1, 2), (2, 2), (2, 1)])
    x = min(precondition_x(math.hypot(*o), enc.step_scale, enc.grid_scale) for o in cells)
    assert x == pytest.approx(2) and timing(enc.kind, enc.ng, x, enc.step_scale) == ("act", 0)
    far = _encounter(9, 0.4, 2 * V_ROB, -1)
    assert timing(far.kind, far.ng, x, far.step_scale) == ("go_on", 2)   # Eq. (17): (9 - 2) // 3


def test_obs3_overtaking_from_behind_goes_on_one_cell_first():
    enc = _encounter(5, 0.4, 3 * V_ROB, +1, behind=True)  # Gong et al. (2022) §5.4 Obs3
    assert (enc.kind, enc.ng) == (FROM_BEHIND, 5)
    x = min(precondition_x(math.hypot(*o), enc.step_scale, enc.grid_scale)
            for o in escape_offsets(EAST, enc.grid_scale))
    assert timing(enc.kind, enc.ng, x, enc.step_scale) == ("go_on", 1)     # Eqs. (19)-(20)


def test_catching_a_slower_obstacle_and_crossing_and_no_conflict():
    assert _encounter(4, 0.4, 0.5 * V_ROB, +1).kind == CATCHING_UP
    assert _encounter(4, 0.4, 2 * V_ROB, +1).kind == NO_CONFLICT          # faster and ahead: moving away
    crossing = classify(np.zeros(2), EAST, np.array([1.2, -1.0]), np.array([0.0, 0.3]), 0.3, 0.2, V_ROB, CELL, True)
    assert crossing.kind == CROSSING
    missed = classify(np.zeros(2), EAST, np.array([1.2, -1.0]), np.array([0.0, 0.3]), 0.3, 0.2, V_ROB, CELL, False)
    assert missed.kind == NO_CONFLICT
    beside = _encounter(3, 0.3, 3 * V_ROB, -1, lateral_m=1.5, conflict=False)
    assert beside.kind == NO_CONFLICT


def _setup(navigator_name, params=None, rows=12, cols=20, start=(5, 2), goal=(5, 18)):
    occ = np.zeros((rows, cols), dtype=bool)
    problem = map_problem(occ, CELL, start, goal, robot_radius_m=0.15, clearance_m=0.05)
    planner = make_planner("iaco", {"ants": 10, "iterations": 10})
    rng = np.random.default_rng(0)
    path = planner.plan(problem, rng)
    geometry = DriveGeometry(wheel_radius_m=0.035, track_m=0.23, max_wheel_speed_rad_s=12.0)
    setup = NavigationSetup(path, problem, planner, rng, PointToPointController(geometry, max_speed_m_s=V_ROB),
                            GoalChecker(problem.goal.x_m, problem.goal.y_m, 0.1), 0.02, V_ROB)
    nav = make_navigator(navigator_name, params)
    nav.reset(setup)
    return nav, problem


def _observe(problem, detections):
    return Observation(0.0, Pose2D(problem.start.x_m, problem.start.y_m, 0.0), Twist(), np.zeros(0), np.zeros(0),
                       0.0, tuple(detections))


@pytest.mark.parametrize("strategy, action", [("paper", "escape"), ("wait_only", "wait")])
def test_head_on_action_paper_escapes_wait_only_waits(strategy, action):
    nav, problem = _setup("iaco_local", {"strategy": strategy})
    x, y = problem.start.x_m, problem.start.y_m
    obs1 = DetectedObstacle(x + 5 * CELL + 0.6, y, 0.6, -3 * V_ROB, 0.0, 7)
    step = nav.step(_observe(problem, [obs1]))
    kinds = [d for k, d in step.events if k == "collision_type"]
    assert kinds and kinds[0]["type"] == HEAD_ON and kinds[0]["action"] == action and kinds[0]["track_id"] == 7
    if action == "escape":
        assert step.new_path is not None
        escape = kinds[0]["escape_cell"]
        assert abs(escape[0] - 5) == 2 and abs(escape[1] - 2) == 0   # Eq. (14) for a heading along x
    else:
        assert any(k == "wait" for k, _ in step.events)
        assert step.command.linear_m_s == 0.0


def test_crossing_obstacle_makes_the_robot_wait_before_the_crossing():
    nav, problem = _setup("iaco_local")
    x, y = problem.start.x_m, problem.start.y_m
    crossing = DetectedObstacle(x + 3 * CELL, y - 1.6, 0.2, 0.0, 0.2, 1)   # reaches the path in ~8 s
    step = nav.step(_observe(problem, [crossing]))
    found = [d for k, d in step.events if k == "collision_type"]
    assert found[0]["type"] == CROSSING and found[0]["action"] in ("wait", "go_to_wait")
    wait_col = found[0]["wait_cell"][1]
    assert 2 <= wait_col < 2 + 3 - 0      # stops before the crossing column, never past it


@pytest.mark.parametrize("name, key, value", [("iaco_local", "strategy", "dance"),
                                              ("iaco_local", "lead_steps", -1),
                                              ("iaco_local", "horizon_cells", 0),
                                              ("immas_stepwise", "reach_m", -0.1),
                                              ("immas_stepwise", "alpha", -1.0)])
def test_bad_parameters_name_the_field(name, key, value):
    with pytest.raises(ConfigError) as err:
        make_navigator(name, {key: value})
    assert err.value.field == f"navigator.params.{key}"


def test_immas_stepwise_never_steps_onto_an_occupied_cell_on_20_world_seeds():
    base = load_scenario("immas-dynamic-10x10")
    problem = scenario_problem(base)
    grid = static_grid(problem)
    start = grid.cell_of(base.start.x_m, base.start.y_m)
    goal = grid.cell_of(base.goal.x_m, base.goal.y_m)
    walk = StepwiseWalk(analyse_environment(grid.occupied, start, goal), goal, 3.0, 1.0)
    step_s = base.obstacles[0].motion.period_s   # Algorithm 3's loop: one obstacle update per robot move
    reached = 0
    for world_seed in range(20):
        scenario = base.with_world_seed(world_seed)
        moving = [ob for ob in scenario.obstacles if ob.moving]
        reach = np.array([ob.radius_m for ob in moving]) + problem.inflation_m
        tracks = np.stack([ob.trajectory().positions_at(np.arange(60) * step_s) for ob in moving], axis=1)
        result = stepwise_walk(walk, start, lambda k: occupied_cells(grid, tracks[k], reach), 50)
        reached += result.reached
        for k, cell in enumerate(result.cells[1:], start=1):
            if cell == result.cells[k - 1]:
                continue  # stayed: no step taken
            centre = grid.centres_m(np.array([cell]))[0]
            gaps = np.linalg.norm(tracks[k] - centre, axis=1) - reach
            assert np.all(gaps >= 0.0), (world_seed, k, cell)
    assert reached >= 18


class _Events:
    def __init__(self):
        self.events = []

    def start(self, context): pass
    def path(self, time_s, waypoints_m): pass
    def step(self, frame): pass
    def finish(self, summary): pass

    def event(self, time_s, kind, details):
        self.events.append((kind, details))


def test_iaco_local_avoids_obs1_to_obs3_where_wait_only_does_not():
    scenario = load_scenario("iaco-dynamic")
    events = _Events()
    paper = run_episode(EpisodeSpec(scenario), [events]).result
    assert paper.reached and paper.collisions == 0
    kinds = [(d["type"], d["grid_scale"] % 2, d["action"]) for k, d in events.events if k == "collision_type"]
    assert (2, 1, "escape") in kinds and (2, 0, "escape") in kinds and (3, 0, "escape") in kinds  # Obs1, 2, 3
    waiting = run_episode(EpisodeSpec(scenario, navigator_params={"strategy": "wait_only"}),
                          stop_on_collision=True).result
    assert waiting.collisions >= 1 or not waiting.reached


def test_immas_stepwise_run_is_deterministic():
    scenario = load_scenario("immas-dynamic-10x10")
    a = run_episode(EpisodeSpec(scenario, world_seed=1)).result
    b = run_episode(EpisodeSpec(scenario, world_seed=1)).result
    assert a.reached and np.array_equal(a.poses, b.poses)


@pytest.mark.parametrize("name", ["iaco_local", "immas_stepwise"])
def test_static_discs_stay_in_the_navigators_map_and_moving_ones_do_not(name):
    """A static disc blocks its cells for the whole run; a moving obstacle's t = 0 disc blocks nothing."""
    from dataclasses import replace
    from swarmnav.models.world import Disc
    nav, problem = _setup(name)
    static = Disc(problem.start.x_m + 6 * CELL, problem.start.y_m + 2 * CELL, 0.3)
    moving = Disc(problem.start.x_m + 10 * CELL, problem.start.y_m, 0.3)
    known = replace(problem, obstacles=(static,))
    frozen = replace(problem, obstacles=(static, moving))
    planner = make_planner("iaco" if name == "iaco_local" else "immas")
    path = make_planner("iaco", {"ants": 5, "iterations": 5}).plan(known, np.random.default_rng(0))
    setup = NavigationSetup(path, frozen, planner, np.random.default_rng(0),
                            PointToPointController(DriveGeometry(0.035, 0.23, 12.0), max_speed_m_s=V_ROB),
                            GoalChecker(problem.goal.x_m, problem.goal.y_m, 0.1), 0.02, V_ROB, known_problem=known)
    nav.reset(setup)
    grid = nav.grid
    assert grid.occupied[grid.cell_of(static.x_m, static.y_m)]
    assert not grid.occupied[grid.cell_of(moving.x_m, moving.y_m)]


def test_turns_are_counted_on_the_driven_path():
    from swarmnav.sim.trajectory_metrics import count_turns
    t = np.linspace(0.0, 1.0, 200)[:, None]
    straight = np.hstack([t * 4.0, 0.0 * t, 0.0 * t])
    corner = np.vstack([straight, np.hstack([4.0 + 0.0 * t, t * 4.0, 0.0 * t])])
    zigzag = np.vstack([corner, np.hstack([4.0 + t * 4.0, 4.0 + 0.0 * t, 0.0 * t])])
    assert [count_turns(p, 0.4) for p in (straight, corner, zigzag)] == [0, 1, 2]


def test_paper_navigation_rows_are_study_rows_with_the_walks_events(tmp_path):
    """bench navigation --suite papers reads its figures from the study rows: IMMAS's moves are the count of
    its move events, and every contender's run is a row of the kept study folder."""
    import pandas as pd

    from swarmnav.benchmarks.paper_navigation import benchmark_paper_navigation

    rows = benchmark_paper_navigation(1, ("immas-dynamic-10x10",), str(tmp_path))
    runs = pd.read_parquet(tmp_path / "runs.parquet")
    assert len(rows) == len(runs) >= 2
    walk = runs[runs.navigator == "immas_stepwise"].iloc[0]
    events = json.loads(walk.run_events)
    paper = next(r for r in rows if r["strategy"] == "paper")
    assert paper["moves"] == events["counts"]["immas_move"] == events["last"]["immas_move"]["moves"] > 0
    assert paper["turns"] == walk.driven_turns and paper["collisions"] == walk.collisions
