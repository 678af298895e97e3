"""A fixed random linear policy on a flat observation, for the flatten / normalise tests (not a trained network)."""

import numpy as np


def act(obs):
    obs = np.asarray(obs, dtype=np.float64)
    weights = np.random.default_rng(len(obs)).normal(size=(2, len(obs))) / np.sqrt(len(obs))
    return np.tanh(weights @ obs + np.array([0.8, 0.0])).astype(np.float32)
