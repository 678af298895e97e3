"""The robust mode's final local polish of the best candidate: a compass search.

Compass (coordinate) search as Kolda, Lewis & Torczon (2003, "Optimization by direct
search: new perspectives on some classical and modern methods", SIAM Review 45(3),
Algorithm 3.2) state it: from the incumbent ``x`` with step ``delta``, try the ``2 n``
points ``x +- delta e_i``; move to the best of them when it lowers the cost, otherwise
halve ``delta``.  All ``2 n`` trial points of a round are one population, evaluated in one
call.  The search moves on the cost alone (its penalty keeps the curve out of the grown
discs); at the end the exact check (``accept``) is run on the last incumbent and, if that
fails, on the earlier ones, newest first, down to ``start`` (which the caller has checked):
the polish never turns a feasible path into an infeasible one, and it runs the exact
check about once instead of once a move.
"""

from __future__ import annotations

from typing import Callable

import numpy as np


def compass_directions(dimensions: int) -> np.ndarray:
    """(2 n, n) the unit moves ``+e_i`` then ``-e_i``."""
    eye = np.eye(dimensions)
    return np.vstack([eye, -eye])


def compass_polish(start: np.ndarray, start_cost: float, evaluate: Callable[[np.ndarray], np.ndarray],
                   accept: Callable[[np.ndarray], bool], lower: np.ndarray, upper: np.ndarray,
                   step_m: float, rounds: int, min_step_m: float = 1e-4) -> tuple[np.ndarray, float, int]:
    """Compass search from ``start`` for at most ``rounds`` rounds.

    Args:
        evaluate: (M, n) -> (M,) costs (may return ``inf`` once a budget is spent).
        accept: whether a candidate may be returned (the exact check); ``start`` is taken to pass.
        step_m: the first step ``delta``; the search stops below ``min_step_m``.

    Returns:
        (incumbent, its cost, rounds done).
    """
    best = np.asarray(start, dtype=float).copy()
    best_cost = float(start_cost)
    moves = compass_directions(best.size)
    step = float(step_m)
    trail = [(best, best_cost)]
    done = 0
    for done in range(1, rounds + 1):
        trial = np.clip(best[None, :] + step * moves, lower, upper)
        costs = evaluate(trial)
        i = int(np.argmin(costs))
        if costs[i] < best_cost:
            best, best_cost = trial[i].copy(), float(costs[i])
            trail.append((best, best_cost))
        else:
            step *= 0.5
            if step < min_step_m:
                break
    for candidate, cost in reversed(trail[1:]):
        if accept(candidate):
            return candidate, cost, done
    return trail[0][0], trail[0][1], done
