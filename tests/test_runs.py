"""Closed-loop smoke simulations and determinism."""

import numpy as np
import pytest

from swarmnav.models.scenario import load_scenario
from swarmnav.sim.episode import EpisodeSpec, run_episode
from swarmnav.planners.problem import scenario_problem


def simulate(scenario, planner, params, seed, **options):
    return run_episode(EpisodeSpec(scenario, planner, params, seed=seed), **options)


@pytest.mark.parametrize("name", ["gwo-scenario-1", "restaurant-table-2", "restaurant-table-5"])
def test_astar_reaches_the_goal_without_collisions(name):
    scenario = load_scenario(name)
    episode = simulate(scenario, "astar", {}, seed=0)
    r = episode.result
    assert r.reached and r.outcome == "goal_reached", r.summary()
    assert r.collisions == 0 and r.first_collision_s is None
    assert r.sim_time_s < scenario.time_limit_s
    assert r.min_clearance_m > 0.0
    # The driven path is close to the planned one: no wild detours.
    assert r.path_length_m == pytest.approx(episode.path.stats.length_m, rel=0.05)


def test_same_scenario_and_seed_give_an_identical_trajectory():
    scenario = load_scenario("gwo-scenario-3")  # has moving obstacles
    a = simulate(scenario, "astar", {}, seed=3, time_limit_s=20.0)
    b = simulate(scenario, "astar", {}, seed=3, time_limit_s=20.0)
    assert a.path.same_as(b.path)
    assert np.array_equal(a.result.poses, b.result.poses)
    assert np.array_equal(a.result.wheel_command_rad_s, b.result.wheel_command_rad_s)


def test_a_straight_line_through_an_obstacle_collides_in_physics():
    scenario = load_scenario("gwo-scenario-2")  # obstacle 2 moves across the diagonal
    episode = simulate(scenario, "straight", {}, seed=0)
    r = episode.result
    assert r.collisions >= 1
    assert r.first_collision_s is not None and r.first_collision_s > 0
    assert r.min_clearance_m < 0.0
    assert len(r.collision_points_m) == r.collisions


def test_an_empty_arena_reports_no_clearance_rather_than_infinity():
    import json

    from swarmnav.models.scenario import parse_scenario
    scenario = parse_scenario('name = "empty"\narena = { width_m = 3.0, height_m = 3.0 }\n'
                              'start = { x = 1.0, y = 1.0 }\ngoal = { x = 2.0, y = 1.0 }\n')
    result = simulate(scenario, "straight", {}, 0).result
    summary = result.summary()
    assert result.reached and summary["min_clearance_m"] is None
    json.loads(json.dumps(summary, allow_nan=False))


@pytest.mark.parametrize("scenario_name, planner_name, params", [
    # The paper mode with the gwo-vs-abc study's penalty (weight 1 ends inside a disc: NoPathFound).
    ("gwo-scenario-1", "gwo", {"population": 30, "iterations": 60, "penalty_weight": 1000.0, "penalty_margin_m": 0.02,
                               "population_fallback": True}),
    ("gwo-scenario-1", "adl_abc", {"population": 30, "iterations": 60, "penalty_weight": 1000.0,
                                   "penalty_margin_m": 0.02, "population_fallback": True}),
    ("gwo-scenario-1", "optimal", {}),
    ("immas-env1-scattered", "immas", {}),
])
def test_swarm_and_exact_paths_are_driven_without_collisions(scenario_name, planner_name, params):
    scenario = load_scenario(scenario_name)
    episode = simulate(scenario, planner_name, params, seed=0, time_limit_s=scenario.time_limit_s)
    r = episode.result
    assert scenario_problem(scenario).is_collision_free(episode.path.waypoints)
    assert r.reached, r.summary()
    if not any(ob.moving for ob in scenario.obstacles):
        assert r.collisions == 0 and r.min_clearance_m > 0.0, r.summary()


def test_collisions_are_detected_at_the_physics_rate_where_the_bodies_touch():
    scenario = load_scenario("gwo-scenario-1")  # the straight line hits the 0.2 m disc at (1, 1)
    r = simulate(scenario, "straight", {}, seed=0, time_limit_s=10.0).result
    assert r.collisions >= 1
    physics_steps = r.first_collision_s / 0.002
    assert abs(physics_steps - round(physics_steps)) < 1e-6
    # Between two control steps (every 10 physics steps), not on one.
    assert round(physics_steps) % 10 != 0
    # The base is then one robot radius plus the disc radius from the disc centre
    # (the chassis sits 1 cm ahead of the base origin).
    gap = float(np.hypot(*(r.collision_points_m[0] - (1.0, 1.0))))
    assert 0.34 <= gap <= 0.37


def test_stepping_k_physics_steps_at_once_away_from_obstacles_changes_nothing(monkeypatch):
    from swarmnav.sim import stepper

    scenario = load_scenario("gwo-scenario-2")  # the straight line meets a moving obstacle
    fast = simulate(scenario, "straight", {}, 0, time_limit_s=40.0).result
    original = stepper.EpisodeStepper.__init__

    def always_check_every_physics_step(self, *args, **kwargs):
        original(self, *args, **kwargs)
        self.contact_free_gap_m = float("inf")

    monkeypatch.setattr(stepper.EpisodeStepper, "__init__", always_check_every_physics_step)
    slow = simulate(scenario, "straight", {}, 0, time_limit_s=40.0).result
    assert fast.collisions == slow.collisions >= 1
    assert fast.first_collision_s == slow.first_collision_s
    assert np.array_equal(fast.poses, slow.poses)


def test_the_episode_stepper_is_driven_by_anyone_and_refuses_steps_outside_its_episode():
    """A hand-written driver (constant wheels) on the stepper: a reset repeats the episode; a step before
    reset or after the end, and a second reset of a recorded episode, are errors."""
    from swarmnav.controllers.controller import ControlCommand
    from swarmnav.controllers.kinematics import WheelSpeeds
    from swarmnav.sim.recording import RecorderGroup
    from swarmnav.sim.simulation import Simulation

    simulation = Simulation(load_scenario("gwo-scenario-2"))
    stepper = simulation.stepper(time_limit_s=1.0)
    forward = ControlCommand(WheelSpeeds(4.0, 4.2), 0.2, 0.0, 0)
    with pytest.raises(RuntimeError, match="reset"):
        stepper.step(forward)
    runs = []
    for _ in range(2):
        observation = stepper.reset()
        while not stepper.outcome:
            observation = stepper.step(forward)
        runs.append(stepper.result)
    assert runs[0].outcome == "timeout" and runs[0].steps == round(1.0 * simulation.scenario.sim.control_hz)
    assert observation.time_s == runs[0].sim_time_s and np.array_equal(runs[0].poses, runs[1].poses)
    assert runs[0].reference_length_m is not None and runs[0].path_length_m > 0.1
    with pytest.raises(RuntimeError, match="over"):
        stepper.step(forward)
    recorded = simulation.stepper(time_limit_s=1.0, recorder=RecorderGroup([]))
    recorded.reset()
    with pytest.raises(RuntimeError, match="once"):
        recorded.reset()


def test_an_overridden_time_limit_between_control_periods_is_refused_by_the_stepper():
    """The stepper runs whole control periods: a limit that is not one is a ConfigError, never cut short."""
    from swarmnav.models.errors import ConfigError
    from swarmnav.sim.simulation import Simulation

    simulation = Simulation(load_scenario("gwo-scenario-2"))
    with pytest.raises(ConfigError, match=r"0.051 s is not a whole number of control periods.*after 0.04 s"):
        simulation.stepper(time_limit_s=0.051)
    with pytest.raises(ConfigError, match="not a whole number"):
        simulation.stepper(time_limit_s=0.01)  # shorter than one period
    assert simulation.stepper(time_limit_s=0.06).n_max == 3
