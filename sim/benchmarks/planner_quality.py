"""The quality tables of ``swarmnav bench planners``, run as studies.

Two studies, built in code and run by the study machinery (:mod:`swarmnav.study`:
the same cells, the one episode function, the same Parquet rows as ``swarmnav study``):

* ``bench-planners`` on the bundled scenarios: every planner in every mode (labels
  ``gwo-paper``, ``gwo-robust``, ...), OMPL's sampling planners (labels ``rrt_star``, ...,
  mode ``ompl``: :mod:`planners.sampling_ompl`, given as many collision checks as a swarm's
  population x iterations evaluations) and ``optimal`` (the exact shortest path, the
  yardstick), plan only, with the papers' clearance (``--clearance-m``, default 0: the
  robot radius only) and the moving obstacles frozen at t = 0 (as every plan is);
* ``bench-planners-fields`` on random disc fields of 10-40 discs written as scenario
  files (:mod:`swarmnav.models.disc_fields`; field ``f`` has ``10 + 30 f / (fields - 1)``
  discs, drawn with seed ``f``), with the fields' own 0.05 m clearance.

Both folders (``OUT/scenarios``, ``OUT/fields``) are ordinary study folders:
``swarmnav report OUT/scenarios`` draws their box plots, statistics and convergence
curves.  The tables below are computed from the rows alone.  A run that found no
path is a row (outcome ``no_path``) and counts in ``runs``, never in the lengths.
"""

from __future__ import annotations

import json
import math
import statistics
from pathlib import Path as FilePath
from typing import Any

OPTIMUM_LABEL = "optimal"
SAMPLING_MODE = "ompl"  # the mode column of OMPL's planners (they have no paper/robust modes)
WITHIN_RATIO = 1.03  # issue 14: robust median length <= 1.03 x the exact optimum


def mode_label(planner: str, mode: str) -> str:
    return f"{planner}-{mode}"


def study_tables(name: str, scenarios: list[str], planners: list[str], modes: list[str], seeds: int,
                 population: int, iterations: int, clearance_m: float | None = None,
                 paper_lengths_m: dict[tuple[str, str], float] | None = None,
                 sampling: list[str] = ()) -> dict[str, Any]:
    """The tables of a plan-only study of ``planners`` x ``modes``, the ``sampling`` (OMPL) planners with a
    budget of ``population * iterations`` collision checks, and the exact optimum."""
    entries = [{"name": p, "label": mode_label(p, m),
                "params": {"population": population, "iterations": iterations, "mode": m}}
               for p in planners for m in modes]
    entries += [{"name": p, "label": p, "params": {"max_evaluations": population * iterations}} for p in sampling]
    entries.append({"name": "optimal", "label": OPTIMUM_LABEL})
    tables: dict[str, Any] = {"name": name, "scenarios": scenarios, "mode": "plan", "seeds": seeds,
                              "planners": entries, "reference": entries[0]["label"]}
    if clearance_m is not None:
        tables["clearance_m"] = clearance_m
    stems = {FilePath(s).stem for s in scenarios}
    tables["paper"] = [{"scenario": scenario, "planner": mode_label(planner, "paper"), "metric": "plan_length_m",
                        "value": value, "note": "the paper's best path"}
                       for (scenario, planner), value in (paper_lengths_m or {}).items()
                       if scenario in stems and planner in planners and "paper" in modes]
    return tables


def run_time_s(row: dict[str, Any]) -> float:
    """A run's plan time, or its whole cell time when it has none (it found no path or raised)."""
    return row["plan_time_s"] if row["plan_time_s"] is not None else row["cell_wall_s"]


def arms(rows: list[dict[str, Any]]) -> dict[tuple[str, str], list[dict[str, Any]]]:
    """(scenario, planner label) -> its rows."""
    out: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for row in rows:
        out.setdefault((row["scenario"], row["label"]), []).append(row)
    return out


def optimum_by_scenario(rows: list[dict[str, Any]]) -> dict[str, float | None]:
    """The exact optimum of each scenario from its ``optimal`` rows (their ``optimum_length_m``: the exact
    length, a hair below that of the polygon ``optimal`` returns); None where no path exists."""
    out: dict[str, float | None] = {}
    for (scenario, label), arm in arms(rows).items():
        if label == OPTIMUM_LABEL:
            lengths = {json.loads(r["plan_extra"])["optimum_length_m"] for r in arm if r["success"]}
            if len(lengths) > 1:
                raise AssertionError(f"the exact optimum of {scenario} differs between seeds: {sorted(lengths)}")
            out[scenario] = lengths.pop() if lengths else None
    return out


def arm_figures(arm: list[dict[str, Any]]) -> dict[str, Any]:
    """Runs, feasible runs and the statistics of the feasible lengths of one planner on one scenario.

    The plan time of a run that found no path is its whole cell time (it has no plan time of its own)."""
    lengths = [r["plan_length_m"] for r in arm if r["success"]]
    times = [run_time_s(r) for r in arm]
    evaluations = [r["plan_evaluations"] for r in arm if r["plan_evaluations"] is not None]
    return {"runs": len(arm), "feasible_runs": len(lengths),
            "failed_runs": sum(r["outcome"] != "ok" for r in arm),
            "best_length_m": min(lengths) if lengths else None,
            "median_length_m": statistics.median(lengths) if lengths else None,
            "std_length_m": statistics.pstdev(lengths) if lengths else None,
            "mean_plan_time_s": statistics.fmean(times) if times else None,
            "median_plan_time_s": statistics.median(times) if times else None,
            "evaluations": round(statistics.fmean(evaluations)) if evaluations else None}


def _arm_keys(planners: list[str], modes: list[str], sampling: list[str]) -> list[tuple[str, str, str]]:
    """(planner, mode, label) of each arm, in the order asked: the swarms in their modes, then OMPL's."""
    return [(p, m, mode_label(p, m)) for p in planners for m in modes] + [(p, SAMPLING_MODE, p) for p in sampling]


def scenario_rows(rows: list[dict[str, Any]], planners: list[str], modes: list[str],
                  sampling: list[str] = ()) -> list[dict[str, Any]]:
    """One table row per scenario, planner and mode, in the order asked."""
    by_arm, optimum = arms(rows), optimum_by_scenario(rows)
    out = []
    for scenario in dict.fromkeys(r["scenario"] for r in rows):
        for planner, mode, label in _arm_keys(planners, modes, sampling):
            arm = by_arm.get((scenario, label), [])
            figures = arm_figures(arm)
            best = optimum.get(scenario)
            median = figures["median_length_m"]
            out.append({"scenario": scenario, "planner": planner, "mode": mode, **figures,
                        "optimum_length_m": best,
                        "ratio_to_optimum": median / best if (median is not None and best) else None,
                        "straight_line_m": arm[0]["straight_line_m"] if arm else None})
    return out


def field_summary(rows: list[dict[str, Any]], planners: list[str], modes: list[str],
                  sampling: list[str] = ()) -> list[dict[str, Any]]:
    """Per planner and mode over the random fields: feasible runs, the median and worst of the per-field
    median length over the exact optimum, fields within :data:`WITHIN_RATIO`, the median plan time.  A field
    without any path (the exact planner proves it) is counted in ``fields_without_path`` and has no ratio."""
    by_arm, optimum = arms(rows), optimum_by_scenario(rows)
    with_path = [s for s, best in optimum.items() if best is not None]
    out = []
    for planner, mode, label in _arm_keys(planners, modes, sampling):
        ratios, times, feasible, runs = [], [], 0, 0
        for scenario in with_path:
            figures = arm_figures(by_arm.get((scenario, label), []))
            runs += figures["runs"]
            feasible += figures["feasible_runs"]
            times += [run_time_s(r) for r in by_arm.get((scenario, label), [])]
            median = figures["median_length_m"]
            ratios.append(median / optimum[scenario] if median is not None else math.inf)
        out.append({"planner": planner, "mode": mode, "fields": len(with_path),
                    "fields_without_path": len(optimum) - len(with_path), "runs": runs,
                    "feasible_runs": feasible,
                    "median_ratio": statistics.median(ratios) if ratios else None,
                    "worst_median_ratio": max(ratios) if ratios else None,
                    "fields_within_1_03": sum(r <= WITHIN_RATIO for r in ratios),
                    "median_plan_time_s": statistics.median(times) if times else None})
    return out
