"""The mppi navigator: its unicycle rollouts, its choice among predicted obstacles, and a run in physics."""

import math

import numpy as np
import pytest

from swarmnav.controllers.navigators import make_navigator
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.scenario_generator import GeneratorOptions, generate
from swarmnav.sim.episode import EpisodeSpec, run_episode


def test_rollouts_integrate_the_unicycle():
    nav = make_navigator("mppi", {"samples": 2, "horizon_steps": 10})
    controls = np.zeros((2, 10, 2), dtype=np.float32)
    controls[0, :, 0] = 0.2                                   # straight at 0.2 m/s
    controls[1, :, 0] = 0.2
    controls[1, :, 1] = (math.pi / 2) / 1.0                   # a quarter turn over the 1 s horizon
    px, py = nav.rollouts(1.0, 2.0, 0.0, controls)
    assert px[0, -1] == pytest.approx(1.0 + 0.2 * 1.0, abs=1e-5) and py[0, -1] == pytest.approx(2.0, abs=1e-6)
    # A quarter circle of radius v / omega: ends near (x + r, y + r) (explicit Euler, 10 steps).
    r = 0.2 / (math.pi / 2)
    assert px[1, -1] == pytest.approx(1.0 + r, abs=0.02) and py[1, -1] == pytest.approx(2.0 + r, abs=0.03)


def test_bad_parameters_name_the_field():
    with pytest.raises(ConfigError, match="navigator.params.samples"):
        make_navigator("mppi", {"samples": 0})
    with pytest.raises(ConfigError, match="samples"):
        make_navigator("mppi", {"samples": 100_000, "horizon_steps": 100})


@pytest.mark.parametrize("kind", ["head_on", "crossing"])
def test_mppi_reaches_the_goal_without_collision_and_repeats_itself(kind):
    scenario = parse_scenario(generate(kind, 7, GeneratorOptions(obstacles=1, arena_m=5.0, speed_ratio=0.5,
                                                                 sensor_model="detector", range_m=1.0)))
    first = run_episode(EpisodeSpec(scenario, navigator="mppi")).result
    assert first.success, first.summary()
    again = run_episode(EpisodeSpec(scenario, navigator="mppi")).result
    assert np.array_equal(first.poses, again.poses)
