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


def convergence(arms: dict[str, list[dict[str, Any]]], progress: dict[str, list[tuple[int, float, int]]]
                ) -> bytes | None:
    """Median best cost with the interquartile band over runs, against iterations and against evaluations."""
    curves = {}
    for name, rows in arms.items():
        runs = [sorted(progress[r["config_hash"]]) for r in rows if progress.get(r["config_hash"])]
        runs = [run for run in runs if len(run) > 1]
        if runs:
            curves[name] = runs
    if not curves:
        return None
    fig, (by_iter, by_eval) = plt.subplots(1, 2, figsize=(10, 3.6))
    for name, runs in curves.items():
        costs = [np.array([c for _, c, _ in run]) for run in runs]
        length = max(c.size for c in costs)
        stack = _carried(costs, length)
        q1, med, q3 = np.percentile(stack, [25, 50, 75], axis=0)
        line, = by_iter.plot(np.arange(length), med, label=name)
        by_iter.fill_between(np.arange(length), q1, q3, alpha=0.2, color=line.get_color())
        grid = np.linspace(0, max(run[-1][2] for run in runs), 200)
        on_grid = np.stack([np.array([c for _, c, _ in run])[
            np.clip(np.searchsorted([e for _, _, e in run], grid, side="right") - 1, 0, len(run) - 1)]
            for run in runs])
        q1, med, q3 = np.percentile(on_grid, [25, 50, 75], axis=0)
        by_eval.plot(grid, med, label=name, color=line.get_color())
        by_eval.fill_between(grid, q1, q3, alpha=0.2, color=line.get_color())
    by_iter.set_xlabel("iteration")
    by_eval.set_xlabel("evaluations (spread evenly over iterations)")
    for ax in (by_iter, by_eval):
        ax.set_ylabel("best cost")
        ax.grid(alpha=0.3)
    by_iter.legend(fontsize=7)
    return _png(fig)


def paths(arms: dict[str, list[dict[str, Any]]], scenario) -> bytes | None:
    """The plan of the lowest seed of each arm over the scenario's obstacles at t = 0 (if it loads)."""
    drawn = False
    fig, ax = plt.subplots(figsize=(5, 5))
    if scenario is not None:
        for disc in scenario.discs_at(0.0):
            ax.add_patch(plt.Circle((disc.x_m, disc.y_m), disc.radius_m, color="0.6"))
        ax.add_collection(PatchCollection([plt.Rectangle((b.x_min_m, b.y_min_m), b.x_max_m - b.x_min_m,
                                                         b.y_max_m - b.y_min_m) for b in scenario.boxes],
                                          color="0.6"))
        bounds = scenario.bounds
        ax.set_xlim(bounds.x_min_m, bounds.x_max_m)
        ax.set_ylim(bounds.y_min_m, bounds.y_max_m)
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
