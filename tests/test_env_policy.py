"""The ``policy`` navigator: a Python callable drives ``swarmnav run`` exactly as it drives the environment."""

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import load_scenario
from swarmnav.env import make_environment
from swarmnav.sim.episode import EpisodeSpec, run_episode

TESTS_DIR = str(Path(__file__).resolve().parent)  # holds reactive_policy.py, the bundled example policy


@pytest.fixture
def policy_module(tmp_path, monkeypatch):
    """``reactive_policy:act`` importable here and in subprocesses; ``tmp_path`` too, for bad policies."""
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([TESTS_DIR, str(tmp_path), os.environ.get("PYTHONPATH", "")]))
    return "reactive_policy:act"


def swarmnav(*args):
    return subprocess.run([sys.executable, "-m", "swarmnav.cli", *args], capture_output=True, text=True,
                          timeout=300)


def test_a_reactive_policy_runs_through_swarmnav_run_among_moving_obstacles(policy_module):
    out = swarmnav("run", "gwo-scenario-2", "--navigator", "policy", "--navigator-set", f"policy={policy_module}",
                   "--no-log", "--json")
    assert out.returncode == 0, out.stderr
    summary = json.loads(out.stdout)
    assert summary["navigator"] == "policy"
    assert summary["reached"] and summary["outcome"] == "goal_reached"
    assert summary["path_length_m"] > 14.0  # at least the straight line from (0, 0) to (10, 10)


@pytest.mark.parametrize("name", ["gwo-scenario-2", "dyn-crossing-3"])  # rangefinder, detector
def test_the_policy_navigator_and_the_environment_drive_the_same_trajectory(policy_module, name):
    import reactive_policy
    scenario = load_scenario(name)
    seen = []

    def recording_policy(obs):
        seen.append(obs)
        return reactive_policy.act(obs)

    reactive_policy.recording = recording_policy
    run = run_episode(EpisodeSpec(scenario, navigator="policy", navigator_params={"policy": "reactive_policy:recording"}),
                      time_limit_s=20.0).result
    env = make_environment(scenario, time_limit_s=20.0)
    timestep = env.reset()
    observations = []
    while not timestep.last():
        observations.append(timestep.observation)
        timestep = env.step(reactive_policy.act(timestep.observation))
    stepper = env.task.stepper
    assert stepper.step_index == run.steps
    assert np.array_equal(stepper.poses[:stepper.step_index + 1], run.poses)
    assert np.array_equal(stepper.wheel_cmd[:stepper.step_index], run.wheel_command_rad_s[:-1])
    # The navigator's policy saw exactly the environment's observations, entry by entry.
    assert len(seen) == len(observations)
    for a, b in zip(seen, observations):
        assert sorted(a) == sorted(b) and all(np.array_equal(a[k], b[k]) and a[k].dtype == b[k].dtype for k in a)
    if scenario.sensor_model == "detector":
        assert "obstacles" in observations[0] and max(o["obstacle_mask"].sum() for o in observations) >= 1


@pytest.mark.parametrize("value", ["no_such_module_xyz:act", "reactive_policy:no_such_function", "reactive_policy",
                                   "reactive_policy:np"])
def test_a_bad_module_function_is_one_line_and_exit_2(policy_module, value):
    out = swarmnav("run", "gwo-scenario-2", "--navigator", "policy", "--navigator-set", f"policy={value}", "--no-log")
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "navigator.params.policy" in lines[0] and "Traceback" not in out.stderr


BAD_ACTIONS = [("[1.0, 0.0, 0.0]", "shape"), ("[float('nan'), 0.0]", "not finite"), ("[True, False]", "dtype"),
               ("['a', 'b']", "dtype")]


@pytest.mark.parametrize("action, problem", BAD_ACTIONS)  # as the environment's ActionError (test_env_options)
def test_a_policy_returning_a_bad_action_names_the_field(policy_module, tmp_path, action, problem):
    module = f"bad_policy_{BAD_ACTIONS.index((action, problem))}"  # one module per case: imports are cached
    (tmp_path / f"{module}.py").write_text(f"def act(obs):\n    return {action}\n")
    with pytest.raises(ConfigError, match=f"navigator.params.policy.*bad action.*{problem}"):
        run_episode(EpisodeSpec(load_scenario("restaurant-table-5"), navigator="policy",
                                navigator_params={"policy": f"{module}:act"}), time_limit_s=1.0)


def test_a_nan_action_through_swarmnav_run_is_one_line_and_exit_2(policy_module, tmp_path):
    (tmp_path / "nan_policy.py").write_text("def act(obs):\n    return [float('nan'), 0.0]\n")
    out = swarmnav("run", "restaurant-table-5", "--navigator", "policy", "--navigator-set", "policy=nan_policy:act",
                   "--no-log")
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "navigator.params.policy" in lines[0] and "not finite" in lines[0], out.stderr


def test_a_policy_that_raises_is_reported_against_the_parameter(tmp_path, monkeypatch):
    (tmp_path / "raising_policy.py").write_text("def act(obs):\n    return {}['missing']\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(ConfigError, match="navigator.params.policy.*raised KeyError"):
        run_episode(EpisodeSpec(load_scenario("restaurant-table-5"), navigator="policy",
                                navigator_params={"policy": "raising_policy:act"}), time_limit_s=1.0)


def test_bench_navigation_runs_the_policy_named_by_navigator_set(policy_module):
    out = swarmnav("bench", "navigation", "--seeds", "1", "--scenario", "dyn-crossing-3", "--navigator", "policy",
                   "--navigator", "follow", "--navigator-set", f"policy={policy_module}", "--json")
    assert out.returncode == 0, out.stderr
    rows = {row["navigator"]: row for row in json.loads(out.stdout)}
    assert sorted(rows) == ["follow", "oracle", "policy"] and rows["policy"]["runs"] == 1  # the oracle: the yardstick
    direct = run_episode(EpisodeSpec(load_scenario("dyn-crossing-3").with_world_seed(0), navigator="policy",
                                     navigator_params={"policy": policy_module}, seed=0, world_seed=0)).result
    assert rows["policy"]["success_rate"] == float(direct.success)
    # Without --navigator the policy joins the default set once it has its callable; a bad one is exit 2.
    bad = swarmnav("bench", "navigation", "--seeds", "1", "--scenario", "dyn-crossing-3",
                   "--navigator-set", "policy=no_such_module_xyz:act", "--json")
    assert bad.returncode == 2 and "navigator.params.policy" in bad.stderr and len(bad.stderr.strip().splitlines()) == 1


def test_a_tiny_study_runs_the_policy_navigator_beside_replan(policy_module, tmp_path):
    import pyarrow.parquet as pq
    study = tmp_path / "tiny-policy.toml"
    study.write_text(textwrap.dedent(f'''
        scenarios = ["dyn-crossing-3"]
        mode = "physics"
        seeds = 1
        world_seeds = [0]

        [[planners]]
        name = "astar"

        [[navigators]]
        name = "policy"
        params = {{ policy = "{policy_module}" }}

        [[navigators]]
        name = "replan"
    '''))
    out = swarmnav("study", str(study), "--out", str(tmp_path / "out"), "--workers", "1", "--json", "--trust-code")
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout)["failed"] == 0
    rows = pq.read_table(tmp_path / "out" / "runs.parquet").to_pylist()
    policy = [r for r in rows if r["navigator"] == "policy"]
    assert len(rows) == 2 and len(policy) == 1 and json.loads(policy[0]["navigator_params"]) == {"policy": policy_module}
    direct = run_episode(EpisodeSpec(load_scenario("dyn-crossing-3").with_world_seed(0), planner="astar",
                                     navigator="policy", navigator_params={"policy": policy_module},
                                     seed=0, world_seed=0)).result
    assert policy[0]["reached"] == direct.reached and policy[0]["path_length_m"] == direct.path_length_m
