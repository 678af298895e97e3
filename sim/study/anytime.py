"""Anytime views of a study's best-cost histories (``progress.parquet``), as COCO/BBOB (Hansen et al. 2021,
"COCO: a platform for comparing continuous optimizers in a black-box setting") and IOHprofiler (Doerr et al.
2018) draw them:

* **fixed-budget**: the median best cost over a planner's runs, with the interquartile band, against the
  budget spent (objective evaluations; wall seconds), on a log-scaled budget axis;
* **fixed-target**: the empirical cumulative distribution of the budget at which a run first reaches a
  target, over the (run, target) pairs of a planner, targets at ``TARGET_FACTORS`` × the reference: the
  exact optimum where the study recorded one, else the best cost any run reached (the figure says which).
  A run with no history (no path, an error, a timeout) never reaches a target but counts in the
  denominator.

Each run's history is a step function: its best cost at a budget is the latest entry at or below it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

TARGET_FACTORS = (1.1, 1.03, 1.01, 1.003)
GRID_POINTS = 240


@dataclass(frozen=True)
class History:
    """One run's best-cost history."""

    cost: np.ndarray         # best cost after each entry (inf before the first feasible one)
    evaluations: np.ndarray  # cumulative objective evaluations at each entry
    wall_s: np.ndarray       # wall seconds since the plan started (NaN where not recorded)
    estimated: bool          # evaluations spread evenly (the planner recorded none)


def histories(progress_rows: list[dict[str, Any]]) -> dict[str, History]:
    """config_hash -> its history, from ``progress.parquet`` rows (a repeated entry of a resumed part once)."""
    entries: dict[str, dict[int, tuple]] = {}
    for p in progress_rows:
        entries.setdefault(p["config_hash"], {}).setdefault(
            p["iteration"], (p["best_cost"], p["evaluations"], p.get("wall_s"), bool(p.get("evaluations_estimated"))))
    out = {}
    for key, by_iteration in entries.items():
        ordered = [by_iteration[i] for i in sorted(by_iteration)]
        out[key] = History(np.array([e[0] for e in ordered], dtype=float),
                           np.array([e[1] for e in ordered], dtype=float),
                           np.array([np.nan if e[2] is None else e[2] for e in ordered], dtype=float),
                           any(e[3] for e in ordered))
    return out


def on_grid(budget: np.ndarray, cost: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """The step function (``budget`` ascending, ``cost`` after it) at each ``grid`` budget: the latest entry at
    or below it; NaN before the first entry."""
    index = np.searchsorted(budget, grid, side="right") - 1
    padded = np.append(cost, np.nan)
    return padded[np.where(index >= 0, index, -1)]


def first_reached(budget: np.ndarray, cost: np.ndarray, target: float) -> float:
    """The smallest budget at which the best cost is at or below ``target`` (inf if never)."""
    hit = np.flatnonzero(cost <= target)
    return float(budget[hit[0]]) if hit.size else float("inf")


def quartiles(stack: np.ndarray) -> np.ndarray:
    """25th, 50th and 75th percentiles of each column over every run, a run with no finite best cost there
    yet (not started, or no feasible candidate) counting as the worst; each quartile is a run's value (the
    inverted empirical CDF, no interpolation), NaN where it falls on such a run (not drawn)."""
    worst = np.where(np.isfinite(stack), stack, np.inf)
    out = np.percentile(worst, [25, 50, 75], axis=0, method="inverted_cdf")
    return np.where(np.isfinite(out), out, np.nan)


def log_grid(values: list[np.ndarray]) -> np.ndarray | None:
    """A log-spaced budget grid from the smallest positive budget to the largest (None if none is positive)."""
    positive = np.concatenate([v[np.isfinite(v) & (v > 0)] for v in values]) if values else np.array([])
    if positive.size == 0:
        return None
    low, high = float(positive.min()), float(positive.max())
    if high <= low:
        return np.array([low])
    return np.geomspace(low, high, GRID_POINTS)


def budget_of(history: History, axis: str) -> np.ndarray:
    return history.evaluations if axis == "evaluations" else history.wall_s


def fixed_budget(runs: list[History], axis: str) -> tuple[np.ndarray, np.ndarray] | None:
    """(grid, quartiles (3, grid)) of the best cost over ``runs`` against ``axis`` ("evaluations" or "wall_s");
    a run keeps its last best cost after it stopped."""
    usable = [h for h in runs if np.isfinite(budget_of(h, axis)).all() and budget_of(h, axis).size]
    grid = log_grid([budget_of(h, axis) for h in usable])
    if grid is None:
        return None
    stack = np.stack([on_grid(budget_of(h, axis), h.cost, grid) for h in usable])
    return grid, quartiles(stack)


def fixed_target(runs: list[History], total_runs: int, reference: float, axis: str
                 ) -> tuple[np.ndarray, np.ndarray] | None:
    """(grid, share of the ``total_runs`` × targets pairs reached by each budget) against ``axis``."""
    usable = [h for h in runs if np.isfinite(budget_of(h, axis)).all() and budget_of(h, axis).size]
    grid = log_grid([budget_of(h, axis) for h in usable])
    if grid is None or total_runs == 0:
        return None
    hits = np.array([first_reached(budget_of(h, axis), h.cost, reference * factor)
                     for h in usable for factor in TARGET_FACTORS])
    reached = np.searchsorted(np.sort(hits), grid, side="right")
    return grid, reached / (total_runs * len(TARGET_FACTORS))


def reference_cost(optimum_m: float | None, runs: list[History]) -> tuple[float | None, str]:
    """The targets' reference: the exact optimum, else the best cost any run reached (and which it is)."""
    if optimum_m is not None:
        return float(optimum_m), f"the exact optimum {optimum_m:.4g} m"
    finals = [float(np.min(h.cost)) for h in runs if h.cost.size and np.isfinite(h.cost).any()]
    if not finals:
        return None, "no reference: no run reached a finite cost"
    best = min(finals)
    return best, f"no exact optimum for this scenario; the best cost any run reached, {best:.4g}"
