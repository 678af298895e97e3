"""Summaries and tests over a study's rows (plain dicts as read from ``runs.parquet``).

* per arm (planner label, navigator label): runs, failures, success rate, and
  mean ± std (sample, ddof = 1), median and best of each metric over the runs
  that produced it;
* between arms on one scenario, for each metric (length, time, clearance, ...): the
  Wilcoxon rank-sum test (``scipy.stats.ranksums``, as Gong et al. 2022,
  Table 4 use it on path lengths) with Cliff's delta;
  the Wilcoxon signed-rank test (``scipy.stats.wilcoxon``) on the runs that pair by
  (seed, world seed) with the matched-pairs rank-biserial correlation; Holm's
  step-down correction over the comparisons against the reference planner; and the
  Friedman test across all arms on the seeds every arm completed, with Kendall's W;
* success rates: Fisher's exact test (``scipy.stats.fisher_exact``) of the reference
  arm's successes and failures against each other arm's, Holm-corrected;
* a one-row-per-arm table in the shape of Gong et al. (2022) Table 3: best (the paper's
  "optimal") and mean length, std, convergence iteration, bends and time, with the IMMAS
  columns (Hasan et al. 2023: gates raised, tunnels closed, arc cost) where present.
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass
from typing import Any, Iterable

import numpy as np
from scipy import stats

LOWER_IS_BETTER = {"min_clearance_m": False}  # every other metric: lower is better


def arm(row: dict[str, Any]) -> str:
    """The name of a row's arm: the planner label, with the navigator's when it is not plain follow."""
    navigator = row.get("navigator_label") or "follow"
    return row["label"] if navigator == "follow" else f"{row['label']} + {navigator}"


def by_scenario(rows: Iterable[dict[str, Any]]) -> dict[str, dict[str, list[dict[str, Any]]]]:
    """scenario -> arm -> rows, both in first-seen order."""
    out: dict[str, dict[str, list[dict[str, Any]]]] = {}
    for row in rows:
        out.setdefault(row["scenario"], {}).setdefault(arm(row), []).append(row)
    return out


def values(rows: list[dict[str, Any]], metric: str) -> np.ndarray:
    return np.array([r[metric] for r in rows if r.get(metric) is not None and r.get("outcome") == "ok"], dtype=float)


@dataclass
class MetricSummary:
    n: int
    mean: float
    std: float
    median: float
    best: float


def summarise(rows: list[dict[str, Any]], metric: str) -> MetricSummary | None:
    v = values(rows, metric)
    if v.size == 0:
        return None
    best = float(v.max() if not LOWER_IS_BETTER.get(metric, True) else v.min())
    if np.ptp(v) <= 1e-12 * max(1.0, abs(float(v[0]))):  # identical runs up to rounding: no spread
        return MetricSummary(int(v.size), float(v[0]), 0.0 if v.size > 1 else float("nan"), float(v[0]), best)
    return MetricSummary(int(v.size), float(v.mean()), float(v.std(ddof=1)) if v.size > 1 else float("nan"),
                         float(np.median(v)), best)


OUTCOME_CLASSES = ("success", "collision", "left arena", "timeout", "no path", "error")


def outcome_class(row: dict[str, Any]) -> str:
    """What became of a run, one of :data:`OUTCOME_CLASSES`: success is the goal reached with no collision
    (plan-only: a collision-free plan); a collision is any contact on the way (plan-only: a plan that cuts an
    obstacle); "left arena" a run whose robot left the arena (or drove a given path that leaves it), collisions
    or not; a timeout is the wall limit or, in physics, the simulated-time limit with no collision."""
    outcome = row.get("outcome")
    if outcome == "no_path":
        return "no path"
    if outcome in ("error", "timeout"):
        return outcome
    if row.get("success"):
        return "success"
    if row.get("run_outcome") == "left_arena":
        return "left arena"
    if row.get("mode") == "physics":
        return "collision" if (row.get("collisions") or 0) > 0 else "timeout"
    return "collision"


def arm_counts(rows: list[dict[str, Any]]) -> dict[str, Any]:
    n = len(rows)
    outcomes: dict[str, int] = defaultdict(int)
    for r in rows:
        outcomes[r["outcome"]] += 1
    successes = sum(bool(r["success"]) for r in rows)
    return {"runs": n, "successes": successes, "success_rate": successes / n if n else float("nan"),
            "failed": n - outcomes.get("ok", 0), "outcomes": dict(outcomes),
            "classes": {c: sum(outcome_class(r) == c for r in rows) for c in OUTCOME_CLASSES}}


def ranksum_p(a: np.ndarray, b: np.ndarray) -> float:
    """Two-sided p of the Wilcoxon rank-sum test (``scipy.stats.ranksums``); NaN without values on a side, and
    1 when every value of both sides is the same (scipy's statistic is then 0 / 0: no difference at all)."""
    if a.size == 0 or b.size == 0:
        return float("nan")
    if np.all(a == a[0]) and np.all(b == a[0]):
        return 1.0
    return float(stats.ranksums(a, b).pvalue)


def cliffs_delta(a: np.ndarray, b: np.ndarray) -> float:
    """P(a > b) - P(a < b) over all pairs (Cliff 1993).

    The pairs are counted exactly without forming them: with ``b`` sorted, the values of ``b`` below ``a[i]``
    and above it are two binary searches, so two arms of 12,500 runs take milliseconds, not the 1.25 GB of
    the full difference matrix."""
    ordered = np.sort(b)
    below = np.searchsorted(ordered, a, side="left").sum(dtype=np.int64)
    above = (b.size - np.searchsorted(ordered, a, side="right")).sum(dtype=np.int64)
    return float((below - above) / (a.size * b.size))


def paired(ref_rows: list[dict[str, Any]], other_rows: list[dict[str, Any]], metric: str
           ) -> tuple[np.ndarray, np.ndarray]:
    """Values of the runs of two arms that share (seed, world seed), both with the metric."""
    def keyed(rows):
        return {(r["seed"], r["world_seed"]): r[metric] for r in rows
                if r.get("outcome") == "ok" and r.get(metric) is not None}
    a, b = keyed(ref_rows), keyed(other_rows)
    keys = sorted(set(a) & set(b), key=lambda k: (k[0], -1 if k[1] is None else k[1]))
    return np.array([a[k] for k in keys], dtype=float), np.array([b[k] for k in keys], dtype=float)


def rank_biserial_paired(a: np.ndarray, b: np.ndarray) -> float:
    """Matched-pairs rank-biserial correlation (W+ - W-) / (W+ + W-) over the non-zero differences."""
    d = a - b
    d = d[d != 0]
    if d.size == 0:
        return 0.0
    ranks = stats.rankdata(np.abs(d))
    return float((ranks[d > 0].sum() - ranks[d < 0].sum()) / ranks.sum())


def holm(p_values: list[float]) -> list[float]:
    """Holm's (1979) step-down adjusted p-values, in the input order (NaN stays NaN)."""
    finite = [(p, i) for i, p in enumerate(p_values) if not math.isnan(p)]
    finite.sort()
    m = len(finite)
    adjusted = [float("nan")] * len(p_values)
    running = 0.0
    for k, (p, i) in enumerate(finite):
        running = max(running, min(1.0, (m - k) * p))
        adjusted[i] = running
    return adjusted


@dataclass
class Comparison:
    other: str
    n_ref: int
    n_other: int
    ranksum_p: float
    cliffs_delta: float  # > 0: the reference's values tend to be larger
    n_pairs: int
    signed_rank_p: float
    rank_biserial: float
    ranksum_p_holm: float = float("nan")
    signed_rank_p_holm: float = float("nan")


def compare(arms: dict[str, list[dict[str, Any]]], reference: str, metric: str) -> list[Comparison]:
    """The reference arm against every other arm of one scenario, Holm-corrected within the family."""
    if reference not in arms:
        return []
    ref = values(arms[reference], metric)
    out = []
    for name, rows in arms.items():
        if name == reference:
            continue
        other = values(rows, metric)
        p = ranksum_p(ref, other)
        delta = cliffs_delta(ref, other) if ref.size and other.size else float("nan")
        a, b = paired(arms[reference], rows, metric)
        if a.size and np.any(a != b):
            p_signed = float(stats.wilcoxon(a, b).pvalue)
        else:  # no pairs, or every pair equal: the test is undefined
            p_signed = float("nan")
        out.append(Comparison(name, int(ref.size), int(other.size), p, delta, int(a.size), p_signed,
                              rank_biserial_paired(a, b) if a.size else float("nan")))
    for attribute in ("ranksum_p", "signed_rank_p"):
        for c, adjusted in zip(out, holm([getattr(c, attribute) for c in out])):
            setattr(c, f"{attribute}_holm", adjusted)
    return out


def friedman(arms: dict[str, list[dict[str, Any]]], metric: str) -> dict[str, Any] | None:
    """Friedman's test across all arms (at least 3) on the (seed, world seed) blocks every arm completed."""
    if len(arms) < 3:
        return None
    keyed = [{(r["seed"], r["world_seed"]): r[metric] for r in rows
              if r.get("outcome") == "ok" and r.get(metric) is not None} for rows in arms.values()]
    blocks = sorted(set.intersection(*(set(k) for k in keyed)), key=str)
    if len(blocks) < 2:
        return {"blocks": len(blocks), "statistic": float("nan"), "p": float("nan"), "kendall_w": float("nan")}
    samples = [np.array([k[b] for b in blocks], dtype=float) for k in keyed]
    try:
        with np.errstate(invalid="ignore", divide="ignore"):  # every block tied: scipy's 0 / 0 is NaN
            result = stats.friedmanchisquare(*samples)
        statistic, p = float(result.statistic), float(result.pvalue)
    except ValueError:
        statistic, p = float("nan"), float("nan")
    k = len(samples)
    return {"blocks": len(blocks), "statistic": statistic, "p": p,
            "kendall_w": statistic / (len(blocks) * (k - 1)) if math.isfinite(statistic) else float("nan")}


def impossible(metric: str, paper_value: float, scenario_rows: list[dict[str, Any]]) -> str | None:
    """Why a paper's value cannot be: below the straight line, no path at all, or below the exact optimum
    (when the study ran the ``optimal`` planner)."""
    if not metric.endswith("length_m"):
        return None
    straight = [r["straight_line_m"] for r in scenario_rows if r.get("straight_line_m") is not None]
    if straight and paper_value < min(straight) - 1e-9:
        return f"impossible: below the straight line ({min(straight):.4f} m)"
    optimal_rows = [r for r in scenario_rows if r["planner"] == "optimal"]
    if optimal_rows and all(r["outcome"] == "no_path" for r in optimal_rows):
        return "impossible: no collision-free path exists (the exact optimum finds none)"
    optimum = values(optimal_rows, "plan_length_m")
    if optimum.size and paper_value < optimum.min() - 1e-6:
        return f"impossible: below the exact optimum ({optimum.min():.4f} m)"
    return None


@dataclass
class SuccessComparison:
    other: str
    ref_successes: int
    ref_runs: int
    other_successes: int
    other_runs: int
    fisher_p: float
    fisher_p_holm: float = float("nan")


def compare_success(arms: dict[str, list[dict[str, Any]]], reference: str) -> list[SuccessComparison]:
    """Fisher's exact test (two-sided) of the 2 x 2 table successes/failures, reference against each arm."""
    if reference not in arms:
        return []
    def counts(rows):
        return sum(bool(r["success"]) for r in rows), len(rows)
    ref_s, ref_n = counts(arms[reference])
    out = []
    for name, rows in arms.items():
        if name == reference:
            continue
        s, n = counts(rows)
        p = float(stats.fisher_exact([[ref_s, ref_n - ref_s], [s, n - s]]).pvalue) if ref_n and n else float("nan")
        out.append(SuccessComparison(name, ref_s, ref_n, s, n, p))
    for c, adjusted in zip(out, holm([c.fisher_p for c in out])):
        c.fisher_p_holm = adjusted
    return out


# (header, metric, statistic) of the one-row-per-arm table; a column whose metric no run has is left out.
PAPER_COLUMNS = (("best length (m)", "plan_length_m", "best"), ("mean length (m)", "plan_length_m", "mean"),
                 ("std (m)", "plan_length_m", "std"), ("mean - best (m)", "plan_length_m", "spread"),
                 ("convergence iteration", "plan_convergence_iteration", "mean"),
                 ("bends", "plan_bends", "mean"), ("plan time (s)", "plan_time_s", "mean"),
                 ("gates", "plan_gates_raised", "mean"), ("tunnels", "plan_tunnels_closed", "mean"),
                 ("arc cost", "plan_arc_cost", "mean"), ("map arc cost", "plan_map_arc_cost", "mean"),
                 ("iterations", "plan_iterations", "mean"))


def paper_table(arms: dict[str, list[dict[str, Any]]]) -> tuple[list[str], list[list[float | int | None]]]:
    """Per arm: runs, successes, then each :data:`PAPER_COLUMNS` entry over the completed runs.
    ``mean - best`` is there because Gong et al. (2022) Table 3's "standard deviation" column equals
    the mean minus the optimal (our best) length in every one of its rows.  "Best length" is each planner's
    shortest plan over its runs (the paper's "optimal length"), not the ``optimal`` planner's."""
    all_rows = [r for rows in arms.values() for r in rows]
    columns = [c for c in PAPER_COLUMNS if any(r.get(c[1]) is not None for r in all_rows)]
    header = ["planner", "runs", "successes"] + [c[0] for c in columns]
    table = []
    for name, rows in arms.items():
        line: list = [name, len(rows), sum(bool(r["success"]) for r in rows)]
        for _, metric, statistic in columns:
            summary = summarise(rows, metric)
            if summary is None:
                line.append(None)
            elif statistic == "spread":  # rounding noise of identical runs (1e-15 m) is no spread
                spread = summary.mean - summary.best
                line.append(0.0 if abs(spread) <= 1e-12 * max(1.0, abs(summary.best)) else spread)
            else:
                line.append(getattr(summary, statistic))
        table.append(line)
    return header, table
