"""The ``policy`` navigator: a Python callable drives ``swarmnav run`` exactly as it drives the environment."""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import load_scenario
from swarmnav.sim.env import make_environment
from swarmnav.sim.episode import EpisodeSpec, run_episode

REACTIVE = textwrap.dedent('''
    """A hand-written reactive policy: head for the goal, veer away from the nearest range hit."""
    import numpy as np


    def act(obs):
        distance_m, bearing_rad = obs["goal"]
        ranges = obs["ranges"]
        angles = 2.0 * np.pi * np.arange(len(ranges)) / len(ranges)
        angles = np.where(angles > np.pi, angles - 2.0 * np.pi, angles)
        nearest = int(np.argmin(ranges))
        turn = 2.0 * bearing_rad
        speed = 1.0 if abs(bearing_rad) < 0.5 else 0.2
        if ranges[nearest] < 1.0 and abs(angles[nearest]) < 1.6:
            turn -= np.sign(angles[nearest] or 1.0) * 3.0 * (1.0 - ranges[nearest])
            speed *= ranges[nearest]
        return np.clip([speed, turn], -1.0, 1.0)
''')


@pytest.fixture
def policy_module(tmp_path, monkeypatch):
    (tmp_path / "reactive_policy.py").write_text(REACTIVE)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", str(tmp_path) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return "reactive_policy:act"


def swarmnav(*args):
    return subprocess.run([sys.executable, "-m", "swarmnav.sim.cli", *args], capture_output=True, text=True,
                          timeout=300)


def test_a_reactive_policy_runs_through_swarmnav_run_among_moving_obstacles(policy_module):
    out = swarmnav("run", "gwo-scenario-2", "--navigator", "policy", "--navigator-set", f"policy={policy_module}",
                   "--no-log", "--json")
    assert out.returncode == 0, out.stderr
    summary = json.loads(out.stdout)
    assert summary["navigator"] == "policy"
    assert summary["reached"] and summary["outcome"] == "goal_reached"
    assert summary["path_length_m"] > 14.0  # at least the straight line from (0, 0) to (10, 10)


def test_the_policy_navigator_and_the_environment_drive_the_same_trajectory(policy_module):
    import reactive_policy
    scenario = load_scenario("gwo-scenario-2")
    run = run_episode(EpisodeSpec(scenario, navigator="policy", navigator_params={"policy": policy_module}),
                      time_limit_s=20.0).result
    env = make_environment(scenario, time_limit_s=20.0)
    timestep = env.reset()
    while not timestep.last():
        timestep = env.step(reactive_policy.act(timestep.observation))
    loop = env.task.loop
    assert loop.step == run.steps
    assert np.array_equal(loop.poses[:loop.step + 1], run.poses)
    assert np.array_equal(loop.wheel_cmd[:loop.step], run.wheel_command_rad_s[:-1])


@pytest.mark.parametrize("value", ["no_such_module_xyz:act", "reactive_policy:no_such_function", "reactive_policy",
                                   "reactive_policy:np"])
def test_a_bad_module_function_is_one_line_and_exit_2(policy_module, value):
    out = swarmnav("run", "gwo-scenario-2", "--navigator", "policy", "--navigator-set", f"policy={value}", "--no-log")
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "navigator.params.policy" in lines[0] and "Traceback" not in out.stderr


def test_a_policy_returning_a_wrong_shape_names_the_field(policy_module, tmp_path):
    (tmp_path / "bad_policy.py").write_text("def act(obs):\n    return [1.0, 0.0, 0.0]\n")
    with pytest.raises(ConfigError, match="navigator.params.policy"):
        run_episode(EpisodeSpec(load_scenario("restaurant-table-5"), navigator="policy",
                                navigator_params={"policy": "bad_policy:act"}), time_limit_s=1.0)
