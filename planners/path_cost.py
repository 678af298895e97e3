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
from swarmnav.planners.disc_cells import DiscCells
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


def length_of_block(block: np.ndarray) -> np.ndarray:
    """:func:`length_of_columns` of a (2, S, P) block (the same arithmetic, in one buffer)."""
    d = block[:, 1:] - block[:, :-1]
    d *= d
    dx = d[0]
    dx += d[1]
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


def obstacle_penalty(xs: np.ndarray, ys: np.ndarray, centres_m: np.ndarray, radii_m: np.ndarray) -> np.ndarray:
    """Kamil et al. 2020's obstacle penalty, Eqs. (3)-(5), of (P, S) samples: the fast kernel
    (:func:`obstacle_penalty_of_block` on the samples stored sample-major)."""
    return obstacle_penalty_of_block(columns_block(xs, ys), DiscCells(centres_m, radii_m))


def columns_block(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """(2, S, P) block of (P, S) sampled curves."""
    return np.ascontiguousarray(np.stack([xs, ys]).transpose(0, 2, 1))


def obstacle_penalty_of_block(block: np.ndarray, cells: DiscCells) -> np.ndarray:
    """Kamil et al. 2020's obstacle penalty, Eqs. (3)-(5): the fast kernel, on samples stored
    as one contiguous (2, S, P) block (:meth:`planners.via_points.ViaPointCurve.sample_block`).

    The same value as :func:`obstacle_penalty_reference` (to rounding: the
    distance is ``sqrt(dx**2 + dy**2)`` rather than ``hypot``, and the sums run in
    another order), computed only where it can be non-zero: a term ``max(1 - d / R, 0)``
    is non-zero only for a sample inside the disc, so each sample is mapped to its cell
    of ``cells`` (:class:`planners.disc_cells.DiscCells`); samples in cells that no disc
    meets are dropped with one lookup, and the others are paired with their cell's
    discs only (the padding's sentinel disc gives exactly 0).  The terms are formed in
    place in one (M, K) buffer and summed per candidate with ``bincount``.

    Args:
        block: (2, S, P) sampled curves, x then y.
        cells: the discs (centres and the radii ``R`` of the penalty) and their cells.

    Returns:
        (P,) penalty.
    """
    _, samples, count = block.shape
    if cells.centres_m.shape[0] == 0 or count == 0:
        return np.zeros(count)
    cell = cells.cells_of(block).ravel()
    hit = np.flatnonzero(cells.occupied.take(cell, mode="clip"))    # into the (S, P) samples
    if hit.size == 0:
        return np.zeros(count)
    discs = cells.table.take(cell[hit], axis=1, mode="clip")       # (M, K)
    flat = block.reshape(2, -1)
    d = flat[0].take(hit) - cells.centre_x.take(discs)
    d *= d
    dy = flat[1].take(hit) - cells.centre_y.take(discs)
    dy *= dy
    d += dy
    np.sqrt(d, out=d)
    d *= cells.inverse_radius.take(discs)
    np.subtract(1.0, d, out=d)
    np.maximum(d, 0.0, out=d)
    return np.bincount(hit % count, weights=d.sum(axis=0), minlength=count) / samples


def bounds_penalty_of_block(block: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """:func:`bounds_penalty` of a (2, S, P) block; ``low``, ``high`` are (2, 1, 1) lower and
    upper limits of x and y.  Summed per axis and then added (the reference adds per
    sample; equal to rounding)."""
    out = np.clip(block, low, high)
    out -= block
    np.abs(out, out=out)
    per_axis = out.sum(axis=1)
    return (per_axis[0] + per_axis[1]) / block.shape[1]


def bounds_limits(bounds: Rect) -> tuple[np.ndarray, np.ndarray]:
    """(2, 1, 1) lower and upper limits of a (2, S, P) block's x and y."""
    return (np.array([bounds.x_min_m, bounds.y_min_m]).reshape(2, 1, 1),
            np.array([bounds.x_max_m, bounds.y_max_m]).reshape(2, 1, 1))


def bounds_penalty_of_columns(xt: np.ndarray, yt: np.ndarray, bounds: Rect) -> np.ndarray:
    """:func:`bounds_penalty` of (S, P) samples (through :func:`bounds_penalty_of_block`)."""
    return bounds_penalty_of_block(np.stack([xt, yt]), *bounds_limits(bounds))


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

    ``cost = w1 * length + w2 * smoothness + penalty_weight * (obstacle_penalty [+ bounds_penalty])``

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
        bounds_penalty: add :func:`bounds_penalty` (in neither paper: swarmnav's robust mode).
    """

    curve: ViaPointCurve
    centres_m: np.ndarray
    penalty_radii_m: np.ndarray
    bounds: Rect
    length_weight: float = 1.0
    smoothness_weight: float = 0.0
    penalty_weight: float = 1.0
    bounds_penalty: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "cells", DiscCells(self.centres_m, self.penalty_radii_m))
        object.__setattr__(self, "limits", bounds_limits(self.bounds))

    def __call__(self, population: np.ndarray) -> np.ndarray:
        """(P,) costs of a (P, 2k) population, all candidates at once."""
        return self.cost_of_block(self.curve.sample_block(population))

    def cost_from_samples(self, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        """(P,) costs of curves already sampled, (P, S) each (for peers that sample their own way)."""
        return self.cost_of_block(columns_block(xs, ys))

    def cost_of_columns(self, xt: np.ndarray, yt: np.ndarray) -> np.ndarray:
        """(P,) costs of curves sampled sample-major, (S, P)."""
        return self.cost_of_block(np.stack([xt, yt]))

    def cost_of_block(self, block: np.ndarray) -> np.ndarray:
        """(P,) costs of curves sampled into one (2, S, P) block (see
        :meth:`planners.via_points.ViaPointCurve.sample_block`)."""
        cost = length_of_block(block)
        if self.length_weight != 1.0 or self.smoothness_weight:
            smoothness = smoothness_rad(block[0].T, block[1].T) if self.smoothness_weight else 0.0
            cost = weighted_objective(cost, smoothness, self.length_weight, self.smoothness_weight)
        penalty = obstacle_penalty_of_block(block, self.cells)
        if self.bounds_penalty:
            penalty += bounds_penalty_of_block(block, *self.limits)
        penalty *= self.penalty_weight
        cost += penalty
        return cost
