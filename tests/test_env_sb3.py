"""A real client: a PPO policy trained and saved by ``examples/rl/train_sb3.py`` runs through ``swarmnav run`` as trained.

Needs the ``rl`` extra (Stable-Baselines3, PyTorch's CPU wheel), which ``make install`` installs, so CI runs it;
skipped only where the extra is not installed.  Kept small: 2,048 steps of a network of one hidden layer of 16.
"""

import importlib.util
import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

if importlib.util.find_spec("stable_baselines3") is None:  # not imported here: PyTorch loads only if these run
    pytest.skip("needs the rl extra (pip install -e '.[rl]')", allow_module_level=True)

from swarmnav.controllers.observation_normaliser import ObservationNormaliser  # noqa: E402
from swarmnav.sim.episode import EpisodeSpec, run_episode  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "rl"
KINDS = ["crossing"]
TIME_LIMIT_S = 20.0


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    """The example script run as a user runs it: its saved files and the command it prints."""
    out = tmp_path_factory.mktemp("trained")
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / "train_sb3.py"), "--out", str(out), "--steps", "2048", "--kinds", *KINDS,
         "--time-limit-s", str(TIME_LIMIT_S), "--n-steps", "512", "--epochs", "3", "--net-arch", "16"],
        capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    assert (out / "model.zip").is_file() and (out / "normalise.npz").is_file()
    sys.path.insert(0, str(EXAMPLES))
    import sb3_policy
    import train_sb3
    yield out, done.stdout.strip().splitlines()[-1], train_sb3, sb3_policy
    sys.path.remove(str(EXAMPLES))


def rollout_in_the_environment(env, model, normaliser, seed):
    """The saved policy on the saved normalisation, stepping the environment: (observations it saw, actions)."""
    obs, _ = env.reset(seed=seed)
    seen, actions, done = [], [], False
    while not done:
        seen.append(normaliser(obs))
        action, _ = model.predict(seen[-1], deterministic=True)
        actions.append(action)
        obs, _, terminated, truncated, _ = env.step(action)
        done = terminated or truncated
    return seen, actions


@pytest.fixture(scope="module")
def episode(trained):
    """One generated world driven by the saved policy in the environment and through the policy navigator."""
    import torch
    from stable_baselines3 import PPO
    out, _, train_sb3, sb3_policy = trained
    torch.set_num_threads(1)
    model = PPO.load(out / "model.zip", device="cpu")
    assert model.policy.mlp_extractor.policy_net[0].out_features == 16  # the script's --net-arch was applied
    normaliser = ObservationNormaliser.load(out / "normalise.npz")
    env = train_sb3.make_env(KINDS, TIME_LIMIT_S)  # a generated world, drawn from the reset's seed
    env_obs, env_actions = rollout_in_the_environment(env, model, normaliser, seed=5)
    run_obs, run_actions = [], []

    def recording(obs):
        run_obs.append(obs)
        run_actions.append(sb3_policy.act(obs))
        return run_actions[-1]

    scenario, seeds = env.task.scenario, env.task.seeds
    params = {"policy": "sb3_policy:recording", "flatten": True, "normalise": str(out / "normalise.npz")}
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SWARMNAV_SB3_MODEL", str(out / "model.zip"))
        patch.setattr(sb3_policy, "_model", None)
        patch.setattr(sb3_policy, "recording", recording, raising=False)
        run = run_episode(EpisodeSpec(scenario, navigator="policy", navigator_params=params, seed=seeds.planner,
                                      world_seed=seeds.world), time_limit_s=TIME_LIMIT_S).result
    return env, env_obs, env_actions, run, run_obs, run_actions


def test_the_saved_policy_acts_in_swarmnav_run_as_in_the_environment(episode):
    env, env_obs, env_actions, run, run_obs, run_actions = episode
    # The same observations, entry by entry, and the same actions for them.
    assert len(run_obs) == len(env_obs) == run.steps > 10
    assert all(a.dtype == b.dtype == np.float32 and np.array_equal(a, b) for a, b in zip(run_obs, env_obs))
    assert all(np.array_equal(a, b) for a, b in zip(run_actions, env_actions))
    assert len({tuple(np.round(a, 3)) for a in env_actions}) > 1  # the policy's actions depend on what it sees
    stepper = env.task.stepper
    assert np.array_equal(stepper.wheel_cmd[:stepper.step_index], run.wheel_command_rad_s[:-1])
    assert np.array_equal(stepper.poses[:stepper.step_index + 1], run.poses)


def test_the_command_the_script_prints_runs_the_policy_with_a_video(trained, episode):
    """In a fresh process, as a user would: PyTorch (and its triton, installed by the test extra) loads on the
    policy's first action, after ``--video`` made its GL context (issue 25's segfault, exit -11, when it did)."""
    out, command, _, _ = trained
    env, _, _, run, _, _ = episode
    words = shlex.split(command)
    variables = dict(word.split("=", 1) for word in words[:2])
    assert set(variables) == {"PYTHONPATH", "SWARMNAV_SB3_MODEL"} and words[2:4] == ["swarmnav", "run"]
    scenario, seeds = env.task.scenario, env.task.seeds
    text = re.sub(r"(?m)^time_limit_s = .*$", f"time_limit_s = {TIME_LIMIT_S:g}", scenario.source_text)
    assert f"time_limit_s = {TIME_LIMIT_S:g}" in text
    world = out / "world.toml"
    world.write_text(text)
    args = [str(world), *words[5:], "--world-seed", str(seeds.world), "--seed", str(seeds.planner), "--no-log",
            "--json", "--video", str(out / "run.mp4"), "--width", "160", "--height", "120", "--fps", "10"]
    done = subprocess.run([sys.executable, "-m", "swarmnav.cli", "run", *args], capture_output=True, text=True,
                          timeout=600, cwd=ROOT, env={**os.environ, **variables, "MUJOCO_GL": "egl"})
    assert done.returncode == 0, (done.returncode, done.stderr)
    assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr, done.stderr
    summary = json.loads(done.stdout)
    assert summary["navigator"] == "policy" and summary["outcome"] == run.outcome
    assert summary["sim_time_s"] == pytest.approx(run.sim_time_s)
    assert summary["path_length_m"] == pytest.approx(run.path_length_m, rel=1e-12)
    assert summary["video"] == str(out / "run.mp4")
    import imageio.v2 as imageio
    with imageio.get_reader(out / "run.mp4") as reader:
        frames = [frame for frame in reader]
    assert abs(len(frames) - run.sim_time_s * 10) <= 2  # --fps 10 over the run's simulated time
    assert frames[0].shape == (120, 160, 3) and all(frame.std() > 0 for frame in (frames[0], frames[-1]))
