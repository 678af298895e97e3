"""A real client: Stable-Baselines3's PPO trained by the example script runs through ``swarmnav run`` as trained.

Skipped without the ``rl`` extra (Stable-Baselines3 and PyTorch, which CI does not install: PyPI's torch is a
multi-GB CUDA build; the README says how to install the CPU wheel).
"""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from swarmnav.controllers.observation_normaliser import ObservationNormaliser  # noqa: E402
from swarmnav.sim.episode import EpisodeSpec, run_episode  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "rl"
TIME_LIMIT_S = 20.0


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    sys.path.insert(0, str(EXAMPLES))
    import train_sb3
    out = tmp_path_factory.mktemp("trained")
    model, venv = train_sb3.train(out, steps=3072, kinds=["crossing"], seed=0, time_limit_s=TIME_LIMIT_S,
                                  n_steps=512)
    yield train_sb3, model, venv, out
    sys.path.remove(str(EXAMPLES))


def test_ppo_trained_by_the_example_drives_swarmnav_run_as_in_the_environment(trained, monkeypatch):
    train_sb3, model, venv, out = trained
    monkeypatch.setenv("SWARMNAV_SB3_MODEL", str(out / "model.zip"))
    normaliser = ObservationNormaliser.load(out / "normalise.npz")
    env = train_sb3.make_env(["crossing"], TIME_LIMIT_S)
    obs, _ = env.reset(seed=5)
    assert np.array_equal(normaliser(obs), venv.normalize_obs(obs))  # the saved file is VecNormalize's transform
    actions, done = [], False
    while not done:
        action, _ = model.predict(venv.normalize_obs(obs), deterministic=True)
        actions.append(action)
        obs, _, terminated, truncated, _ = env.step(action)
        done = terminated or truncated
    scenario, seeds = env.task.scenario, env.task.seeds
    params = {"policy": "sb3_policy:act", "flatten": True, "normalise": str(out / "normalise.npz")}
    run = run_episode(EpisodeSpec(scenario, navigator="policy", navigator_params=params, seed=seeds.planner,
                                  world_seed=seeds.world), time_limit_s=TIME_LIMIT_S).result
    stepper = env.task.stepper
    assert run.steps == stepper.step_index == len(actions) > 10
    assert np.array_equal(stepper.wheel_cmd[:stepper.step_index], run.wheel_command_rad_s[:-1])
    assert np.array_equal(stepper.poses[:stepper.step_index + 1], run.poses)

    # The same through the command line, rendering a video (a fresh process: PyTorch loads before any GL library;
    # issue 25's segfault was EGL loaded at import, then PyTorch's triton).
    text = re.sub(r"(?m)^time_limit_s = .*$", f"time_limit_s = {TIME_LIMIT_S:g}", scenario.source_text)
    (out / "world.toml").write_text(text)
    done = subprocess.run(
        [sys.executable, "-m", "swarmnav.sim.cli", "run", str(out / "world.toml"), "--navigator", "policy",
         "--navigator-set", "policy=sb3_policy:act", "--navigator-set", "flatten=true",
         "--navigator-set", f"normalise={out / 'normalise.npz'}", "--world-seed", str(seeds.world),
         "--seed", str(seeds.planner), "--no-log", "--json",
         "--video", str(out / "run.mp4"), "--width", "160", "--height", "120", "--fps", "10"],
        capture_output=True, text=True, timeout=600,
        env={**os.environ, "PYTHONPATH": str(EXAMPLES), "MUJOCO_GL": "egl"})
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout)
    assert summary["outcome"] == run.outcome and summary["sim_time_s"] == pytest.approx(run.sim_time_s)
    assert summary["path_length_m"] == pytest.approx(run.path_length_m, rel=1e-12)
    assert (out / "run.mp4").stat().st_size > 1000 and "Traceback" not in done.stderr
