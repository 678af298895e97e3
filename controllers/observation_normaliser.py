"""A saved observation normalisation, applied by the ``policy`` navigator as in training.

A policy trained under Stable-Baselines3's ``VecNormalize`` (Raffin et al., 2021,
*Stable-Baselines3: Reliable Reinforcement Learning Implementations*, JMLR 22(268))
sees ``clip((obs - mean) / sqrt(var + epsilon), -clip, clip)`` with the running mean
and variance of training.  Saved as data (an ``.npz`` of arrays, never a pickle),
the same transform runs in ``swarmnav run``:

* a flat observation (``flatten=True``): arrays ``mean`` and ``var``;
* an observation dict: ``mean.<key>`` and ``var.<key>`` for each normalised key
  (keys without them pass through, as ``VecNormalize(norm_obs_keys=...)`` leaves them);
* scalars ``clip`` (default 10.0, VecNormalize's ``clip_obs``) and ``epsilon`` (default 1e-8).

``examples/rl/train_sb3.py`` writes one from its ``VecNormalize``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from swarmnav.models.errors import ConfigError

DEFAULT_CLIP = 10.0
DEFAULT_EPSILON = 1e-8


@dataclass(frozen=True)
class ObservationNormaliser:
    """``clip((obs - mean) / sqrt(var + epsilon), -clip, clip)`` per key ("" for a flat observation)."""

    mean: dict[str, np.ndarray]
    var: dict[str, np.ndarray]
    clip: float = DEFAULT_CLIP
    epsilon: float = DEFAULT_EPSILON

    def save(self, path: str | Path) -> None:
        arrays = {("mean" if key == "" else f"mean.{key}"): value for key, value in self.mean.items()}
        arrays |= {("var" if key == "" else f"var.{key}"): value for key, value in self.var.items()}
        np.savez(path, clip=self.clip, epsilon=self.epsilon, **arrays)

    @classmethod
    def load(cls, path: str | Path, field: str = "normalise") -> "ObservationNormaliser":
        try:
            with np.load(path, allow_pickle=False) as data:
                arrays = {name: np.asarray(data[name], dtype=np.float64) for name in data.files}
        except Exception as exc:  # a missing or unreadable file: a bad value of the option
            raise ConfigError(field, f"cannot read {str(path)!r}: {type(exc).__name__}: {exc}") from None
        mean = {name.partition(".")[2]: value for name, value in arrays.items() if name.split(".")[0] == "mean"}
        var = {name.partition(".")[2]: value for name, value in arrays.items() if name.split(".")[0] == "var"}
        if not mean or set(mean) != set(var):
            raise ConfigError(field, f"{str(path)!r} needs 'mean' and 'var' arrays (or 'mean.<key>' and "
                                     f"'var.<key>' pairs), has {sorted(arrays)}")
        for key in mean:
            if mean[key].shape != var[key].shape or np.any(var[key] < 0) or not np.all(np.isfinite(mean[key])):
                raise ConfigError(field, f"{str(path)!r}: mean and var of {key or 'the observation'!r} must be "
                                         f"finite arrays of one shape, var >= 0")
        clip = float(arrays.get("clip", DEFAULT_CLIP))
        epsilon = float(arrays.get("epsilon", DEFAULT_EPSILON))
        return cls(mean, var, clip, epsilon)

    def __call__(self, observation):
        if isinstance(observation, dict):
            if "" in self.mean:
                raise ValueError("a flat normalisation ('mean', 'var') given a dict observation: use flatten")
            return {key: self._one(key, value) if key in self.mean else value for key, value in observation.items()}
        if "" not in self.mean:
            raise ValueError("a per-key normalisation given a flat observation")
        return self._one("", observation)

    def _one(self, key: str, value: np.ndarray) -> np.ndarray:
        if np.shape(value) != self.mean[key].shape:
            raise ValueError(f"normalisation of {key or 'the observation'!r} has shape {self.mean[key].shape}, "
                             f"the observation {np.shape(value)}")
        scaled = (np.asarray(value, dtype=np.float64) - self.mean[key]) / np.sqrt(self.var[key] + self.epsilon)
        return np.clip(scaled, -self.clip, self.clip).astype(np.float32)
