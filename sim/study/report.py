"""``swarmnav report DIR``: a self-contained HTML report of a study's rows, and its Markdown twin.

It reads only ``DIR/runs.parquet``, ``DIR/progress.parquet`` and ``DIR/study.json``
(the reference planner, the paper's values, and each scenario's arena and obstacles
at t = 0 as recorded when the study ran), so a copied results folder reports alike.  The HTML embeds its
images (base64 PNG); the Markdown links the same PNGs, written to
``<report>_files/`` beside it.
"""

from __future__ import annotations

import base64
import html
import json
import math
import re
from pathlib import Path as FilePath
from typing import Any

from swarmnav.sim.study import figures
from swarmnav.sim.study.rows import load_progress, load_runs
from swarmnav.sim.study.statistics import (arm_counts, by_scenario, compare, compare_success, friedman, impossible,
                                           paper_table, summarise, values)

PLAN_METRICS = ["plan_length_m", "plan_time_s", "plan_iterations", "plan_convergence_iteration", "plan_bends",
                "plan_evaluations", "plan_raw_length_m", "plan_gates_raised", "plan_tunnels_closed", "plan_arc_cost"]
RUN_METRICS = ["path_length_m", "sim_time_s", "min_clearance_m", "collisions"]
# The metrics tested between planners, each where the runs have it (seed 003 Table 4 tests path lengths).
TEST_METRICS = ["plan_length_m", "plan_time_s", "path_length_m", "sim_time_s", "min_clearance_m"]


def _fmt(x: Any, digits: int = 4) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    if isinstance(x, float):
        return f"{x:.{digits}g}" if abs(x) < 1e-3 and x != 0 else f"{x:.{digits}f}".rstrip("0").rstrip(".")
    return str(x)


class _Document:
    """Builds the HTML and the Markdown side by side."""

    def __init__(self, title: str, files_dir: FilePath):
        self.html = [f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
                     "<style>body{font-family:sans-serif;max-width:1200px;margin:auto}"
                     "table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #bbb;padding:3px 6px;"
                     "font-size:13px;text-align:right}th{background:#eee}td:first-child{text-align:left}"
                     ".flag{color:#b00}</style></head><body>", f"<h1>{html.escape(title)}</h1>"]
        self.markdown = [f"# {title}", ""]
        self.files_dir = files_dir
        self.images = 0

    def heading(self, text: str, level: int = 2) -> None:
        self.html.append(f"<h{level}>{html.escape(text)}</h{level}>")
        self.markdown += ["#" * level + " " + text, ""]

    def paragraph(self, text: str) -> None:
        self.html.append(f"<p>{html.escape(text)}</p>")
        self.markdown += [text, ""]

    def table(self, header: list[str], rows: list[list[str]]) -> None:
        self.html.append("<table><tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in header) + "</tr>"
                         + "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in rows)
                         + "</table>")
        self.markdown += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        self.markdown += ["| " + " | ".join(c.replace("|", "\\|") for c in r) + " |" for r in rows]
        self.markdown.append("")

    def image(self, png: bytes | None, caption: str) -> None:
        if png is None:
            return
        self.images += 1
        name = f"figure-{self.images:03d}.png"
        self.files_dir.mkdir(parents=True, exist_ok=True)
        (self.files_dir / name).write_bytes(png)
        self.html.append(f"<figure><img src='data:image/png;base64,{base64.b64encode(png).decode()}'>"
                         f"<figcaption>{html.escape(caption)}</figcaption></figure>")
        self.markdown += [f"![{caption}]({self.files_dir.name}/{name})", ""]


def count_rows(arms: dict[str, list[dict[str, Any]]]) -> tuple[list[str], list[list[str]]]:
    """Runs, failures by outcome and success rate per arm."""
    header = ["planner", "runs", "failed", "outcomes", "success %"]
    rows = []
    for name, arm_rows in arms.items():
        c = arm_counts(arm_rows)
        rows.append([name, str(c["runs"]), str(c["failed"]),
                     ", ".join(f"{k} {v}" for k, v in sorted(c["outcomes"].items())),
                     _fmt(100 * c["success_rate"], 1)])
    return header, rows


def metric_rows(arms: dict[str, list[dict[str, Any]]], metrics: list[str]) -> tuple[list[str], list[list[str]]]:
    """Mean, sample std, median and best of each metric per arm, over the runs that produced it."""
    header = ["planner", "metric", "n", "mean", "std", "median", "best"]
    rows = []
    for metric in metrics:
        for name, arm_rows in arms.items():
            s = summarise(arm_rows, metric)
            if s is not None:
                rows.append([name, metric, str(s.n), _fmt(s.mean), _fmt(s.std), _fmt(s.median), _fmt(s.best)])
    return header, rows


def _present(rows: list[dict[str, Any]], metrics: list[str]) -> list[str]:
    return [m for m in metrics if any(r.get(m) is not None for r in rows)]


def _natural(text: str) -> tuple:
    """A sort key that orders the numbers inside a label by value ("iterations=9" before "iterations=10")."""
    return tuple((0, float(part), "") if part.replace(".", "", 1).isdigit() else (1, 0.0, part)
                 for part in re.split(r"(\d+(?:\.\d+)?)", text) if part)


def ordered_runs(runs: list[dict[str, Any]], meta: dict[str, Any]) -> list[dict[str, Any]]:
    """The rows in the study's own order (scenario, planner, its sweep, navigator, world seed, seed), not the
    order in which they finished, so the same rows always give the same report.  Scenarios, planners and
    navigators the metadata does not list come after the listed ones, by name."""
    def rank(names: list[str], name: str) -> tuple:
        return (names.index(name), "") if name in names else (len(names), name)

    scenarios, planners = list(meta.get("scenarios", {})), meta.get("planners", [])
    navigators = meta.get("navigators", [])

    def key(row: dict[str, Any]) -> tuple:
        label = row["label"]
        base = label.split("(", 1)[0]
        return (rank(scenarios, row["scenario"]), rank(planners, label if label in planners else base),
                _natural(label), rank(navigators, (row.get("navigator_label") or "follow").split("(", 1)[0]),
                _natural(row.get("navigator_label") or ""), -1 if row["world_seed"] is None else row["world_seed"],
                row["seed"])
    return sorted(runs, key=key)


def write_report(directory: str | FilePath, html_path: str | FilePath) -> FilePath:
    """Write the HTML report and its Markdown twin (``.md`` beside it); return the Markdown path."""
    directory, html_path = FilePath(directory), FilePath(html_path)
    runs = load_runs(directory)  # only the columns a report reads; each cell once
    progress = load_progress(directory)
    meta_path = directory / "study.json"
    meta = json.loads(meta_path.read_text(encoding="utf-8")) if meta_path.exists() else {}
    runs = ordered_runs(runs, meta)
    title = f"Study {meta.get('name', directory.name)}"
    markdown_path = html_path.with_suffix(".md")
    doc = _Document(title, html_path.parent / f"{html_path.stem}_files")
    if meta.get("description"):
        doc.paragraph(meta["description"])
    failed = sum(r["outcome"] != "ok" for r in runs)
    doc.paragraph(f"{len(runs)} runs, {failed} failed (no path, error or wall-limit timeout; counted, never "
                  f"dropped). Mode: {meta.get('mode', '?')}. Statistics compare each planner against the "
                  f"reference planner {meta.get('reference', '?')!r}.")
    for scenario, arms in by_scenario(runs).items():
        scenario_rows = [r for rows in arms.values() for r in rows]
        doc.heading(f"Scenario {scenario}")
        metrics = _present(scenario_rows, PLAN_METRICS + RUN_METRICS)
        doc.table(*count_rows(arms))
        header, table = paper_table(arms)
        doc.paragraph("One row per planner in the shape of Gong et al. (2022) Table 3, over the completed runs "
                      "(std: sample; their 'standard deviation' column equals mean - optimal in every row, "
                      "so that is given too). Bends: heading changes between consecutive waypoints, as the paper "
                      "counts them on grid paths; a continuous planner's path is its spline sampled densely, so "
                      "there every sample counts and the figure says little.")
        doc.table(header, [[_fmt(v) for v in line] for line in table])
        doc.table(*metric_rows(arms, metrics))
        errors = sorted({r["error"] for r in scenario_rows if r.get("error")})
        if errors:
            doc.paragraph("Failures: " + "; ".join(errors[:5]) + (" …" if len(errors) > 5 else ""))
        _statistics(doc, arms, meta.get("reference"))
        _paper_values(doc, scenario, arms, scenario_rows, meta.get("paper", []))
        doc.image(figures.box_plots(arms, _present(scenario_rows, ["plan_length_m", "plan_time_s", "path_length_m",
                                                                   "sim_time_s", "min_clearance_m"])),
                  f"{scenario}: distributions over runs")
        doc.image(figures.success_bars(arms), f"{scenario}: success rate")
        doc.image(figures.convergence(arms, progress), f"{scenario}: median best cost with interquartile band")
        doc.image(figures.paths(arms, meta.get("scenarios", {}).get(scenario)),
                  f"{scenario}: the plan of one seed per planner")
    doc.html.append("</body></html>")
    html_path.parent.mkdir(parents=True, exist_ok=True)
    html_path.write_text("\n".join(doc.html), encoding="utf-8")
    markdown_path.write_text("\n".join(doc.markdown) + "\n", encoding="utf-8")
    return markdown_path


def _statistics(doc: _Document, arms: dict[str, list[dict[str, Any]]], reference: str | None) -> None:
    if len(arms) < 2:
        return
    reference = reference if reference in arms else next((a for a in arms if a.split("(")[0] == reference),
                                                        next(iter(arms)))
    scenario_rows = [r for rows in arms.values() for r in rows]
    doc.paragraph(f"{reference} against each planner, per metric. Wilcoxon rank-sum (scipy.stats.ranksums, as "
                  "Gong et al. 2022 Table 4) with Cliff's delta (> 0: the reference's values are larger); Wilcoxon "
                  "signed-rank on runs paired by seed and world seed, with the matched-pairs rank-biserial "
                  "correlation; Holm-adjusted over the planners, per metric.")
    rows = []
    for metric in _present(scenario_rows, TEST_METRICS):
        rows += [[c.other, metric, str(c.n_ref), str(c.n_other), _fmt(c.ranksum_p), _fmt(c.ranksum_p_holm),
                  _fmt(c.cliffs_delta, 3), str(c.n_pairs), _fmt(c.signed_rank_p), _fmt(c.signed_rank_p_holm),
                  _fmt(c.rank_biserial, 3)] for c in compare(arms, reference, metric)]
    doc.table(["against", "metric", "n ref", "n other", "rank-sum p", "Holm p", "Cliff's delta", "pairs",
               "signed-rank p", "Holm p", "rank-biserial"], rows)
    success = compare_success(arms, reference)
    doc.paragraph("Success rates: Fisher's exact test (two-sided, scipy.stats.fisher_exact) of successes and "
                  f"failures, {reference} against each planner, Holm-adjusted.")
    doc.table(["against", "ref successes", "other successes", "Fisher p", "Holm p"],
              [[c.other, f"{c.ref_successes}/{c.ref_runs}", f"{c.other_successes}/{c.other_runs}",
                _fmt(c.fisher_p), _fmt(c.fisher_p_holm)] for c in success])
    for metric in _present(scenario_rows, TEST_METRICS[:1]):
        result = friedman(arms, metric)
        if result is not None:
            doc.paragraph(f"Friedman test of {metric} across all {len(arms)} planners on {result['blocks']} seeds "
                          f"every planner completed: chi² = {_fmt(result['statistic'])}, p = {_fmt(result['p'])}, "
                          f"Kendall's W = {_fmt(result['kendall_w'], 3)}.")


def _paper_values(doc: _Document, scenario: str, arms, scenario_rows, paper: list[dict[str, Any]]) -> None:
    entries = [p for p in paper if p["scenario"] == scenario]
    if not entries:
        return
    rows = []
    for p in entries:
        mine = [r for name, rs in arms.items() if name == p["planner"] or name.startswith(p["planner"] + "(")
                for r in rs]
        v = values(mine, p["metric"])
        ours = f"{_fmt(float(v.mean()))} ± {_fmt(float(v.std(ddof=1)) if v.size > 1 else float('nan'))}" \
            if v.size else "–"
        flag = impossible(p["metric"], p["value"], scenario_rows) or ""
        rows.append([p["planner"], p["metric"], _fmt(p["value"]), ours, str(v.size), p.get("note", ""), flag])
    doc.paragraph("The paper's values beside ours (mean ± std over our completed runs).")
    doc.table(["planner", "metric", "paper", "ours", "our runs", "source", "check"], rows)
