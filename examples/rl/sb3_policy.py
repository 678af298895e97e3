"""A saved Stable-Baselines3 policy as the ``policy`` navigator's callable: ``sb3_policy:act``.

The model file is ``$SWARMNAV_SB3_MODEL`` (``model.zip`` of ``train_sb3.py``), loaded on
the first call on the CPU.  The navigator flattens and normalises the observation
first (``flatten=true``, ``normalise=normalise.npz``), so ``act`` sees what the policy
saw in training; it answers the deterministic action (the distribution's mean).
"""

from __future__ import annotations

import os

import numpy as np

_model = None


def act(obs: np.ndarray) -> np.ndarray:
    global _model
    if _model is None:
        from stable_baselines3 import PPO
        _model = PPO.load(os.environ["SWARMNAV_SB3_MODEL"], device="cpu")
    action, _ = _model.predict(obs, deterministic=True)
    return action
