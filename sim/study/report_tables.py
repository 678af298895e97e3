"""The report's tables of one scenario (and of the claims), as :class:`~swarmnav.study.tables.Table`:
wide tables, one row per arm (planner, with its navigator when not plain follow), metrics as columns with
their units."""

from __future__ import annotations

import json
from typing import Any

from swarmnav.study.statistics import (OUTCOME_CLASSES, arm_counts, compare, compare_success, friedman,
                                           impossible, summarise, values)
from swarmnav.study.tables import Pair, Table

# (column, header with unit) of the wide summary tables, in this order where the runs have them.
METRICS = (("plan_length_m", "plan length (m)"), ("plan_time_s", "plan time (s)"),
           ("plan_evaluations", "evaluations"), ("plan_iterations", "iterations"),
           ("plan_convergence_iteration", "convergence iteration"), ("plan_bends", "bends"),
           ("plan_raw_length_m", "raw length (m)"), ("plan_gates_raised", "gates"),
           ("plan_tunnels_closed", "tunnels"), ("plan_arc_cost", "arc cost"), ("plan_map_arc_cost", "map arc cost"),
           ("path_length_m", "driven length (m)"), ("sim_time_s", "simulated time (s)"),
           ("min_clearance_m", "min clearance (m)"), ("collisions", "collisions"))
UNITS = dict(METRICS)
# The metrics tested between planners, each where the runs have it (Gong et al. (2022) Table 4 tests path lengths).
TEST_METRICS = ["plan_length_m", "plan_time_s", "path_length_m", "sim_time_s", "min_clearance_m"]
# What must be equal, run by run, for two arms to be one configuration (timings excluded).
SAME = ("outcome", "plan_waypoints", "plan_length_m", "plan_evaluations", "reached", "collisions", "sim_time_s",
        "path_length_m", "min_clearance_m", "run_outcome")


def merge_identical(arms: dict[str, list[dict[str, Any]]]) -> tuple[dict[str, list[dict[str, Any]]], list[str]]:
    """Arms of one planner label whose rows are equal run by run (same seeds, same plan and drive, e.g. a
    static scenario driven by follow and by replan) shown once, under the first arm's name; and a sentence per
    merge saying so."""
    def signature(rows):
        return sorted(json.dumps([r["seed"], r["world_seed"]] + [r.get(k) for k in SAME], default=str)
                      for r in rows)
    out: dict[str, list[dict[str, Any]]] = {}
    kept: dict[str, tuple[str, list]] = {}
    notes: dict[str, list[str]] = {}
    for name, rows in arms.items():
        label = rows[0]["label"]
        if not any(r.get("outcome") == "ok" for r in rows):  # rows that all failed show no plan and no drive
            out[name] = rows
            continue
        sig = signature(rows)
        match = next((first for first, (lab, s) in kept.items() if lab == label and s == sig), None)
        if match is None:
            kept[name] = (label, sig)
            out[name] = rows
        else:
            notes.setdefault(match, []).append(name)
    if not notes:
        return out, []
    pairs = "; ".join(f"{', '.join(others)} as {first}" for first, others in notes.items())
    return out, [f"Identical configurations, shown once: {pairs}. Each gave the same plan and the same drive as "
                 "the arm it is shown as, on every seed (e.g. a static scenario, where replanning never changes the "
                 "plan); the claims and their tests use every row."]


def count_table(scenario: str, arms: dict[str, list[dict[str, Any]]]) -> Table:
    """Runs, successes and the failures split by outcome, per arm."""
    rows = []
    for name, arm_rows in arms.items():
        c = arm_counts(arm_rows)
        rows.append([name, c["runs"]] + [c["classes"][k] for k in OUTCOME_CLASSES]
                    + [100.0 * c["classes"]["success"] / c["runs"]])
    return Table(f"{scenario}-outcomes", f"{scenario}: outcomes per planner (success: reached with no collision)",
                 ["planner", "runs"] + list(OUTCOME_CLASSES) + ["success (%)"], rows)


def summary_tables(scenario: str, arms: dict[str, list[dict[str, Any]]]) -> list[Table]:
    """Mean ± std (sample) and median of each metric per arm, over the completed runs that have it."""
    all_rows = [r for rows in arms.values() for r in rows]
    metrics = [(m, h) for m, h in METRICS if any(r.get(m) is not None for r in all_rows)]
    if not metrics:
        return []
    mean_rows, median_rows = [], []
    for name, rows in arms.items():
        summaries = [summarise(rows, m) for m, _ in metrics]
        n = max((s.n for s in summaries if s is not None), default=0)
        mean_rows.append([name, n] + [None if s is None else Pair(s.mean, s.std) for s in summaries])
        median_rows.append([name, n] + [None if s is None else s.median for s in summaries])
    header = ["planner", "n"] + [h for _, h in metrics]
    return [Table(f"{scenario}-mean", f"{scenario}: mean ± std over the completed runs", header, mean_rows),
            Table(f"{scenario}-median", f"{scenario}: median over the completed runs", header, median_rows)]


def statistics_section(scenario: str, arms: dict[str, list[dict[str, Any]]], reference: str | None) -> list:
    """Paragraphs and tables of the tests against the reference planner."""
    if len(arms) < 2:
        return []
    reference = reference if reference in arms else next((a for a in arms if a.split("(")[0] == reference),
                                                        next(iter(arms)))
    scenario_rows = [r for rows in arms.values() for r in rows]
    out: list = [f"{reference} against each planner, per metric. Wilcoxon rank-sum (scipy.stats.ranksums, as "
                 "Gong et al. 2022 Table 4) with Cliff's delta (> 0: the reference's values are larger); Wilcoxon "
                 "signed-rank on runs paired by seed and world seed, with the matched-pairs rank-biserial "
                 "correlation; Holm-adjusted over the planners, per metric."]
    rows = []
    for metric in [m for m in TEST_METRICS if any(r.get(m) is not None for r in scenario_rows)]:
        rows += [[c.other, UNITS.get(metric, metric), c.n_ref, c.n_other, c.ranksum_p, c.ranksum_p_holm,
                  c.cliffs_delta, c.n_pairs, c.signed_rank_p, c.signed_rank_p_holm, c.rank_biserial]
                 for c in compare(arms, reference, metric)]
    out.append(Table(f"{scenario}-tests", f"{scenario}: {reference} against each planner",
                     ["against", "metric", "n ref", "n other", "rank-sum p", "Holm p", "Cliff's delta", "pairs",
                      "signed-rank p", "Holm p", "rank-biserial"], rows, kinds={4: "p", 5: "p", 8: "p", 9: "p"}))
    success = compare_success(arms, reference)
    out.append("Success rates: Fisher's exact test (two-sided, scipy.stats.fisher_exact) of successes and "
               f"failures, {reference} against each planner, Holm-adjusted.")
    out.append(Table(f"{scenario}-success-tests", f"{scenario}: success rates, {reference} against each planner",
                     ["against", "ref successes", "other successes", "Fisher p", "Holm p"],
                     [[c.other, f"{c.ref_successes}/{c.ref_runs}", f"{c.other_successes}/{c.other_runs}",
                       c.fisher_p, c.fisher_p_holm] for c in success], kinds={3: "p", 4: "p"}))
    if any(r.get("plan_length_m") is not None for r in scenario_rows):
        result = friedman(arms, "plan_length_m")
        if result is not None and result["blocks"] >= 2:
            from swarmnav.study.tables import number, p_value
            out.append(f"Friedman test of the plan length across all {len(arms)} planners on {result['blocks']} "
                       f"seeds every planner completed: chi² = {number(result['statistic'])}, "
                       f"p = {p_value(result['p'])}, Kendall's W = {number(result['kendall_w'], 3)}.")
    return out


def paper_values_table(scenario: str, arms, scenario_rows, paper: list[dict[str, Any]]) -> Table | None:
    entries = [p for p in paper if p["scenario"] == scenario]
    if not entries:
        return None
    rows = []
    for p in entries:
        mine = [r for name, rs in arms.items() if name == p["planner"] or name.startswith(p["planner"] + "(")
                for r in rs]
        v = values(mine, p["metric"])
        ours = Pair(float(v.mean()), float(v.std(ddof=1)) if v.size > 1 else None) if v.size else None
        rows.append([p["planner"], UNITS.get(p["metric"], p["metric"]), p["value"], ours, v.size,
                     p.get("note", ""), impossible(p["metric"], p["value"], scenario_rows) or ""])
    return Table(f"{scenario}-paper-values", f"{scenario}: the paper's values beside ours",
                 ["planner", "metric", "paper", "ours", "our runs", "source", "check"], rows)


def claims_table(document: dict[str, Any]) -> Table:
    rows = []
    for c in document["claims"]:
        n = "; ".join(f"{c['planner']} {p['n'][0]}/{p['runs'][0]} vs {p['than']} {p['n'][1]}/{p['runs'][1]}"
                      + (f" ({p['test'].replace('_', ' ')})" if p.get("test", c["test"]) != c["test"] else "")
                      for p in c["pairs"])
        interval = c.get("interval") or [None, None]
        rows.append([c["id"], c["statement"], c["source"], c["scenario"], c["test"], c["verdict"], c["p_holm"],
                     c["a12"], c.get("difference"), interval[0], interval[1], n, c.get("seeds_needed")])
    return Table("claims", f"The claims of study {document['study']} and their verdicts",
                 ["claim", "statement", "source", "scenario", "test", "verdict", "Holm p", "A12", "difference",
                  "95% low", "95% high", "n", "seeds needed"], rows, kinds={6: "p"})
