"""Path costs of the continuous planners, vectorised over a whole population.

Every function takes sampled curves ``xs, ys`` of shape ``(P, S)`` (``P``
candidates, ``S`` samples each, from :class:`planners.via_points.ViaPointCurve`)
and returns one value per candidate, shape ``(P,)``.

* Length: Kamil et al. (2020) Eq. (1) and Abdulla & Hadi (2025) Eq. (2) (the same sum of chord lengths).
* Obstacle penalty: Kamil et al. (2020) Eqs. (3)-(5).
* Smoothness: Abdulla & Hadi (2025) Eqs. (3)-(5).
* Weighted objective and its fitness: Abdulla & Hadi (2025) Eqs. (6)-(8); Kamil et al. (2020) Eq. (2).

:class:`PathObjective` combines them into the one cost the optimisers minimise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from swarmnav.models.world import Rect
from swarmnav.planners.via_points import ViaPointCurve


def sampled_length_m(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """Length of each sampled curve, Kamil et al. (2020) Eq. (1) / Abdulla & Hadi (2025) Eq. (2).

    ``F = sum_i sqrt((x[i+1] - x[i])**2 + (y[i+1] - y[i])**2)`` over the samples.
    """
    return length_of_columns(np.ascontiguousarray(xs.T), np.ascontiguousarray(ys.T))


def length_of_columns(xt: np.ndarray, yt: np.ndarray) -> np.ndarray:
    """:func:`sampled_length_m` of curves stored sample-major, (S, P): every NumPy call then
    runs along the long, contiguous candidate axis (``sqrt`` of the squares, not ``hypot``,
    which is several times slower)."""
    dx = xt[1:] - xt[:-1]
    dy = yt[1:] - yt[:-1]
    dx *= dx
    dy *= dy
    dx += dy
    np.sqrt(dx, out=dx)
    return dx.sum(axis=0)


def obstacle_penalty_reference(xs: np.ndarray, ys: np.ndarray, centres_m: np.ndarray,
                               radii_m: np.ndarray) -> np.ndarray:
    """Kamil et al. 2020's obstacle penalty, Eqs. (3)-(5), written as the paper states it.

    For every obstacle ``j``: ``Dist`` is the distance of each sample to its
    centre (Eq. 5), ``v = max(1 - Dist / R, 0)`` (Eq. 4), and the penalty grows
    by ``mean(v)`` over the samples (Eq. 3), i.e. ``$p = sum_j mean_i v_ij``.
    Every sample-disc pair is computed; :func:`obstacle_penalty` is the fast
    kernel the planners use, which the tests compare with this one.

    Args:
        xs, ys: (P, S) sampled curves.
        centres_m: (C, 2) obstacle centres.
        radii_m: (C,) radii ``R`` (the caller passes the inflated radii).

    Returns:
        (P,) penalty, 0 for a candidate whose samples all lie outside every disc.
    """
    centres = np.asarray(centres_m, dtype=float).reshape(-1, 2)
    if centres.shape[0] == 0:
        return np.zeros(xs.shape[0])
    radii = np.asarray(radii_m, dtype=float).reshape(-1)
    dist = np.hypot(xs[:, :, None] - centres[:, 0], ys[:, :, None] - centres[:, 1])  # (P, S, C)
    violation = np.maximum(1.0 - dist / radii, 0.0)
    return violation.mean(axis=1).sum(axis=1)


#: Most samples per chunk of a curve whose bounding box :func:`obstacle_penalty` tests against each disc.
PENALTY_CHUNK = 10


def sample_boxes(xt: np.ndarray, yt: np.ndarray) -> np.ndarray:
    """(4, P) each candidate's sample bounding box (x_min, x_max, y_min, y_max) from (S, P) samples."""
    return np.stack([xt.min(axis=0), xt.max(axis=0), yt.min(axis=0), yt.max(axis=0)])


def obstacle_penalty(xs: np.ndarray, ys: np.ndarray, centres_m: np.ndarray, radii_m: np.ndarray) -> np.ndarray:
    """Kamil et al. 2020's obstacle penalty, Eqs. (3)-(5), of (P, S) samples: the fast kernel
    (:func:`obstacle_penalty_of_columns` on the transposed samples)."""
    return obstacle_penalty_of_columns(np.ascontiguousarray(xs.T), np.ascontiguousarray(ys.T), centres_m, radii_m)


def _chunk_size(samples: int) -> int:
    """The largest chunk of at most :data:`PENALTY_CHUNK` samples that divides ``samples``
    (at least 4), else :data:`PENALTY_CHUNK` with padding."""
    for size in range(PENALTY_CHUNK, 3, -1):
        if samples % size == 0:
            return size
    return PENALTY_CHUNK


def obstacle_penalty_of_columns(xt: np.ndarray, yt: np.ndarray, centres_m: np.ndarray,
                                radii_m: np.ndarray) -> np.ndarray:
    """Kamil et al. 2020's obstacle penalty, Eqs. (3)-(5): the fast kernel, on samples stored
    sample-major, (S, P).

    The same value as :func:`obstacle_penalty_reference` (to rounding: the
    distance is ``sqrt(dx**2 + dy**2)`` rather than ``hypot`` and the sums run in
    another order), computed only where it can be non-zero:

    * layout: samples are rows, candidates columns, so every reduction runs along
      the long contiguous axis (NumPy reduces short rows one by one, ~30x slower);
    * culling: each curve is cut into chunks of up to :data:`PENALTY_CHUNK`
      samples (padded by repeating the last sample, with weight 0, when no size
      divides the sample count); a disc can contribute to a chunk only if the
      chunk's bounding box meets the disc's bounding square (otherwise every
      sample is at least ``R`` away on one axis, so ``v = 0``), and only those
      (chunk, candidate, disc) triples are computed;
    * their terms are formed in place in one buffer (squares, root, scale,
      ``1 - .``, clip at 0) and summed per candidate with ``bincount``.

    Args:
        xt, yt: (S, P) sampled curves, one column per candidate.
        centres_m: (C, 2) obstacle centres.
        radii_m: (C,) radii ``R``.

    Returns:
        (P,) penalty.
    """
    samples, count = xt.shape
    centres = np.asarray(centres_m, dtype=float).reshape(-1, 2)
    if centres.shape[0] == 0 or count == 0:
        return np.zeros(count)
    radii = np.asarray(radii_m, dtype=float).reshape(-1)
    chunk = _chunk_size(samples)
    chunks = -(-samples // chunk)
    pad = chunks * chunk - samples
    if pad:
        xt = np.concatenate([xt, np.repeat(xt[-1:], pad, axis=0)])
        yt = np.concatenate([yt, np.repeat(yt[-1:], pad, axis=0)])
    x3 = xt.reshape(chunks, chunk, count)
    y3 = yt.reshape(chunks, chunk, count)
    cx, cy = centres[:, 0], centres[:, 1]
    near = ((x3.min(axis=1)[..., None] <= cx + radii) & (x3.max(axis=1)[..., None] >= cx - radii)
            & (y3.min(axis=1)[..., None] <= cy + radii) & (y3.max(axis=1)[..., None] >= cy - radii))  # (n, P, C)
    which, cand, discs = np.nonzero(near)
    if which.size == 0:
        return np.zeros(count)
    d = x3.transpose(1, 0, 2)[:, which, cand] - cx[discs]            # (chunk, K)
    d *= d
    dy = y3.transpose(1, 0, 2)[:, which, cand] - cy[discs]
    dy *= dy
    d += dy
    np.sqrt(d, out=d)
    d *= 1.0 / radii[discs]
    np.subtract(1.0, d, out=d)
    np.maximum(d, 0.0, out=d)
    if pad:
        d[chunk - pad:, which == chunks - 1] = 0.0
    return np.bincount(cand, weights=d.sum(axis=0), minlength=count) / samples


def bounds_penalty_of_columns(xt: np.ndarray, yt: np.ndarray, bounds: Rect) -> np.ndarray:
    """:func:`bounds_penalty` of (S, P) samples; only the candidates whose samples leave
    the bounds are computed (the others get exactly 0)."""
    boxes = sample_boxes(xt, yt)
    out = ((boxes[0] < bounds.x_min_m) | (boxes[1] > bounds.x_max_m)
           | (boxes[2] < bounds.y_min_m) | (boxes[3] > bounds.y_max_m))
    penalty = np.zeros(xt.shape[1])
    if out.any():
        penalty[out] = bounds_penalty(xt[:, out].T, yt[:, out].T, bounds)
    return penalty


def bounds_penalty(xs: np.ndarray, ys: np.ndarray, bounds: Rect, scale_m: float = 1.0) -> np.ndarray:
    """Mean distance (in units of ``scale_m``) by which the samples leave the workspace.

    Not in the papers (their splines are not checked against the arena edges);
    added so that a spline does not buy length by overshooting the bounds.
    """
    out_x = np.maximum(bounds.x_min_m - xs, 0.0) + np.maximum(xs - bounds.x_max_m, 0.0)
    out_y = np.maximum(bounds.y_min_m - ys, 0.0) + np.maximum(ys - bounds.y_max_m, 0.0)
    return (out_x + out_y).mean(axis=1) / scale_m


def wrap_angle_rad(angle_rad: np.ndarray) -> np.ndarray:
    """Wrap angles to [-pi, pi)."""
    return (angle_rad + np.pi) % (2.0 * np.pi) - np.pi


def smoothness_rad(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """Abdulla & Hadi 2025's smoothness, Eqs. (3)-(5).

    ``F2 = sum_i |theta(p_i, p_{i+1}) - theta(p_i, p_N)|`` over samples
    ``i = 1 .. N-1``, where Eq. (4) is the heading of the next step and Eq. (5)
    the bearing to the goal ``p_N``.  The extraction lost the operator between
    the two angles; a difference is the only reading that measures "the angular
    difference between the present and proposed locations".  ``tan^-1`` is taken
    as the four-quadrant ``arctan2`` and the difference is wrapped to [-pi, pi),
    so a step straight at the goal costs 0 whatever its direction.
    """
    step = np.arctan2(np.diff(ys, axis=1), np.diff(xs, axis=1))                        # (P, S-1)
    to_goal = np.arctan2(ys[:, -1:] - ys[:, :-1], xs[:, -1:] - xs[:, :-1])              # (P, S-1)
    return np.sum(np.abs(wrap_angle_rad(step - to_goal)), axis=1)


def weighted_objective(length_m: np.ndarray, smoothness: np.ndarray, length_weight: float,
                       smoothness_weight: float) -> np.ndarray:
    """Abdulla & Hadi (2025) Eq. (6): ``F = w1 F1 + w2 F2`` (Eq. (7) only names ``w = w1 + w2``)."""
    return length_weight * length_m + smoothness_weight * smoothness


def inverse_fitness(objective: np.ndarray, epsilon: float = 0.001) -> np.ndarray:
    """Abdulla & Hadi (2025) Eq. (8) ``1 / (F + e)``; with ``e = 0`` and ``F`` = length + penalty, Kamil et al. (2020) Eq. (2)."""
    return 1.0 / (np.asarray(objective, dtype=float) + epsilon)


@dataclass(frozen=True, eq=False)
class PathObjective:
    """The cost every continuous planner minimises (lower is better).

    ``cost = w1 * length + w2 * smoothness + penalty_weight * (obstacle_penalty + bounds_penalty)``

    With ``w2 = 0`` this is Kamil et al. 2020's ``F + $p`` (Eqs. (1)-(5), the reciprocal
    of its fitness Eq. (2)) with the penalty scaled; with ``w2 > 0`` it is Abdulla & Hadi
    2025's Eq. (6) plus that penalty (Abdulla & Hadi 2025 states no obstacle term in its
    objective).  Minimising the cost is the same as maximising either paper's
    fitness ``1 / (cost + e)``, Eq. (8).

    Attributes:
        curve: the encoding that turns decision vectors into samples.
        centres_m: (C, 2) disc centres.
        penalty_radii_m: (C,) radii ``R`` used by the penalty (inflated radius plus margin).
        bounds: the workspace.
        length_weight, smoothness_weight: ``w1`` and ``w2`` of Eq. (6).
        penalty_weight: multiplier of the penalty (Kamil et al. 2020 uses 1).
    """

    curve: ViaPointCurve
    centres_m: np.ndarray
    penalty_radii_m: np.ndarray
    bounds: Rect
    length_weight: float = 1.0
    smoothness_weight: float = 0.0
    penalty_weight: float = 1.0

    def __call__(self, population: np.ndarray) -> np.ndarray:
        """(P,) costs of a (P, 2k) population, all candidates at once."""
        xt, yt = self.curve.sample_columns(population)
        return self.cost_of_columns(xt, yt)

    def cost_from_samples(self, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        """(P,) costs of curves already sampled, (P, S) each (for peers that sample their own way)."""
        return self.cost_of_columns(np.ascontiguousarray(xs.T), np.ascontiguousarray(ys.T))

    def cost_of_columns(self, xt: np.ndarray, yt: np.ndarray) -> np.ndarray:
        """(P,) costs of curves sampled sample-major, (S, P)."""
        smoothness = smoothness_rad(xt.T, yt.T) if self.smoothness_weight else 0.0
        cost = weighted_objective(length_of_columns(xt, yt), smoothness, self.length_weight, self.smoothness_weight)
        penalty = obstacle_penalty_of_columns(xt, yt, self.centres_m, self.penalty_radii_m)
        penalty = penalty + bounds_penalty_of_columns(xt, yt, self.bounds)
        return cost + self.penalty_weight * penalty
