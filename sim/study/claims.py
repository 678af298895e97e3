"""Verdicts on a study's claims (``[[claims]]``, see :mod:`swarmnav.sim.study.claim_spec`) from its rows.

Each claim compares its planner with every label of ``than`` on its scenario (and navigator, when given):

* ``rank_sum``: the Wilcoxon rank-sum test (``scipy.stats.ranksums``, two-sided) of the metric over the
  rows that completed (``outcome == "ok"``) and have it;
* ``signed_rank``: the Wilcoxon signed-rank test (``scipy.stats.wilcoxon``, two-sided) over the runs of the
  two sides that share (seed, world seed), both completed;
* ``fisher``: Fisher's exact test (``scipy.stats.fisher_exact``, two-sided) of successes and failures over
  every row (a run with no path, an error or a timeout is a failure).

Failed rows count: for ``success`` they are failures; for a numeric metric they are left out of its test, and
each pair states n per side (runs tested / runs).  The p-values of every pair of every claim of the study are
Holm-adjusted together (Holm 1979).  A claim **reproduces** when each of its pairs is significant (adjusted
p < 0.05) in the claimed direction, is **contradicted** when any pair is significant in the opposite
direction, and is **inconclusive** otherwise (a pair that cannot be tested, e.g. with no rows or no
difference at all, is not significant).

The effect size is the Vargha–Delaney (2000) A12, oriented by the claim: the probability that a run of the
claimed planner is *better* (lower or higher, as the claim says) than a run of the other, ties counting half;
0.5 is no effect, above 0.5 favours the claim.  A claim reports its largest adjusted p and its weakest pair's
A12 (the smallest).  The direction of a pair is the side of 0.5 its A12 is on; for ``signed_rank``, the sign of
the signed-rank sum of the oriented paired differences.
"""

from __future__ import annotations

import math
from typing import Any, Iterable

import numpy as np
from scipy import stats

from swarmnav.sim.study.claim_spec import SUCCESS, Claim
from swarmnav.sim.study.statistics import holm, ranksum_p

ALPHA = 0.05
REPRODUCES, CONTRADICTED, INCONCLUSIVE = "reproduces", "contradicted", "inconclusive"


def a12(better: np.ndarray, worse: np.ndarray) -> float:
    """Vargha–Delaney A12: P(X > Y) + 0.5 P(X = Y) for X from ``better``, Y from ``worse`` (NaN if empty).

    Counted exactly by binary search over the sorted ``worse`` (no matrix of every pair: studies of
    thousands of runs per arm)."""
    if better.size == 0 or worse.size == 0:
        return float("nan")
    ordered = np.sort(worse)
    below = np.searchsorted(ordered, better, side="left").sum(dtype=np.int64)
    at_or_below = np.searchsorted(ordered, better, side="right").sum(dtype=np.int64)
    return float((below + 0.5 * (at_or_below - below)) / (better.size * worse.size))


def _side(rows: Iterable[dict[str, Any]], claim: Claim, label: str) -> list[dict[str, Any]]:
    return [r for r in rows if r["scenario"] == claim.scenario and r["label"] == label
            and (claim.navigator is None or (r.get("navigator_label") or "follow") == claim.navigator)]


def _values(rows: list[dict[str, Any]], metric: str) -> np.ndarray:
    if metric == SUCCESS:
        return np.array([1.0 if r.get("success") else 0.0 for r in rows])
    return np.array([r[metric] for r in rows if r.get("outcome") == "ok" and r.get(metric) is not None], dtype=float)


def _paired(a_rows: list[dict[str, Any]], b_rows: list[dict[str, Any]], metric: str) -> tuple[np.ndarray, np.ndarray]:
    def keyed(rows):
        return {(r["seed"], r["world_seed"]): r[metric] for r in rows
                if r.get("outcome") == "ok" and r.get(metric) is not None}
    a, b = keyed(a_rows), keyed(b_rows)
    keys = sorted(set(a) & set(b), key=lambda k: (k[0], -1 if k[1] is None else k[1]))
    return np.array([a[k] for k in keys], dtype=float), np.array([b[k] for k in keys], dtype=float)


def pair_result(claim: Claim, rows: list[dict[str, Any]], other: str) -> dict[str, Any]:
    """One (planner, other) pair of a claim: n per side, the raw p-value, A12 and the direction
    (+1 the claimed one, -1 the opposite, 0 none)."""
    mine, theirs = _side(rows, claim, claim.planner), _side(rows, claim, other)
    sign = 1.0 if claim.better == "higher" else -1.0  # orient so that larger is better
    a, b = sign * _values(mine, claim.metric), sign * _values(theirs, claim.metric)
    pair: dict[str, Any] = {"than": other, "n": [int(a.size), int(b.size)], "runs": [len(mine), len(theirs)],
                            "a12": a12(a, b)}
    p = float("nan")
    direction = 0 if math.isnan(pair["a12"]) else int(np.sign(pair["a12"] - 0.5))
    if claim.test == "fisher":
        if mine and theirs:
            sa, sb = sum(bool(r.get("success")) for r in mine), sum(bool(r.get("success")) for r in theirs)
            p = float(stats.fisher_exact([[sa, len(mine) - sa], [sb, len(theirs) - sb]]).pvalue)
            pair["successes"] = [sa, sb]
    elif claim.test == "rank_sum":
        p = ranksum_p(a, b)
    else:  # signed_rank
        pa, pb = _paired(mine, theirs, claim.metric)
        pa, pb = sign * pa, sign * pb
        pair["pairs"] = int(pa.size)
        d = pa - pb
        if np.any(d != 0):
            p = float(stats.wilcoxon(pa, pb).pvalue)
            nonzero = d[d != 0]
            ranks = stats.rankdata(np.abs(nonzero))
            direction = int(np.sign(ranks[nonzero > 0].sum() - ranks[nonzero < 0].sum()))
        else:
            direction = 0
    pair["p"] = p
    pair["direction"] = direction
    return pair


def verdicts(claims: Iterable[Claim], rows: list[dict[str, Any]], alpha: float = ALPHA) -> list[dict[str, Any]]:
    """Each claim with its pairs, their Holm-adjusted p-values (over all pairs of all claims), its verdict,
    its largest adjusted p and its weakest A12."""
    out = [{**claim.as_dict(), "pairs": [pair_result(claim, rows, other) for other in claim.than]} for claim in claims]
    flat = [pair for claim in out for pair in claim["pairs"]]
    for pair, adjusted in zip(flat, holm([pair["p"] for pair in flat])):
        pair["p_holm"] = adjusted
    for claim in out:
        pairs = claim["pairs"]
        significant = [not math.isnan(p["p_holm"]) and p["p_holm"] < alpha for p in pairs]
        if any(s and p["direction"] < 0 for s, p in zip(significant, pairs)):
            claim["verdict"] = CONTRADICTED
        elif all(s and p["direction"] > 0 for s, p in zip(significant, pairs)):
            claim["verdict"] = REPRODUCES
        else:
            claim["verdict"] = INCONCLUSIVE
        adjusted = [p["p_holm"] for p in pairs]
        claim["p_holm"] = float("nan") if any(math.isnan(p) for p in adjusted) else max(adjusted)
        effects = [p["a12"] for p in pairs]
        claim["a12"] = float("nan") if any(math.isnan(e) for e in effects) else min(effects)
    return out


def claims_document(study: str, claims: Iterable[Claim], rows: list[dict[str, Any]]) -> dict[str, Any]:
    """What ``claims.json`` holds: the study, its run count and seeds, and each claim's verdict."""
    seeds = sorted({r["seed"] for r in rows})
    return {"study": study, "runs": len(rows), "seeds": len(seeds), "alpha": ALPHA, "correction": "holm",
            "effect_size": "vargha_delaney_a12 (oriented: > 0.5 favours the claim)",
            "claims": [_json_safe(c) for c in verdicts(claims, rows)]}


def _json_safe(value: Any) -> Any:
    """NaN becomes null (strict JSON)."""
    if isinstance(value, float) and math.isnan(value):
        return None
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_json_safe(v) for v in value]
    return value
