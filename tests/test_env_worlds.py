"""Randomised worlds: ``scenarios=`` draws a new scenario per episode from the reset's seed (issue 25)."""

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import load_scenario
from swarmnav.env import NavigateEnv

GENERATOR = {"kinds": ["crossing", "crowd"], "obstacles": [2, 5], "speed_ratio": [0.3, 0.8],
             "radius_max_m": [0.3, 0.45], "sensor_model": "detector"}


@pytest.fixture(scope="module")
def generated():
    return NavigateEnv(scenarios=GENERATOR)


def test_the_same_seed_is_the_same_world_and_auto_reset_a_new_one(generated):
    first, _ = generated.reset(seed=7)
    world = generated.task.scenario.source_text
    worlds = set()
    for _ in range(4):  # SB3's auto-reset: no seed, no options
        generated.reset()
        worlds.add(generated.task.scenario.source_text)
    assert len(worlds | {world}) == 5
    again, _ = generated.reset(seed=7)
    assert generated.task.scenario.source_text == world
    assert all(np.array_equal(first[key], again[key]) for key in first)
    generated.reset(seed=8)
    assert generated.task.scenario.source_text != world


def test_spaces_stay_fixed_and_padding_is_zero_rows(generated):
    space = generated.observation_space
    counts = set()
    for seed in range(8):
        obs, _ = generated.reset(seed=seed)
        assert generated.observation_space == space and space.contains(obs)
        moving = sum(ob.moving for ob in generated.task.scenario.obstacles)
        counts.add(moving)
        assert moving <= obs["obstacle_mask"].shape[0] == 5
        for _ in range(20):
            obs, *_ = generated.step(np.array([1.0, 0.0], np.float32))
            assert space.contains(obs)
            assert not obs["obstacles"][obs["obstacle_mask"] == 0].any()
    assert len(counts) > 1  # the draws differ in how many obstacles they have
    assert space["obstacles"].high[0, 4] == pytest.approx(0.45)  # the largest radius a draw can give


def test_a_list_draws_only_its_scenarios_and_all_of_them():
    env = NavigateEnv(scenarios=["gwo-scenario-1", "gwo-scenario-2"])
    names = set()
    for seed in range(12):
        env.reset(seed=seed)
        names.add(env.task.scenario.name)
    assert names == {load_scenario("gwo-scenario-1").name, load_scenario("gwo-scenario-2").name}


def test_gymnasiums_checker_passes_on_drawn_worlds():
    check_env(NavigateEnv(scenarios={"kinds": ["head_on"], "obstacles": [1, 3]}), skip_render_check=True)


def test_a_count_that_fits_some_radii_only_never_fails_a_reset():
    # three head-on discs fit the envelope's radii but not every draw's (the generator refuses seed 4 of
    # `scenarios generate head_on --obstacles 3`): such a draw is redrawn, so no reset fails on it
    env = NavigateEnv(scenarios={"kinds": ["head_on"], "obstacles": [3, 3]})
    counts = []
    for seed in range(40):
        env.reset(seed=seed)
        counts.append(len(env.task.scenario.obstacles))
    assert counts == [3] * 40


@pytest.mark.parametrize("spec, field", [
    ({"kinds": ["crossing"], "obstacle": 3}, "env.scenarios.obstacle"),
    ({"kinds": ["spiral"]}, "env.scenarios.kinds"),
    ({"kinds": ["crossing"], "sensor_count": [8, 16]}, "env.scenarios.sensor_count"),
    ({"kinds": ["crossing"], "speed_ratio": [0.9, 0.2]}, "env.scenarios.speed_ratio"),
    ({"kinds": ["overtake"], "speed_ratio": [0.5, 1.5]}, "--speed-ratio"),
    (42, "env.scenarios"),
    ([], "env.scenarios"),
])
def test_bad_specifications_name_the_option(spec, field):
    with pytest.raises(ConfigError, match=field.replace(".", r"\.")):
        NavigateEnv(scenarios=spec)


def test_one_scenario_name_is_a_list_of_one():
    env = NavigateEnv(scenarios="gwo-scenario-1")
    env.reset(seed=3)
    assert env.task.scenario.name == load_scenario("gwo-scenario-1").name


def test_recordings_of_drawn_worlds_are_numbered_on(tmp_path):
    env = NavigateEnv(scenarios={"kinds": ["head_on"], "obstacles": [1, 2]}, record_to=str(tmp_path / "ep{episode}.mcap"))
    for seed in range(3):
        env.reset(seed=seed)
        env.step(np.zeros(2, np.float32))
    env.close()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ep0.mcap", "ep1.mcap", "ep2.mcap"]
