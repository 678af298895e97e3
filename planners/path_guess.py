"""A fast geometric guess for the continuous planners' robust mode, and its via-points.

Three of the robust options of :class:`planners.continuous.ContinuousPlanner` start here:

* the guess (:func:`grid_guesses`): a grid A* path, exactly shortcut by line of sight
  (:class:`planners.grid_search.AStarPlanner`), on the problem's own grid of the inflated
  discs (``guess_cell_m`` to choose another cell).  On dense-field-30 it is 1.007 x the
  exact optimum in about 10 ms, where the exact tangent graph (:mod:`planners.optimal`)
  takes 0.3 s.  A coarser grid is faster but closes narrow gaps: on one random 33-disc
  field the 0.1 m guess is 1.14 x the optimum, the 0.05 m one 1.013 x; seeding with both
  let the wrong one win (its fit is clear of the discs, the right one's cuts a little);
* the number of via-points chosen from the scene, :func:`via_points_for_guess`: one per
  bend of the guess plus two, between 3 (the papers') and :data:`MAX_AUTO_VIA_POINTS`
  (on dense-field-30, 5, 8 and 13 via-points gave the same median length, 1.002-1.003 x
  the optimum; 3 cannot follow its six bends);
* the seeds, :func:`fit_via_points`: the via-points whose curve is nearest the guess in
  the least-squares sense (the curve is linear in the via-points, so this is one
  ``lstsq``), then perturbed copies (:func:`seeded_population`).

Seeding an initial population with a heuristic solution is the standard hybrid
initialisation of population methods (e.g. Kazimipour, Li & Qin 2014, "A review of
population initialization techniques for evolutionary algorithms", CEC 2014, Sect. III-C).
"""

from __future__ import annotations

import numpy as np

from swarmnav.planners.errors import PlanningError
from swarmnav.planners.problem import Problem
from swarmnav.planners.via_points import ViaPointCurve

#: Most via-points :func:`via_points_for_guess` chooses.
MAX_AUTO_VIA_POINTS = 16


def grid_guesses(problem: Problem, cell_m: float | None = None) -> tuple[np.ndarray, ...]:
    """The (N, 2) waypoints of the shortcut A* path at ``cell_m`` (None: the problem's cell),
    as a tuple of one, or of none when the grid has no path."""
    from swarmnav.planners.grid_search import AStarPlanner

    try:
        return (AStarPlanner(cell_m=cell_m).plan(problem, np.random.default_rng(0)).waypoints,)
    except PlanningError:
        return ()


def via_points_for_guess(waypoints: np.ndarray) -> int:
    """Via-points for a curve that follows ``waypoints``: ``bends + 2``, clamped to
    [3, :data:`MAX_AUTO_VIA_POINTS`] (3 is the papers' count)."""
    bends = max(np.asarray(waypoints).reshape(-1, 2).shape[0] - 2, 0)
    return int(min(max(bends + 2, 3), MAX_AUTO_VIA_POINTS))


def resample_by_length(waypoints: np.ndarray, fractions: np.ndarray) -> np.ndarray:
    """(len(fractions), 2) points at the given fractions of the polyline's length."""
    pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
    if along[-1] <= 0.0:
        return np.repeat(pts[:1], fractions.size, axis=0)
    at = np.asarray(fractions, dtype=float) * along[-1]
    return np.column_stack([np.interp(at, along, pts[:, 0]), np.interp(at, along, pts[:, 1])])


def fit_via_points(curve: ViaPointCurve, waypoints: np.ndarray) -> np.ndarray:
    """(2k,) the decision vector whose sampled curve is nearest ``waypoints`` (least squares,
    sample ``s`` of the curve against the point at the same fraction of the guess's length)."""
    fractions = np.linspace(0.0, 1.0, curve.samples)
    target = resample_by_length(waypoints, fractions)                 # (S, 2)
    basis = curve._via_basis.T                                         # (S, k)
    rhs = target - curve._end_offset.T                                 # (S, 2)
    via, *_ = np.linalg.lstsq(basis, rhs, rcond=None)                  # (k, 2)
    return np.concatenate([via[:, 0], via[:, 1]])


def seeded_population(fit: np.ndarray, count: int, spread_m: float, lower: np.ndarray,
                      upper: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """``count`` copies of ``fit``: the first exact, the others with Gaussian noise whose
    standard deviation grows linearly up to ``spread_m``; clipped to the search box."""
    scale = np.linspace(0.0, spread_m, max(count, 1))[:count, None]
    noise = rng.normal(0.0, 1.0, (count, fit.size)) * scale
    return np.clip(fit[None, :] + noise, lower, upper)
