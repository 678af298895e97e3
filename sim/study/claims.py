"""Verdicts on a study's claims (``[[claims]]``, see :mod:`swarmnav.study.claim_spec`) from its rows.

Each claim compares its planner with every label of ``than`` on its scenario (and navigator, when given):

* ``rank_sum``: the Wilcoxon rank-sum test (``scipy.stats.ranksums``, two-sided) of the metric over the
  rows that completed (``outcome == "ok"``) and have it;
* ``signed_rank``: the Wilcoxon signed-rank test (``scipy.stats.wilcoxon``, two-sided) over the runs of the
  two sides that share (seed, world seed), both completed;
* ``fisher``: Fisher's exact test (``scipy.stats.fisher_exact``, two-sided) of successes and failures over
  every row (a run with no path, an error or a timeout is a failure);
* ``signed_rank_scenarios`` (an aggregate claim, a paper's average over many scenarios): each side's mean of
  the metric over its completed runs of each scenario the claim's glob matches, paired by scenario, and the
  Wilcoxon signed-rank test over those scenarios; its n is the number of scenarios both sides completed, the
  difference the mean over them of (claimed minus other), and ``relative`` that mean over the other side's
  mean over them (a paper's "+9.99 %").

Failed rows count: for ``success`` they are failures; for a numeric metric they are left out of its test, and
each pair states n per side (runs tested / runs).  The p-values of every pair of every claim of the study are
Holm-adjusted together (Holm 1979).  A claim **reproduces** when each of its pairs is significant (adjusted
p < 0.05) in the claimed direction, is **contradicted** when any pair is significant in the opposite
direction, is **underpowered** when a pair's runs could not reach significance whatever they gave (the
seed rule of :mod:`swarmnav.study.power`: too few runs, or none, for the study's Holm correction), and
is **inconclusive** otherwise (enough runs, no significant difference).  A side that is one plan repeated (a
deterministic planner) counts once: two such sides compare single values (no test; verdict by the sign of
the difference, **equal** when there is none), one such side is tested by the one-sample signed-rank test of the other side against it
(:mod:`swarmnav.study.power`).

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

from swarmnav.study import power
from swarmnav.study.claim_spec import AGGREGATE, SUCCESS, Claim, claim_scenarios
from swarmnav.study.statistics import holm, ranksum_p

ALPHA = 0.05
REPRODUCES, CONTRADICTED, INCONCLUSIVE, UNDERPOWERED = "reproduces", "contradicted", "inconclusive", "underpowered"
EQUAL = "equal"  # deterministic sides whose single values are the same


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
    rows = list(rows)
    scenarios = set(claim_scenarios(claim, sorted({r["scenario"] for r in rows})))
    return [r for r in rows if r["scenario"] in scenarios and r["label"] == label
            and (claim.navigator is None or (r.get("navigator_label") or "follow") == claim.navigator)]


def _scenario_means(a_rows: list[dict[str, Any]], b_rows: list[dict[str, Any]],
                    metric: str) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Each side's mean of ``metric`` over its completed runs of each scenario both sides completed."""
    def means(rows):
        by: dict[str, list[float]] = {}
        for r in rows:
            if r.get("outcome") == "ok" and r.get(metric) is not None:
                by.setdefault(r["scenario"], []).append(float(r[metric]))
        return {k: float(np.mean(v)) for k, v in by.items()}
    a, b = means(a_rows), means(b_rows)
    keys = sorted(set(a) & set(b))
    return np.array([a[k] for k in keys]), np.array([b[k] for k in keys]), keys


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


def single_valued(rows: list[dict[str, Any]]) -> bool:
    """Whether a side's runs are one plan repeated: its planner can ignore its seed (:data:`power.DETERMINISTIC`)
    and every completed run of it has the same plan length (per world seed) over two seeds or more.  (IMMAS
    with ``selection = "roulette"`` draws, its lengths differ, and its runs stay samples.)"""
    done = [r for r in rows if r.get("outcome") == "ok" and r.get("plan_length_m") is not None]
    if not done or not all(r.get("planner") in power.DETERMINISTIC for r in rows):
        return False
    by_world: dict[Any, set] = {}
    for r in done:
        by_world.setdefault(r.get("world_seed"), set()).add(r["plan_length_m"])
    return len({r["seed"] for r in done}) >= 2 and len(by_world) == 1 and all(len(v) == 1 for v in by_world.values())


def pair_result(claim: Claim, rows: list[dict[str, Any]], other: str) -> dict[str, Any]:
    """One (planner, other) pair of a claim: n per side, the raw p-value, A12, the direction (+1 the claimed
    one, -1 the opposite, 0 none), the difference (claimed minus other, the metric's units) with its 95 %
    interval, and the test actually run ("single_values" when both sides are one plan each, "one_sample"
    when one side is)."""
    mine, theirs = _side(rows, claim, claim.planner), _side(rows, claim, other)
    sign = 1.0 if claim.better == "higher" else -1.0  # orient so that larger is better
    raw_a, raw_b = _values(mine, claim.metric), _values(theirs, claim.metric)
    if claim.test == AGGREGATE:
        return _aggregate_pair(claim, mine, theirs, other, sign)
    single = [claim.metric != SUCCESS and single_valued(side) and values.size > 0
              for side, values in ((mine, raw_a), (theirs, raw_b))]
    if single[0]:
        raw_a = np.array([np.median(raw_a)])
    if single[1]:
        raw_b = np.array([np.median(raw_b)])
    a, b = sign * raw_a, sign * raw_b
    test = claim.test if not any(single) else "single_values" if all(single) else "one_sample"
    pair: dict[str, Any] = {"than": other, "n": [int(a.size), int(b.size)], "runs": [len(mine), len(theirs)],
                            "a12": a12(a, b), "test": test, "single_valued": single}
    p = float("nan")
    direction = 0 if math.isnan(pair["a12"]) else int(np.sign(pair["a12"] - 0.5))
    paired = False
    if test == "fisher":
        if mine and theirs:
            sa, sb = sum(bool(r.get("success")) for r in mine), sum(bool(r.get("success")) for r in theirs)
            p = float(stats.fisher_exact([[sa, len(mine) - sa], [sb, len(theirs) - sb]]).pvalue)
            pair["successes"] = [sa, sb]
    elif test == "single_values":
        direction = int(np.sign(a[0] - b[0]))
    elif test == "one_sample":
        constant, sample = (a[0], b) if single[0] else (b[0], a)
        d = sample - constant
        if np.any(d != 0):
            p = float(stats.wilcoxon(d).pvalue)
            nonzero = d[d != 0]
            ranks = stats.rankdata(np.abs(nonzero))
            towards_sample = int(np.sign(ranks[nonzero > 0].sum() - ranks[nonzero < 0].sum()))
            direction = towards_sample if single[1] else -towards_sample
        else:
            direction = 0
    elif test == "rank_sum":
        p = ranksum_p(a, b)
    else:  # signed_rank
        pa, pb = _paired(mine, theirs, claim.metric)
        raw_a, raw_b, paired = pa, pb, True
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
    pair["difference"], low, high = power.difference_interval(raw_a, raw_b, paired)
    pair["interval"] = [low, high]
    return pair


def _aggregate_pair(claim: Claim, mine: list[dict[str, Any]], theirs: list[dict[str, Any]], other: str,
                    sign: float) -> dict[str, Any]:
    """An aggregate claim's pair (``signed_rank_scenarios``): per-scenario means, paired by scenario."""
    raw_a, raw_b, scenarios = _scenario_means(mine, theirs, claim.metric)
    a, b = sign * raw_a, sign * raw_b
    d = a - b
    p, direction = float("nan"), 0
    if np.any(d != 0):
        p = float(stats.wilcoxon(a, b).pvalue)
        nonzero = d[d != 0]
        ranks = stats.rankdata(np.abs(nonzero))
        direction = int(np.sign(ranks[nonzero > 0].sum() - ranks[nonzero < 0].sum()))
    difference, low, high = power.difference_interval(raw_a, raw_b, True)
    base = float(np.mean(raw_b)) if raw_b.size else math.nan
    return {"than": other, "n": [int(a.size), int(b.size)], "runs": [len(mine), len(theirs)], "a12": a12(a, b),
            "test": AGGREGATE, "single_valued": [False, False], "pairs": int(a.size), "scenarios": scenarios,
            "p": p, "direction": direction, "difference": difference, "interval": [low, high],
            "relative": difference / base if base else math.nan}


def _tested_sizes(pair: dict[str, Any]) -> tuple[int, int]:
    if pair["test"] in ("signed_rank", AGGREGATE):
        return pair.get("pairs", 0), pair.get("pairs", 0)
    return pair["n"][0], pair["n"][1]


def verdicts(claims: Iterable[Claim], rows: list[dict[str, Any]], alpha: float = ALPHA) -> list[dict[str, Any]]:
    """Each claim with its pairs, their Holm-adjusted p-values (over all tested pairs of all claims), its
    verdict, its largest adjusted p, its weakest A12, and the seeds its test needs (:mod:`power`)."""
    claims = list(claims)
    out = [{**claim.as_dict(), "pairs": [pair_result(claim, rows, other) for other in claim.than]} for claim in claims]
    flat = [pair for claim in out for pair in claim["pairs"]]
    m = sum(1 for pair in flat if pair["test"] != "single_values")
    for pair, adjusted in zip(flat, holm([pair["p"] for pair in flat])):
        pair["p_holm"] = adjusted
    for claim in out:
        pairs = claim["pairs"]
        claim["seeds_needed"] = power.seeds_needed(claim["test"], m, alpha)
        claim["effect"] = (f"{claim['planner']} minus {' / '.join(claim['than'])}: {claim['metric']} "
                           f"{'below' if claim['better'] == 'lower' else 'above'} 0 (A12 > 0.5)")
        for pair in pairs:
            pair["reachable"] = pair["test"] == "single_values" or power.can_reach(
                pair["test"], *_tested_sizes(pair), m, alpha)
        significant = [p["test"] == "single_values" and p["direction"] != 0
                       or not math.isnan(p["p_holm"]) and p["p_holm"] < alpha for p in pairs]
        if any(s and p["direction"] < 0 for s, p in zip(significant, pairs)):
            claim["verdict"] = CONTRADICTED
        elif all(s and p["direction"] > 0 for s, p in zip(significant, pairs)):
            claim["verdict"] = REPRODUCES
        elif any(p["test"] == "single_values" and p["direction"] == 0 for p in pairs):
            claim["verdict"] = EQUAL  # one plan each, the same value: the claimed difference is not there
        elif not all(p["reachable"] for p in pairs):
            claim["verdict"] = UNDERPOWERED
        else:
            claim["verdict"] = INCONCLUSIVE
        claim["single_values"] = all(p["test"] == "single_values" for p in pairs)
        adjusted = [p["p_holm"] for p in pairs]
        claim["p_holm"] = float("nan") if any(math.isnan(p) for p in adjusted) else max(adjusted)
        effects = [p["a12"] for p in pairs]
        claim["a12"] = float("nan") if any(math.isnan(e) for e in effects) else min(effects)
        weakest = min(pairs, key=lambda p: (p["a12"] if not math.isnan(p["a12"]) else -1.0))
        claim["n"] = _tested_sizes(weakest)
        claim["difference"], claim["interval"] = weakest["difference"], weakest["interval"]
        if "relative" in weakest:
            claim["relative"] = weakest["relative"]
    return out


def seed_rule(document_claims: list[dict[str, Any]], seeds: int, alpha: float = ALPHA) -> dict[str, Any]:
    """The study's seed rule and whether its run met it."""
    needed = max((c["seeds_needed"] for c in document_claims), default=power.MIN_SEEDS)
    return {"rule": f"runs per side >= max({power.MIN_SEEDS}, smallest n at which the claim's test can give "
                    f"p < alpha / m, m = the study's Holm-corrected pairs)", "alpha": alpha,
            "pairs": sum(1 for c in document_claims for p in c["pairs"] if p["test"] != "single_values"),
            "seeds_needed": needed, "seeds_run": seeds, "met": seeds >= needed}


def claims_document(study: str, claims: Iterable[Claim], rows: list[dict[str, Any]],
                    inputs: dict[str, Any] | None = None) -> dict[str, Any]:
    """What ``claims.json`` holds: the study, its run count and seeds, the seed rule, what produced the rows
    (``inputs``: :func:`provenance.study_inputs` as recorded when the study ran) and each claim's verdict."""
    seeds = sorted({r["seed"] for r in rows})
    judged = verdicts(claims, rows)
    return {"study": study, "runs": len(rows), "seeds": len(seeds), "seed_list": seeds, "alpha": ALPHA,
            "correction": "holm", "effect_size": "vargha_delaney_a12 (oriented: > 0.5 favours the claim)",
            "difference": "claimed minus other, mean (paired: mean paired difference), 95 % bootstrap interval",
            "seed_rule": seed_rule(judged, len(seeds)), "inputs": inputs,
            "claims": [_json_safe(c) for c in judged]}


def _json_safe(value: Any) -> Any:
    """NaN becomes null (strict JSON)."""
    if isinstance(value, float) and math.isnan(value):
        return None
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_json_safe(v) for v in value]
    return value
