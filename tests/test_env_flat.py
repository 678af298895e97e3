"""One flat observation order and a saved normalisation shared by the environment and the ``policy`` navigator."""

import numpy as np
import pytest

from swarmnav.controllers.observation_normaliser import ObservationNormaliser
from swarmnav.controllers.policy_interface import FLAT_ORDER, flatten_observation
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import load_scenario
from swarmnav.env import NavigateEnv
from swarmnav.sim.episode import EpisodeSpec, run_episode
from swarmnav.sim.scene import compile_scene, index_scene

from test_env_policy import policy_module  # noqa: F401  (the fixture: tests/ on the path)


def test_flatten_is_the_documented_order_not_alphabetical():
    flat, nested = NavigateEnv("dyn-crossing-3", flatten=True), NavigateEnv("dyn-crossing-3")
    f, _ = flat.reset(seed=3)
    d, _ = nested.reset(seed=3)
    assert flat.observation_space.contains(f) and f.dtype == np.float32
    assert np.array_equal(f, np.concatenate([d[key].ravel() for key in FLAT_ORDER if key in d]))
    k = len(d["ranges"])
    assert np.array_equal(f[:k], d["ranges"]) and np.array_equal(f[k:k + 2], d["goal"])
    assert flat.metadata["flat_order"] == ["ranges", "goal", "velocity", "obstacles", "obstacle_mask"]
    low, high = flat.observation_space.low, flat.observation_space.high
    assert np.array_equal(low, flatten_observation({key: np.broadcast_to(space.low, space.shape)
                                                    for key, space in nested.observation_space.items()}))
    assert np.array_equal(high[k:k + 2], nested.observation_space["goal"].high)


def test_the_beam_angles_in_the_metadata_are_the_scenes():
    scenario = load_scenario("gwo-scenario-2")
    scene = compile_scene(scenario)
    angles = index_scene(scene.model, scene.xml).range_angles_rad
    env = NavigateEnv(scenario)
    assert env.metadata["range_angles_rad"] == angles.tolist()  # the compiled sites' directions
    assert np.allclose(env.task.layout.range_angles_rad(), angles, rtol=0, atol=1e-6)  # the documented 2 pi k / K


def test_a_flat_normalised_policy_runs_through_swarmnav_run_as_in_the_environment(policy_module, tmp_path):
    import linear_policy
    scenario = load_scenario("dyn-crossing-3")
    env = NavigateEnv(scenario, flatten=True, time_limit_s=15.0)
    obs, _ = env.reset()
    size = obs.shape
    normaliser = ObservationNormaliser({"": np.linspace(0.0, 1.0, size[0])}, {"": np.linspace(0.5, 2.0, size[0])},
                                       clip=3.0)
    normaliser.save(tmp_path / "norm.npz")
    done, actions = False, []
    while not done:
        action = linear_policy.act(normaliser(obs))
        actions.append(action)
        obs, _, terminated, truncated, _ = env.step(action)
        done = terminated or truncated
    run = run_episode(EpisodeSpec(scenario, navigator="policy", navigator_params={
        "policy": "linear_policy:act", "flatten": True, "normalise": str(tmp_path / "norm.npz")}),
        time_limit_s=15.0).result
    stepper = env.task.stepper
    assert run.steps == stepper.step_index == len(actions) > 10
    assert np.array_equal(stepper.poses[:stepper.step_index + 1], run.poses)
    assert np.array_equal(stepper.wheel_cmd[:stepper.step_index], run.wheel_command_rad_s[:-1])
    # Without the normalisation the same policy drives elsewhere: the transform is applied, not ignored.
    plain = run_episode(EpisodeSpec(scenario, navigator="policy", navigator_params={
        "policy": "linear_policy:act", "flatten": True}), time_limit_s=15.0).result
    assert not np.array_equal(plain.poses[:20], run.poses[:20])


def test_a_bad_normalisation_file_names_the_parameter(policy_module, tmp_path):
    np.savez(tmp_path / "bad.npz", mean=np.zeros(3))
    for path in (tmp_path / "missing.npz", tmp_path / "bad.npz"):
        with pytest.raises(ConfigError, match="navigator.params.normalise"):
            run_episode(EpisodeSpec(load_scenario("dyn-crossing-3"), navigator="policy", navigator_params={
                "policy": "linear_policy:act", "flatten": True, "normalise": str(path)}), time_limit_s=1.0)
    np.savez(tmp_path / "short.npz", mean=np.zeros(3), var=np.ones(3))
    with pytest.raises(ConfigError, match="navigator.params.normalise.*shape"):
        run_episode(EpisodeSpec(load_scenario("dyn-crossing-3"), navigator="policy", navigator_params={
            "policy": "linear_policy:act", "flatten": True, "normalise": str(tmp_path / "short.npz")}),
            time_limit_s=1.0)
