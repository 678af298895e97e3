"""The dm_control task: the same model, the same steps as ``swarmnav run``, dm_env's contract."""

import dataclasses
import math

import numpy as np
import pytest
from absl.testing import absltest
from dm_env import test_utils

from swarmnav.models.scenario import Seeds, load_scenario, parse_scenario
from swarmnav.models.world import Pose2D
from swarmnav.env import RewardWeights, make_environment
from swarmnav.env.task import same_model
from swarmnav.sim.episode import EpisodeSpec, run_episode
from swarmnav.sim.scene import compile_scene


@pytest.fixture(scope="module")
def follow_run():
    """A ``follow`` run on a scenario with moving obstacles, which it bumps into."""
    episode = run_episode(EpisodeSpec(load_scenario("gwo-scenario-2")))
    assert episode.result.collisions > 0 and episode.result.reached
    return episode.result


def replay_commands(env, wheel_commands):
    """Drive the environment with a run's wheel commands until its episode ends."""
    timesteps = [env.reset()]
    for command in wheel_commands:
        timesteps.append(env.step(command))
        if timesteps[-1].last():
            break
    return timesteps


def random_walk_scenario():
    text = load_scenario("gwo-scenario-2").source_text
    text = text.replace('kind = "linear", speed_m_s = 0.05, heading_deg = 150.0, at_edge = "reflect"',
                        'kind = "random_walk", step_m = 0.3, period_s = 1.0')
    assert "random_walk" in text
    return parse_scenario(text, "random-walk.toml")


def test_the_physics_carries_the_model_runs_and_logs_use():
    scenario = load_scenario("gwo-scenario-2")
    env = make_environment(scenario)
    assert same_model(env.physics.model.ptr, compile_scene(scenario).model)
    assert not same_model(env.physics.model.ptr, compile_scene(load_scenario("gwo-scenario-1")).model)
    assert env.control_timestep() == pytest.approx(1.0 / scenario.sim.control_hz)


def test_env_and_run_agree_bit_for_bit_on_the_same_wheel_commands(follow_run):
    env = make_environment("gwo-scenario-2", action="wheels")
    timesteps = replay_commands(env, follow_run.wheel_command_rad_s)
    stepper = env.task.stepper
    assert stepper.step_index == follow_run.steps
    assert np.array_equal(stepper.poses[:stepper.step_index + 1], follow_run.poses)
    assert sum(ts.reward is not None for ts in timesteps) == follow_run.steps
    metrics = env.task.info()["metrics"]
    assert metrics["collisions"] == follow_run.collisions
    assert metrics["min_clearance_m"] == follow_run.min_clearance_m
    assert metrics["path_length_m"] == follow_run.path_length_m


def test_costs_sum_to_the_runs_collisions_and_stay_out_of_the_reward(follow_run):
    weights = RewardWeights(progress_per_m=0.0, goal_bonus=0.0, time_penalty_per_s=0.0)
    env = make_environment("gwo-scenario-2", action="wheels", reward=weights)
    env.reset()
    costs, rewards = [], []
    for command in follow_run.wheel_command_rad_s:
        timestep = env.step(command)
        costs.append(env.task.info()["cost"])
        rewards.append(timestep.reward)
        if timestep.last():
            break
    assert sum(costs) == follow_run.collisions
    assert set(rewards) == {0.0}


def test_goal_is_a_termination_with_discount_zero_and_its_reward_uses_the_goal_reached(follow_run):
    env = make_environment("gwo-scenario-2", action="wheels")
    timesteps = replay_commands(env, follow_run.wheel_command_rad_s)
    last = timesteps[-1]
    assert last.last() and last.discount == 0.0 and env.task.info()["outcome"] == "goal_reached"
    goal = load_scenario("gwo-scenario-2").goal
    before, after = follow_run.poses[-2], follow_run.poses[-1]
    d_before = math.hypot(goal.x_m - before[0], goal.y_m - before[1])
    d_after = math.hypot(goal.x_m - after[0], goal.y_m - after[1])
    weights = RewardWeights()
    expected = weights.progress_per_m * (d_before - d_after) + weights.goal_bonus \
        - weights.time_penalty_per_s * env.control_timestep()
    assert last.reward == pytest.approx(expected, rel=1e-12)
    assert last.reward > weights.goal_bonus / 2  # the bonus is in the final step's reward
    assert last.observation["goal"][0] == pytest.approx(d_after)  # the observation of the goal reached
    assert all(ts.discount == 1.0 for ts in timesteps[1:-1])


def test_time_limit_is_a_truncation_with_discount_one_like_the_runs_timeout():
    scenario = load_scenario("gwo-scenario-2")
    run = run_episode(EpisodeSpec(scenario), time_limit_s=3.0).result
    assert run.outcome == "timeout"
    env = make_environment(scenario, action="wheels", time_limit_s=3.0)
    timesteps = replay_commands(env, run.wheel_command_rad_s)
    assert timesteps[-1].last() and timesteps[-1].discount == 1.0
    assert len(timesteps) - 1 == run.steps
    assert np.array_equal(env.task.stepper.poses[:run.steps + 1], run.poses)


def test_stop_on_collision_is_a_termination_at_the_runs_collision(follow_run):
    scenario = load_scenario("gwo-scenario-2")
    run = run_episode(EpisodeSpec(scenario), stop_on_collision=True).result
    assert run.outcome == "collision" and run.steps < follow_run.steps
    env = make_environment(scenario, action="wheels", stop_on_collision=True)
    timesteps = replay_commands(env, run.wheel_command_rad_s)
    assert len(timesteps) - 1 == run.steps
    assert timesteps[-1].discount == 0.0 and env.task.info()["outcome"] == "collision"
    assert env.task.info()["cost"] == 1.0


def _rollout(env, seed, steps=150):
    rng = np.random.default_rng(seed)
    out = [env.reset()]
    for _ in range(steps):
        out.append(env.step(rng.uniform(-1.0, 1.0, 2)))
    return out, env.task.stepper.poses[:steps + 1].copy()


@pytest.mark.parametrize("detector", [False, True])
def test_same_seeds_and_actions_give_the_same_observations_rewards_and_costs(detector):
    scenario = random_walk_scenario()
    if detector:
        text = scenario.source_text.replace("sensors = { count = 12, range_m = 0.4 }",
                                            'sensors = { model = "detector", count = 12, range_m = 8.0 }')
        scenario = parse_scenario(text, "random-walk-detector.toml")
        assert scenario.sensor_model == "detector"
    a = make_environment(scenario, world_seed=7, path_planner="astar", seed=3)
    b = make_environment(scenario, world_seed=7, path_planner="astar", seed=3)
    (run_a, poses_a), (run_b, poses_b) = _rollout(a, 1), _rollout(b, 1)
    for ta, tb in zip(run_a, run_b):
        assert ta.reward == tb.reward and ta.discount == tb.discount
        for key in ta.observation:
            assert np.array_equal(ta.observation[key], tb.observation[key])
    assert np.array_equal(poses_a, poses_b)
    if detector:
        assert any(t.observation["obstacle_mask"].any() for t in run_a)
    # A second episode of the same environment repeats the first.
    run_again, poses_again = _rollout(a, 1)
    assert np.array_equal(poses_again, poses_a)
    assert [t.reward for t in run_again] == [t.reward for t in run_a]
    # Another world seed moves the random-walk obstacle elsewhere.
    a.task.set_seeds(Seeds(a.task.seeds.planner, 8))
    a.reset()
    moved = a.task.stepper.obstacle_track_m
    b.reset()
    assert not np.array_equal(moved, b.task.stepper.obstacle_track_m)


def test_observations_follow_the_documented_conventions():
    env = make_environment("gwo-scenario-2", path_planner="astar", path_waypoints=3)
    obs = env.reset().observation
    scenario = load_scenario("gwo-scenario-2")
    start, goal = scenario.start, scenario.goal
    assert obs["goal"][0] == pytest.approx(math.hypot(goal.x_m - start.x_m, goal.y_m - start.y_m))
    bearing = math.atan2(goal.y_m - start.y_m, goal.x_m - start.x_m) - start.heading_rad
    assert obs["goal"][1] == pytest.approx(bearing, abs=1e-6)
    assert np.all(obs["ranges"] == 1.0)  # nothing within reach at the start
    waypoints = env.task.planned_path().path.waypoints
    rel = waypoints[1] - (start.x_m, start.y_m)
    c, s = math.cos(start.heading_rad), math.sin(start.heading_rad)
    assert obs["path"].shape == (3, 2)
    assert obs["path"][0] == pytest.approx([c * rel[0] + s * rel[1], -s * rel[0] + c * rel[1]], abs=1e-6)
    spec = env.observation_spec()
    for key, value in obs.items():
        spec[key].validate(value)


class DmEnvContract(test_utils.EnvironmentTestMixin, absltest.TestCase):
    """dm_env's own checks of reset/step/spec conformance."""

    def make_object_under_test(self):
        return make_environment("restaurant-table-5", time_limit_s=0.5)


class DmEnvContractWithPath(test_utils.EnvironmentTestMixin, absltest.TestCase):
    def make_object_under_test(self):
        return make_environment("gwo-scenario-2", time_limit_s=0.5, action="wheels", path_planner="astar")


def test_the_detector_model_observes_the_moving_obstacles_in_the_robot_frame_nearest_first():
    scenario = load_scenario("dyn-crossing-3")
    moving = [ob for ob in scenario.obstacles if ob.moving]
    env = make_environment(scenario, action="wheels", time_limit_s=40.0)
    spec = env.observation_spec()
    assert spec["obstacles"].shape == (len(moving), 5) and spec["obstacle_mask"].shape == (len(moving),)
    timestep, step, seen = env.reset(), 0, 0
    while not timestep.last():
        obs = timestep.observation
        for key, value in obs.items():
            spec[key].validate(value)
        x, y, heading = env.task.stepper.poses[step]
        t = step * env.control_timestep()
        expected = []
        for ob in moving:  # the true state, from the scenario's own motions
            cx, cy = ob.trajectory().positions_at(np.array([t]))[0]
            if math.hypot(cx - x, cy - y) - ob.radius_m - scenario.robot_radius_m <= scenario.sensor_range_m:
                rel = (cx - x, cy - y)
                expected.append((math.hypot(*rel) - ob.radius_m, math.cos(heading) * rel[0] + math.sin(heading) * rel[1],
                                 -math.sin(heading) * rel[0] + math.cos(heading) * rel[1], ob.radius_m))
        expected.sort()
        assert obs["obstacle_mask"].tolist() == [1.0] * len(expected) + [0.0] * (len(moving) - len(expected))
        for row, (_, rx, ry, radius) in zip(obs["obstacles"], expected):
            assert row[[0, 1, 4]] == pytest.approx([rx, ry, radius], abs=1e-5)
        assert not obs["obstacles"][len(expected):].any()
        seen += len(expected)
        timestep = env.step(np.array([8.0, 8.5]))  # a wide left curve through the crossing traffic
        step += 1
    assert seen > 0


def test_the_rangefinder_model_gives_the_trackers_estimates_only_when_asked():
    assert "obstacles" not in make_environment("gwo-scenario-2").observation_spec()
    env = make_environment("gwo-scenario-2", tracked_obstacles=True, obstacle_slots=3, action="wheels")
    spec = env.observation_spec()
    assert spec["obstacles"].shape == (3, 5)
    run = run_episode(EpisodeSpec(load_scenario("gwo-scenario-2"))).result
    timesteps = replay_commands(env, run.wheel_command_rad_s)
    for ts in timesteps:
        for key, value in ts.observation.items():
            spec[key].validate(value)
    assert max(ts.observation["obstacle_mask"].sum() for ts in timesteps) >= 1  # the tracker saw the moving one


class DmEnvContractDetector(test_utils.EnvironmentTestMixin, absltest.TestCase):
    """The same checks with the detector sensing model's obstacle list."""

    def make_object_under_test(self):
        return make_environment("dyn-head-on-3", time_limit_s=0.5, path_planner="astar")


def _over_at_start(scenario, **options):
    """reset and one step of an episode that ends before it starts."""
    env = make_environment(scenario, action="wheels", **options)
    first = env.reset()
    return env, first, env.step(np.array([5.0, 5.0]))


def test_a_start_at_the_goal_ends_on_the_first_step_with_discount_zero_and_no_movement():
    base = load_scenario("restaurant-table-5")
    scenario = dataclasses.replace(base, start=Pose2D(base.goal.x_m + 0.5 * base.goal_tolerance_m, base.goal.y_m, 0.3))
    env, first, last = _over_at_start(scenario)
    run = run_episode(EpisodeSpec(scenario)).result
    assert run.outcome == "goal_reached" and run.steps == 0
    assert first.first() and not first.last()
    assert last.last() and last.discount == 0.0 and last.reward == 0.0
    assert env.task.info()["outcome"] == "goal_reached" and env.task.info()["metrics"]["sim_time_s"] == 0.0
    assert np.array_equal(env.task.stepper.poses[:1], run.poses)  # the action was not applied
    assert env.physics.data.time == 0.0
    assert env.step(np.array([5.0, 5.0])).first()  # dm_env: a step after LAST starts a new episode


def test_a_start_in_contact_ends_at_once_when_stopping_on_collision_and_its_cost_is_counted():
    base = load_scenario("restaurant-table-2")
    table = next(ob for ob in base.obstacles if not ob.moving)
    touching = Pose2D(table.x_m + table.radius_m + 0.5 * base.robot_radius_m, table.y_m, 0.0)
    scenario = dataclasses.replace(base, start=touching)
    env, first, last = _over_at_start(scenario, stop_on_collision=True)  # (no planner would start here)
    info = env.task.info()
    assert info["outcome"] == "collision" and info["metrics"]["sim_time_s"] == 0.0
    assert last.last() and last.discount == 0.0 and last.reward == 0.0
    assert info["cost"] == info["collisions"] == info["metrics"]["collisions"] == 1
    assert env.physics.data.time == 0.0
    # Without stopping on collision the episode goes on, and the contact is still the first step's cost.
    env = make_environment(scenario, action="wheels", stop_on_collision=False)
    env.reset()
    assert env.step(np.array([-5.0, -5.0])).mid() and env.task.info()["cost"] >= 1.0


def test_gymnasium_reset_reports_an_episode_over_at_its_start_and_the_first_step_terminates():
    from swarmnav.env import NavigateEnv
    base = load_scenario("restaurant-table-5")
    env = NavigateEnv(dataclasses.replace(base, start=Pose2D(base.goal.x_m, base.goal.y_m, 0.0)))
    _, info = env.reset(seed=0)
    assert info["outcome"] == "goal_reached" and info["metrics"]["reached"]
    _, reward, terminated, truncated, info = env.step(env.action_space.sample())
    assert terminated and not truncated and reward == 0.0


@pytest.mark.parametrize("name, spl", [("restaurant-table-5", "positive"), ("gwo-scenario-2", "zero"),
                                       ("dyn-crossing-3", "zero")])  # success; collisions (rangefinder, detector)
def test_the_environments_final_metrics_are_run_jsons_for_the_same_wheel_commands(name, spl, capsys):
    """SPL included: the environment's episode is the same stepper's, with the same L*.  (``follow``
    runs: the environment has no navigator to replan or trigger a safety filter.)"""
    import json

    from swarmnav.cli.main import main
    assert main(["run", name, "--navigator", "follow", "--json", "--no-log"]) == 0
    run = json.loads(capsys.readouterr().out)
    commands = run_episode(EpisodeSpec(load_scenario(name), navigator="follow")).result.wheel_command_rad_s
    env = make_environment(name, action="wheels")
    replay_commands(env, commands)
    metrics = env.task.info()["metrics"]
    assert (run["spl"] > 0.0) if spl == "positive" else (run["spl"] == 0.0 and run["collisions"] > 0)
    wall = {"wall_time_s"}
    assert {k: v for k, v in metrics.items() if k not in wall} == \
        {k: run[k] for k in metrics if k not in wall}
