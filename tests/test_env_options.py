"""The environment's named reward options, action repeat, terminate-on-collision and bad actions (issue 25)."""

import numpy as np
import pytest

from swarmnav.controllers.policy_interface import ActionError
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import load_scenario
from swarmnav.env import NavigateEnv, RewardWeights, make_environment
from swarmnav.sim.episode import EpisodeSpec, run_episode

ONLY = dict(progress_per_m=0.0, goal_bonus=0.0, time_penalty_per_s=0.0)


@pytest.fixture(scope="module")
def follow_run():
    episode = run_episode(EpisodeSpec(load_scenario("gwo-scenario-2")))
    assert episode.result.collisions > 0
    return episode.result


def replay(env, actions):
    timesteps = [env.reset()]
    for action in actions:
        timesteps.append(env.step(action))
        if timesteps[-1].last():
            break
    return timesteps[1:]


def test_collision_penalty_puts_each_collision_into_the_reward(follow_run):
    env = make_environment("gwo-scenario-2", action="wheels", reward=RewardWeights(**ONLY, collision_penalty=2.5))
    costs, rewards = [], []
    env.reset()
    for command in follow_run.wheel_command_rad_s:
        timestep = env.step(command)
        costs.append(env.task.info()["cost"])
        rewards.append(timestep.reward)
        if timestep.last():
            break
    assert sum(costs) == follow_run.collisions
    assert rewards == [-2.5 * c for c in costs]
    assert min(rewards) < 0


def test_smoothness_charges_changes_of_command_and_effort_its_size():
    smooth = make_environment("gwo-scenario-2", reward=RewardWeights(**ONLY, smoothness=1.0))
    rewards = [t.reward for t in replay(smooth, [np.array([0.5, 0.0], np.float32)] * 5
                                        + [np.array([0.5, -1.0], np.float32)])]
    assert rewards == pytest.approx([-0.25, 0, 0, 0, 0, -1.0])  # starting counts as a change from rest
    effort = make_environment("gwo-scenario-2", reward=RewardWeights(**ONLY, effort_per_s=2.0))
    dt = effort.control_timestep()
    rewards = [t.reward for t in replay(effort, [np.array([0.5, 0.5], np.float32), np.array([3.0, 0.0])])]
    assert rewards == pytest.approx([-2.0 * 0.5 * dt, -2.0 * 1.0 * dt])  # clipped to the action's bounds first


def test_a_penalty_must_not_be_negative():
    with pytest.raises(ConfigError, match="env.reward.smoothness"):
        RewardWeights(smoothness=-1.0)


def test_action_repeat_holds_the_action_for_that_many_control_periods():
    actions = [np.array([0.8, 0.3 * np.sin(i)], np.float32) for i in range(12)]
    once = make_environment("gwo-scenario-2")
    fine = replay(once, [a for a in actions for _ in range(4)])
    held = make_environment("gwo-scenario-2", action_repeat=4)
    coarse = replay(held, actions)
    assert held.control_timestep() == pytest.approx(4 * once.control_timestep())
    assert held.task.stepper.step_index == once.task.stepper.step_index == 48
    assert np.array_equal(held.task.stepper.poses[:49], once.task.stepper.poses[:49])
    summed = [sum(t.reward for t in fine[i:i + 4]) for i in range(0, 48, 4)]
    assert [t.reward for t in coarse] == pytest.approx(summed, rel=1e-9, abs=1e-12)


def test_terminate_on_collision_ends_at_the_runs_first_collision(follow_run):
    env = make_environment("gwo-scenario-2", action="wheels", terminate_on_collision=True)
    last = replay(env, follow_run.wheel_command_rad_s)[-1]
    assert last.last() and last.discount == 0.0 and env.task.info()["outcome"] == "collision"
    assert env.task.stepper.step_index < follow_run.steps
    with pytest.raises(ConfigError, match="env.terminate_on_collision"):
        make_environment("gwo-scenario-2", terminate_on_collision=True, stop_on_collision=False)


@pytest.mark.parametrize("action, problem", [
    (np.array([np.nan, 0.0]), "not finite"), (np.array([0.1, 0.2, 0.3]), "shape"),
    (np.array([True, False]), "dtype"), (np.array(["a", "b"]), "dtype"), ([np.inf, 0.0], "not finite")])
def test_bad_actions_are_a_clear_error_before_any_physics(action, problem):
    env = NavigateEnv("gwo-scenario-2")
    env.reset(seed=0)
    env.step(np.zeros(2, np.float32))
    with pytest.raises(ActionError, match=problem):
        env.step(action)
    assert env.task.stepper.step_index == 1
    env.step(np.zeros(2, np.float32))  # the environment is still usable
    assert env.task.stepper.step_index == 2


def test_a_time_limit_between_control_periods_is_refused_not_cut_short():
    with pytest.raises(ConfigError, match=r"env.time_limit_s.*0.051 s.*after 0.04 s"):
        make_environment("gwo-scenario-2", time_limit_s=0.051)
    env = make_environment("gwo-scenario-2", time_limit_s=0.06)
    steps = replay(env, [np.zeros(2, np.float32)] * 10)
    assert len(steps) == 3 and steps[-1].last() and env.task.info()["time_s"] == pytest.approx(0.06)
