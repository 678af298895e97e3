"""The report's figures, drawn from the rows with matplotlib (Agg) and returned as PNG bytes."""

from __future__ import annotations

import io
import json
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import PatchCollection  # noqa: E402
import numpy as np  # noqa: E402

from swarmnav.sim.study.statistics import values  # noqa: E402


def _png(fig) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=90, bbox_inches="tight")
    plt.close(fig)
    return buffer.getvalue()


def box_plots(arms: dict[str, list[dict[str, Any]]], metrics: list[str]) -> bytes | None:
    if not metrics:  # every run failed: nothing to draw
        return None
    fig, axes = plt.subplots(1, len(metrics), figsize=(4.2 * len(metrics), 3.6), squeeze=False)
    names = list(arms)
    for ax, metric in zip(axes[0], metrics):
        data = [values(arms[n], metric) for n in names]
        ax.boxplot([d if d.size else [np.nan] for d in data], showmeans=True)
        ax.set_xticks(range(1, len(names) + 1), names, rotation=30, ha="right", fontsize=8)
        ax.set_title(metric, fontsize=9)
        ax.grid(axis="y", alpha=0.3)
    return _png(fig)


def success_bars(arms: dict[str, list[dict[str, Any]]]) -> bytes:
    names = list(arms)
    rates = [np.mean([bool(r["success"]) for r in arms[n]]) * 100 for n in names]
    fig, ax = plt.subplots(figsize=(max(3.5, 0.9 * len(names) + 1.5), 3.2))
    bars = ax.bar(range(len(names)), rates, color="tab:green")
    for bar, n in zip(bars, names):
        failed = sum(r["outcome"] != "ok" for r in arms[n])
        ax.text(bar.get_x() + bar.get_width() / 2, bar.get_height() + 1, f"{failed} failed", ha="center", fontsize=7)
    ax.set_xticks(range(len(names)), names, rotation=30, ha="right", fontsize=8)
    ax.set_ylim(0, 110)
    ax.set_ylabel("success rate (%)")
    return _png(fig)


def _carried(histories: list[np.ndarray], length: int) -> np.ndarray:
    """Best-cost histories padded to ``length`` with their final value (a run that stopped keeps its best)."""
    return np.stack([np.concatenate([h, np.full(length - h.size, h[-1])]) for h in histories])


def _quartiles(stack: np.ndarray) -> np.ndarray:
    """25th, 50th and 75th percentiles of each column over the runs that have a finite best cost there
    (before its first tour a colony's best cost is infinite); NaN where no run has one yet."""
    finite = np.where(np.isfinite(stack), stack, np.nan)
    out = np.full((3, stack.shape[1]), np.nan)
    some = ~np.all(np.isnan(finite), axis=0)
    if some.any():
        out[:, some] = np.nanpercentile(finite[:, some], [25, 50, 75], axis=0)
    return out


def _on_evaluation_grid(run: list[tuple], grid: np.ndarray) -> np.ndarray:
    """A run's best cost after each number of evaluations in ``grid``: the latest entry recorded at or below
    it (a step function); NaN before the run's first entry (a population is scored before it exists)."""
    index = np.searchsorted([e for _, _, e, *_ in run], grid, side="right") - 1
    costs = np.array([c for _, c, *_ in run] + [np.nan])
    return costs[np.where(index >= 0, index, -1)]


def convergence(arms: dict[str, list[dict[str, Any]]], progress: dict[str, list[tuple]]) -> bytes | None:
    """Median best cost with the interquartile band over runs, against iterations and against evaluations.

    ``progress`` maps a run's ``config_hash`` to its ``(iteration, best_cost, evaluations[, estimated])``
    entries; ``estimated`` (True where the planner recorded no evaluation history and the total was spread
    evenly over its iterations) is named on the evaluations axis."""
    curves = {}
    for name, rows in arms.items():
        runs = [sorted(progress[r["config_hash"]]) for r in rows if progress.get(r["config_hash"])]
        runs = [run for run in runs if len(run) > 1]
        if runs:
            curves[name] = runs
    if not curves:
        return None
    fig, (by_iter, by_eval) = plt.subplots(1, 2, figsize=(10, 3.6))
    estimated = set()
    for name, runs in curves.items():
        costs = [np.array([c for _, c, *_ in run]) for run in runs]
        length = max(c.size for c in costs)
        stack = _carried(costs, length)
        q1, med, q3 = _quartiles(stack)
        line, = by_iter.plot(np.arange(length), med, label=name)
        by_iter.fill_between(np.arange(length), q1, q3, alpha=0.2, color=line.get_color())
        grid = np.linspace(0, max(run[-1][2] for run in runs), 200)
        q1, med, q3 = _quartiles(np.stack([_on_evaluation_grid(run, grid) for run in runs]))
        by_eval.plot(grid, med, label=name, color=line.get_color())
        by_eval.fill_between(grid, q1, q3, alpha=0.2, color=line.get_color())
        if any(len(entry) > 3 and entry[3] for run in runs for entry in run):
            estimated.add(name)
    by_iter.set_xlabel("iteration")
    by_eval.set_xlabel("evaluations" + (f" (spread evenly over iterations for {', '.join(sorted(estimated))})"
                                        if estimated else ""))
    for ax in (by_iter, by_eval):
        ax.set_ylabel("best cost")
        ax.grid(alpha=0.3)
    by_iter.legend(fontsize=7)
    return _png(fig)


def paths(arms: dict[str, list[dict[str, Any]]], geometry: dict[str, Any] | None) -> bytes | None:
    """The plan of the lowest seed of each arm over the scenario as ``study.json`` recorded it at run time
    (arena, start, goal, obstacle footprints at t = 0); without it, the paths alone."""
    drawn = False
    fig, ax = plt.subplots(figsize=(5, 5))
    if geometry:
        for x, y, r in geometry.get("discs_t0", []):
            ax.add_patch(plt.Circle((x, y), r, color="0.6"))
        ax.add_collection(PatchCollection([plt.Rectangle((x0, y0), x1 - x0, y1 - y0)
                                           for x0, y0, x1, y1 in geometry.get("boxes", [])], color="0.6"))
        width_m, height_m = geometry["arena_m"]
        ax.set_xlim(0.0, width_m)
        ax.set_ylim(0.0, height_m)
        ax.plot(*geometry["start"], "k^", markersize=7)
        ax.plot(*geometry["goal"], "k*", markersize=9)
    for name, rows in arms.items():
        ok = sorted((r for r in rows if r.get("plan_waypoints")), key=lambda r: (r["seed"], str(r["world_seed"])))
        if ok:
            points = np.array(json.loads(ok[0]["plan_waypoints"]))
            ax.plot(points[:, 0], points[:, 1], marker=".", markersize=3, label=f"{name} (seed {ok[0]['seed']})")
            drawn = True
    if not drawn:
        plt.close(fig)
        return None
    ax.set_aspect("equal")
    ax.legend(fontsize=7)
    return _png(fig)
