"""The report's navigation section: each navigator against the clairvoyant oracle, over a study's dynamic scenes.

Read from the rows alone (their ``oracle_verdict``, ``time_score`` and difficulty columns, added when the study
ran: :mod:`sim.study.yardstick`).  Per navigator (per arm where a scenario has several planners): every run in
``success`` and ``SPL`` (failures count, as everywhere in the report); the oracle-solvable runs alone in the
share solved and the mean time score (BARN's, Perille et al. 2020), so a scene the oracle calls unsolvable, or
could not decide, never counts against a navigator.  The figure sets each oracle-solvable scene's success
share against one difficulty metric (:data:`FIGURE_METRIC`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from swarmnav.sim.study.statistics import arm
from swarmnav.sim.study.tables import Table

FIGURE_METRIC = "dynamic_traversability"
METRIC_TITLES = {"dynamic_traversability": "dynamic traversability (Shi et al. 2024; lower is harder)",
                 "survivability": "survivability (Shi et al. 2024; higher is harder)",
                 "t_star_ratio": "T* over the static arrival", "static_density": "static density (BARN)",
                 "dispersion": "dispersion (BARN)"}
STATEMENT = ("Each run of a dynamic scene is read against the clairvoyant oracle's verdict on that scene (its "
             "world seed and time limit): the oracle knows the obstacles' true future and searches a space-time "
             "lattice for the earliest collision-free arrival T*. Success and SPL count every run; 'solved' is the "
             "share of the runs on oracle-solvable scenes that succeeded, and the time score (BARN, Perille et al. "
             "2020: 0 on failure, else T*/T clipped to 1) is averaged over the same runs. Runs on scenes the oracle "
             "calls unsolvable at its resolution, or could not decide, are never counted against a navigator: they "
             "are left out of 'solved' and the time score, and counted in their own columns.")


def dynamic_rows(runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The rows read against the oracle (physics rows of dynamic scenarios)."""
    return [r for r in runs if r.get("oracle_verdict") is not None]


def group_name(rows: list[dict[str, Any]]):
    """The grouping of the rows: by navigator when each scenario has one planner label, else by arm."""
    labels: dict[str, set] = {}
    for r in rows:
        labels.setdefault(r["scenario"], set()).add(r["label"])
    if all(len(v) == 1 for v in labels.values()):
        return lambda r: r.get("navigator_label") or "follow"
    return arm


def _mean(values: list[float]) -> float | None:
    return float(np.mean(values)) if values else None


def navigator_table(runs: list[dict[str, Any]]) -> Table | None:
    """One row per navigator (see the module docstring); None without dynamic rows."""
    rows = dynamic_rows(runs)
    if not rows:
        return None
    name = group_name(rows)
    groups: dict[str, list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault(name(r), []).append(r)
    body = []
    for navigator, group in groups.items():
        solvable = [r for r in group if r["oracle_verdict"] == "solvable"]
        body.append([
            navigator, len(group), 100.0 * sum(bool(r["success"]) for r in group) / len(group),
            _mean([r.get("spl") or 0.0 for r in group]), len(solvable),
            sum(r["oracle_verdict"] == "unsolvable" for r in group),
            sum(r["oracle_verdict"] == "undecided" for r in group),
            100.0 * sum(bool(r["success"]) for r in solvable) / len(solvable) if solvable else None,
            _mean([r["time_score"] for r in solvable]),
        ])
    return Table("navigation-against-oracle", "Each navigator against the clairvoyant oracle (dynamic scenes)",
                 ["navigator", "runs", "success (%)", "SPL", "oracle-solvable runs", "unsolvable runs",
                  "undecided runs", "solved of solvable (%)", "time score"], body)


def scene_success(runs: list[dict[str, Any]], metric: str = FIGURE_METRIC) -> dict[str, list[tuple[float, float]]]:
    """navigator -> [(the scene's ``metric``, the navigator's success share there)], one point per oracle-solvable
    scene (scenario and world seed) that has the metric, ordered by the metric."""
    rows = [r for r in dynamic_rows(runs) if r.get(metric) is not None and r["oracle_verdict"] == "solvable"]
    if not rows:
        return {}
    name = group_name(rows)
    cells: dict[str, dict[tuple, list[dict[str, Any]]]] = {}
    for r in rows:
        cells.setdefault(name(r), {}).setdefault((r["scenario"], r["world_seed"]), []).append(r)
    return {nav: sorted((float(g[0][metric]), sum(bool(r["success"]) for r in g) / len(g)) for g in scenes.values())
            for nav, scenes in cells.items()}


def success_figure(runs: list[dict[str, Any]], metric: str = FIGURE_METRIC):
    """Each navigator's success share per oracle-solvable scene against ``metric`` (points), with the mean over up to five bins
    of equal counts (line); None when no row has the metric."""
    import matplotlib.pyplot as plt
    from swarmnav.sim import palette
    from swarmnav.sim.study.figures import MAX_WIDTH_IN
    points = scene_success(runs, metric)
    if not points:
        return None
    fig, ax = plt.subplots(figsize=(min(MAX_WIDTH_IN, 7.0), 4.0))
    for k, (navigator, xy) in enumerate(points.items()):
        colour = palette.planner_colour(k)
        data = np.array(xy)
        ax.plot(data[:, 0], 100.0 * data[:, 1], "o", color=colour, alpha=0.45, markersize=4)
        bins = [b for b in np.array_split(data, min(5, len(data))) if len(b)]
        ax.plot([b[:, 0].mean() for b in bins], [100.0 * b[:, 1].mean() for b in bins], color=colour,
                linestyle=palette.navigator_style(navigator), marker="s", markersize=3, label=navigator)
    ax.set_xlabel(METRIC_TITLES.get(metric, metric))
    ax.set_ylabel("success (%)")
    ax.set_ylim(-4, 104)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    fig.tight_layout()
    return fig
