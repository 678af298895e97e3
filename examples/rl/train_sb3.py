"""Train a PPO policy (Stable-Baselines3) on generated scenarios and save it for ``swarmnav run``.

::

    pip install -e '.[rl]'        # Stable-Baselines3; PyTorch's CPU wheel is enough
    python examples/rl/train_sb3.py --out trained --steps 200000 --kinds crossing overtake --envs 2

writes ``trained/model.zip`` (the PPO policy) and ``trained/normalise.npz`` (its
``VecNormalize`` observation statistics, as data: :mod:`swarmnav.controllers.observation_normaliser`),
then prints the ``swarmnav run`` command that drives a scenario with it through the
``policy`` navigator (``examples/rl/sb3_policy.py``), which gives the policy the same
flat, normalised observation it was trained on.

Each episode is a new world (``scenarios=``, a generator specification with ranges,
drawn from the episode's seed); observations are flat (``flatten=True``: the order the
navigator's ``flatten=true`` uses); the reward adds a collision penalty and a
smoothness term to the default progress / goal / time terms.
"""

from __future__ import annotations

import argparse
import functools
from pathlib import Path

from stable_baselines3 import PPO
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecNormalize

from swarmnav.controllers.observation_normaliser import ObservationNormaliser
from swarmnav.sim.env import NavigateEnv, RewardWeights

REWARD = RewardWeights(collision_penalty=1.0, smoothness=0.05)


def generator(kinds: list[str]) -> dict:
    """Rangefinder worlds (so the observation has no obstacle rows and the navigator's layout is the same)."""
    return {"kinds": kinds, "obstacles": [1, 3], "speed_ratio": [0.3, 0.8], "radius_max_m": [0.3, 0.4]}


def make_env(kinds: list[str], time_limit_s: float | None) -> NavigateEnv:
    return NavigateEnv(scenarios=generator(kinds), flatten=True, reward=REWARD, time_limit_s=time_limit_s)


def save_normalisation(venv: VecNormalize, path: Path) -> None:
    """The statistics VecNormalize applies, as the navigator's ``normalise`` file."""
    ObservationNormaliser({"": venv.obs_rms.mean}, {"": venv.obs_rms.var}, clip=float(venv.clip_obs),
                          epsilon=float(venv.epsilon)).save(path)


def train(out: Path, steps: int, kinds: list[str], envs: int = 1, seed: int = 0, time_limit_s: float | None = None,
          n_steps: int = 1024) -> tuple[PPO, VecNormalize]:
    out.mkdir(parents=True, exist_ok=True)
    venv = make_vec_env(functools.partial(make_env, kinds, time_limit_s), n_envs=envs, seed=seed,
                        vec_env_cls=SubprocVecEnv if envs > 1 else DummyVecEnv)
    venv = VecNormalize(venv, norm_obs=True, norm_reward=True, clip_obs=10.0)
    model = PPO("MlpPolicy", venv, n_steps=n_steps, batch_size=64, seed=seed, device="cpu", verbose=0)
    model.learn(total_timesteps=steps)
    model.save(out / "model.zip")
    save_normalisation(venv, out / "normalise.npz")
    return model, venv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("trained"))
    parser.add_argument("--steps", type=int, default=200_000)
    parser.add_argument("--kinds", nargs="+", default=["crossing"])
    parser.add_argument("--envs", type=int, default=1, help="worker processes (SubprocVecEnv when > 1)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    train(args.out, args.steps, args.kinds, args.envs, args.seed)
    print(f"PYTHONPATH=examples/rl SWARMNAV_SB3_MODEL={args.out / 'model.zip'} swarmnav run dyn-crossing-1 "
          f"--navigator policy --navigator-set policy=sb3_policy:act --navigator-set flatten=true "
          f"--navigator-set normalise={args.out / 'normalise.npz'}")


if __name__ == "__main__":
    main()
