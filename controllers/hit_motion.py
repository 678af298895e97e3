"""A moving disc fitted to the raw rangefinder hits of a short window (no MuJoCo).

The hit tracker (:mod:`controllers.tracking`) places a centre every step from
that step's hits alone; with the 12 beams 30 degrees apart most steps have one
hit on an obstacle, and one hit fixes only a point of the rim.  A velocity
regressed through such centres inherits their sideways slide: on dyn300 a disc
coming head-on at 0.15 m/s was reported crossing at 0.4 m/s for seconds.

Here every hit of the window constrains the motion directly: with the disc's
centre c(t) = c + v (t - t_now) and radius r, each hit h_k seen at t_k lies on
its rim, |h_k - c(t_k)| = r.  The centre c and velocity v minimise

    sum_k (|h_k - c(t_k)| - r)^2 + w_c |c - c_prior|^2 + w_v |v|^2

by Gauss-Newton (a few steps from the prior).  A hit fixes the centre along
its own direction only, so the weak priors keep the unobserved directions
(sideways of a single beam) where the step's fit put them, and the velocity
small where nothing measures it.  Ours (the papers only say the sensors detect
obstacles, Abdulla & Hadi (2025) Sec. 5.2); the least-squares fit of a moving
circle to points is the kinematic form of Kasa's (1976) fit, solved
geometrically rather than algebraically.
"""

from __future__ import annotations

import numpy as np

CENTRE_PRIOR_WEIGHT = 1.0       # w_c: the step's centre counts as much as one hit (residuals in metres)
VELOCITY_PRIOR_WEIGHT = 0.01    # w_v, in s^2: a velocity of 0.1 m/s costs what a 1 cm rim residual does
ITERATIONS = 4


def fit_moving_disc(times_s: np.ndarray, hits_m: np.ndarray, radius_m: float, now_s: float,
                    centre_prior_m: np.ndarray, velocity_start_m_s: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, float]:
    """(centre now (2,), velocity (2,), rms rim residual in metres) of the disc the hits (N, 2) seen at
    ``times_s`` (N,) lie on; the Gauss-Newton steps start at ``centre_prior_m`` and ``velocity_start_m_s``."""
    t = np.asarray(times_s, dtype=float) - now_s
    h = np.asarray(hits_m, dtype=float).reshape(-1, 2)
    prior = np.asarray(centre_prior_m, dtype=float)
    p = np.concatenate([prior, np.asarray(velocity_start_m_s, dtype=float)])
    reg = np.diag([CENTRE_PRIOR_WEIGHT, CENTRE_PRIOR_WEIGHT, VELOCITY_PRIOR_WEIGHT, VELOCITY_PRIOR_WEIGHT])
    res = np.zeros(len(h))
    for _ in range(ITERATIONS):
        d = h - (p[:2] + p[2:] * t[:, None])                 # (N, 2) hit relative to the centre then
        n = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-9)
        u = d / n[:, None]
        res = n - radius_m
        jac = -np.column_stack([u, u * t[:, None]])           # d res / d (cx, cy, vx, vy)
        prior_res = np.concatenate([p[:2] - prior, p[2:]])
        lhs = jac.T @ jac + reg
        rhs = -(jac.T @ res) - reg @ prior_res
        p = p + np.linalg.solve(lhs, rhs)
    d = h - (p[:2] + p[2:] * t[:, None])
    res = np.hypot(d[:, 0], d[:, 1]) - radius_m
    return p[:2], p[2:], float(np.sqrt(np.mean(res * res))) if len(res) else 0.0
