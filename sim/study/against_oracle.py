"""The report's navigation section: each navigator against the clairvoyant oracle, over a study's dynamic scenes.

Read from the rows alone (their ``oracle_verdict``, ``time_score`` and difficulty columns, added when the study
ran: :mod:`swarmnav.study.yardstick`).  Per navigator (per arm where a scenario has several planners): every run in
``success`` and ``SPL`` (failures count, as everywhere in the report); the oracle-solvable runs alone in the
share solved and the mean time score (BARN's, Perille et al. 2020), so a scene the oracle calls unsolvable, or
could not decide, never counts against a navigator.  The figure sets each navigator's success on the
oracle-solvable scenes against one difficulty metric (:data:`FIGURE_METRIC`), the scenes in bins of equal
counts; the oracle itself, the yardstick, is in the table (its success validates its verdicts) but not in the
figure.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from swarmnav.study.statistics import arm
from swarmnav.study.tables import Table

FIGURE_METRIC = "dynamic_traversability"
FIGURE_BINS = 5
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
        clairvoyant = is_clairvoyant(group[0].get("navigator"))
        body.append([
            f"{navigator} (clairvoyant yardstick)" if clairvoyant else navigator, len(group), 100.0 * sum(bool(r["success"]) for r in group) / len(group),
            _mean([r.get("spl") or 0.0 for r in group]), len(solvable),
            sum(r["oracle_verdict"] == "unsolvable" for r in group),
            sum(r["oracle_verdict"] == "undecided" for r in group),
            100.0 * sum(bool(r["success"]) for r in solvable) / len(solvable) if solvable else None,
            _mean([r["time_score"] for r in solvable]),
        ])
    return Table("navigation-against-oracle", "Each navigator against the clairvoyant oracle (dynamic scenes)",
                 ["navigator", "runs", "success (%)", "SPL", "oracle-solvable runs", "unsolvable runs",
                  "undecided runs", "solved of solvable (%)", "time score"], body)


def is_clairvoyant(navigator: str | None) -> bool:
    """The yardstick itself (the ``oracle``), never a contender."""
    from swarmnav.controllers.navigators import NAVIGATORS
    return bool(getattr(NAVIGATORS.get(navigator or "follow"), "clairvoyant", False))


def binned_success(runs: list[dict[str, Any]], metric: str = FIGURE_METRIC, bins: int = FIGURE_BINS):
    """The oracle-solvable scenes (scenario and world seed) that have ``metric``, ordered by it and split into up
    to ``bins`` bins of equal counts: (each bin's mean ``metric``, its scene count, navigator -> the success share
    of that navigator's runs in each bin's scenes); the clairvoyant oracle left out.  None without such scenes."""
    rows = [r for r in dynamic_rows(runs) if r.get(metric) is not None and r["oracle_verdict"] == "solvable"
            and not is_clairvoyant(r.get("navigator"))]
    if not rows:
        return None
    scenes = sorted({(r["scenario"], r["world_seed"]): float(r[metric]) for r in rows}.items(),
                    key=lambda item: (item[1], str(item[0])))
    groups = [g for g in np.array_split(np.arange(len(scenes)), min(bins, len(scenes))) if len(g)]
    bin_of = {scenes[i][0]: k for k, g in enumerate(groups) for i in g}
    centres = [float(np.mean([scenes[i][1] for i in g])) for g in groups]
    name = group_name(rows)
    tally: dict[str, np.ndarray] = {}
    for r in rows:
        counts = tally.setdefault(name(r), np.zeros((len(groups), 2)))
        counts[bin_of[(r["scenario"], r["world_seed"])]] += (bool(r["success"]), 1)
    shares = {nav: [None if n == 0 else float(s / n) for s, n in counts] for nav, counts in tally.items()}
    return centres, [len(g) for g in groups], shares


def success_figure(runs: list[dict[str, Any]], metric: str = FIGURE_METRIC):
    """Each navigator's success over the oracle-solvable scenes, in bins of ``metric`` (:func:`binned_success`);
    None when no row has the metric."""
    import matplotlib.pyplot as plt
    from swarmnav.sim import palette
    from swarmnav.study.figures import MAX_WIDTH_IN
    found = binned_success(runs, metric)
    if found is None:
        return None
    centres, counts, shares = found
    fig, ax = plt.subplots(figsize=(min(MAX_WIDTH_IN, 7.0), 4.0))
    for k, (navigator, share) in enumerate(shares.items()):
        xy = np.array([(x, 100.0 * s) for x, s in zip(centres, share) if s is not None])
        ax.plot(xy[:, 0], xy[:, 1], color=palette.planner_colour(k), linestyle=palette.navigator_style(navigator),
                marker="o", markersize=4, label=navigator)
    for x, n in zip(centres, counts):
        ax.text(x, 108, str(n), ha="center", va="center", fontsize=7, color=palette.OBSTACLE)
    ax.set_xlabel(METRIC_TITLES.get(metric, metric) + ", mean of each bin (grey, above: its scenes)")
    ax.set_ylabel("success (%)")
    ax.set_ylim(-4, 114)
    ax.set_yticks(range(0, 101, 20))
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    fig.tight_layout()
    return fig
