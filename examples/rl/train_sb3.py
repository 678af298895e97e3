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
import shlex
from pathlib import Path

import torch
from stable_baselines3 import PPO
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecNormalize

from swarmnav.controllers.observation_normaliser import ObservationNormaliser
from swarmnav.env import NavigateEnv, RewardWeights

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
          n_steps: int = 1024, n_epochs: int = 10, net_arch: list[int] | None = None) -> tuple[PPO, VecNormalize]:
    """PPO on ``envs`` environments (``n_steps`` each per update, ``n_epochs`` passes over them), hidden layers
    ``net_arch`` (SB3's default, two of 64, when None); saves ``model.zip`` and ``normalise.npz`` in ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    # One PyTorch thread: the network is small, and more threads only contend with the environment's workers
    # (3,072 steps took 98 s of wall time with 2 threads and 12 s with 1 on a loaded 2-core machine).
    torch.set_num_threads(1)
    venv = make_vec_env(functools.partial(make_env, kinds, time_limit_s), n_envs=envs, seed=seed,
                        vec_env_cls=SubprocVecEnv if envs > 1 else DummyVecEnv)
    venv = VecNormalize(venv, norm_obs=True, norm_reward=True, clip_obs=10.0)
    policy_kwargs = {} if net_arch is None else {"net_arch": list(net_arch)}
    model = PPO("MlpPolicy", venv, n_steps=n_steps, batch_size=64, n_epochs=n_epochs, seed=seed, device="cpu",
                verbose=0, policy_kwargs=policy_kwargs)
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
    parser.add_argument("--time-limit-s", type=float, default=None,
                        help="episode length (the scenario's time_limit_s when not given)")
    parser.add_argument("--n-steps", type=int, default=1024, help="steps per environment per PPO update")
    parser.add_argument("--epochs", type=int, default=10, help="PPO's passes over each update's steps")
    parser.add_argument("--net-arch", type=int, nargs="+", default=None,
                        help="hidden layer sizes of the policy and value networks (SB3's default: 64 64)")
    args = parser.parse_args()
    train(args.out, args.steps, args.kinds, args.envs, args.seed, args.time_limit_s, args.n_steps, args.epochs,
          args.net_arch)
    model, normalise = shlex.quote(str(args.out / "model.zip")), shlex.quote(f"normalise={args.out / 'normalise.npz'}")
    print(f"PYTHONPATH=examples/rl SWARMNAV_SB3_MODEL={model} swarmnav run dyn-crossing-1 "
          f"--navigator policy --navigator-set policy=sb3_policy:act --navigator-set flatten=true "
          f"--navigator-set {normalise}")


if __name__ == "__main__":
    main()
