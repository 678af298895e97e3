"""``swarmnav report DIR``: a self-contained HTML report of a study's rows, its Markdown twin, and the verdicts
on the study's claims as ``claims.json``.

It reads only ``DIR/runs.parquet``, ``DIR/progress.parquet`` and ``DIR/study.json`` (the reference planner,
the paper's values and claims, each scenario's arena and obstacles at t = 0, its moving obstacles' tracks and
exact optimum, as recorded when the study ran), and the MCAP logs of physics runs kept with ``--logs`` (the
driven trajectories), so a copied results folder reports alike.  The HTML embeds its figures as SVG (scaled
to the page's width); ``<report>_files/`` beside it holds each figure as SVG and PNG, and each table as CSV
and as a LaTeX ``booktabs`` table (``tables.tex`` inputs them all into one document).
"""

from __future__ import annotations

import base64
import html
import json
import re
from pathlib import Path as FilePath
from typing import Any

from swarmnav.study import against_oracle, anytime, figures
from swarmnav.study.claim_spec import Claim
from swarmnav.study.claims import claims_document
from swarmnav.study.report_tables import (claims_table, count_table, merge_identical, paper_values_table,
                                              statistics_section, summary_tables)
from swarmnav.study.rows import load_progress_rows, load_runs
from swarmnav.study.statistics import by_scenario, paper_table
from swarmnav.study.tables import Table

CLAIMS_FILE = "claims.json"
STYLE = ("body{font-family:sans-serif;max-width:1200px;margin:auto;padding:0 12px}"
         "img{max-width:100%;height:auto;display:block}figure{margin:12px 0}"
         ".table{overflow-x:auto;max-width:100%}table{border-collapse:collapse;margin:8px 0}"
         "td,th{border:1px solid #bbb;padding:3px 5px;font-size:13px;text-align:right;white-space:nowrap}th{white-space:normal}"
         "th{background:#eee}td:first-child,th:first-child{text-align:left}"
         "td.t{text-align:left;white-space:normal;min-width:8em}")


def no_yardstick(row: dict[str, Any]) -> bool:
    """The oracle's refused run on a scene whose agents react to the robot (its verdict ``none``): no yardstick
    there, so a report counts it nowhere (neither a run nor a failure)."""
    return row.get("navigator") == "oracle" and row.get("oracle_verdict") == "none"


def load_rows(directory: FilePath) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """The run rows (only the columns a report reads; each cell once) and the progress rows of a results folder,
    as dicts."""
    return load_runs(directory), load_progress_rows(directory)


class _Document:
    """Builds the HTML and the Markdown side by side; writes figures and tables into ``files_dir``."""

    def __init__(self, title: str, files_dir: FilePath):
        # An empty icon: served over HTTP a page without one makes the browser ask for /favicon.ico (a 404).
        self.html = [f"<!doctype html><html><head><meta charset='utf-8'><link rel='icon' href='data:,'>"
                     "<meta name='viewport' content='width=device-width, initial-scale=1'>"
                     f"<title>{html.escape(title)}</title><style>{STYLE}</style></head><body>",
                     f"<h1>{html.escape(title)}</h1>"]
        self.markdown = [f"# {title}", ""]
        self.files_dir = files_dir
        self.images = 0
        self.tables: list[str] = []

    def heading(self, text: str, level: int = 2) -> None:
        self.html.append(f"<h{level}>{html.escape(text)}</h{level}>")
        self.markdown += ["#" * level + " " + text, ""]

    def paragraph(self, text: str) -> None:
        self.html.append(f"<p>{html.escape(text)}</p>")
        self.markdown += [text, ""]

    def table(self, table: Table) -> None:
        self.html.append(table.html())
        self.markdown += table.markdown()
        folder = self.files_dir / "tables"
        folder.mkdir(parents=True, exist_ok=True)
        name = re.sub(r"[^A-Za-z0-9._-]+", "-", table.name)
        while name in self.tables:
            name += "-2"
        self.tables.append(name)
        (folder / f"{name}.csv").write_text(table.csv(), encoding="utf-8")
        (folder / f"{name}.tex").write_text(table.latex(), encoding="utf-8")

    def figure(self, fig, caption: str) -> None:
        if fig is None:
            return
        self.images += 1
        stem = f"figure-{self.images:03d}"
        self.files_dir.mkdir(parents=True, exist_ok=True)
        svg, png = figures.encode(fig)
        figures.close(fig)
        (self.files_dir / f"{stem}.svg").write_bytes(svg)
        (self.files_dir / f"{stem}.png").write_bytes(png)
        self.html.append(f"<figure><img src='data:image/svg+xml;base64,{base64.b64encode(svg).decode()}' "
                         f"alt='{html.escape(caption)}' style='max-width:100%;height:auto'>"
                         f"<figcaption>{html.escape(caption)} (<a href='{self.files_dir.name}/{stem}.svg'>SVG</a>, "
                         f"<a href='{self.files_dir.name}/{stem}.png'>PNG</a>)</figcaption></figure>")
        self.markdown += [f"![{caption}]({self.files_dir.name}/{stem}.png)", ""]

    def finish(self, html_path: FilePath, markdown_path: FilePath) -> None:
        self.html.append("</body></html>")
        html_path.write_text("\n".join(self.html), encoding="utf-8")
        markdown_path.write_text("\n".join(self.markdown) + "\n", encoding="utf-8")
        if self.tables:
            inputs = "\n".join(rf"\input{{tables/{name}.tex}}" for name in self.tables)
            (self.files_dir / "tables.tex").write_text(
                "\\documentclass{article}\n\\usepackage[utf8]{inputenc}\n\\usepackage{booktabs}\n"
                "\\usepackage[landscape,margin=1.5cm]{geometry}\n\\begin{document}\n" + inputs
                + "\n\\end{document}\n", encoding="utf-8")


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


def _driven(arms: dict[str, list[dict[str, Any]]]) -> tuple[dict[str, tuple], str]:
    """The driven trajectory and collision points of each arm's path-figure run, read from its MCAP log
    (kept by ``swarmnav study --logs``); and a sentence saying where there were none."""
    from swarmnav.log.reader import read_log
    from swarmnav.log.plot import collision_points_m
    out, missing = {}, []
    for name, rows in arms.items():
        ok = sorted((r for r in rows if r.get("plan_waypoints")), key=lambda r: (r["seed"], str(r["world_seed"])))
        if not ok or ok[0].get("mode") != "physics":
            continue
        log = ok[0].get("log")
        if not log or not FilePath(log).is_file():
            missing.append(name)
            continue
        run_log = read_log(log, allow_truncated=True)
        out[name] = (run_log.position_m[:, :2], collision_points_m(run_log))
    sentence = "" if not missing else (f"No driven trajectory for {', '.join(missing)}: the rows carry none and "
                                       "no log was kept (run the study with --logs to draw them).")
    return out, sentence


def _against_oracle(doc: _Document, runs: list[dict[str, Any]]) -> None:
    """Each navigator against the clairvoyant oracle, over the dynamic scenes (nothing without them)."""
    table = against_oracle.navigator_table(runs)
    if table is None:
        return
    doc.heading("Navigation against the oracle")
    doc.paragraph(against_oracle.STATEMENT)
    doc.table(table)
    metric = against_oracle.FIGURE_METRIC
    doc.figure(against_oracle.success_figure(runs, metric),
               f"Success on the oracle-solvable scenes against their {against_oracle.METRIC_TITLES[metric]}: "
               f"the scenes ordered by it in up to {against_oracle.FIGURE_BINS} bins of equal counts, each "
               "navigator's success over its runs in each bin (the clairvoyant oracle left out); the grey numbers: "
               "the scenes in each bin")

def write_report(directory: str | FilePath, html_path: str | FilePath) -> FilePath:
    """Write the HTML report, its Markdown twin (``.md`` beside it) and ``claims.json`` beside them; return
    the Markdown path."""
    directory, html_path = FilePath(directory), FilePath(html_path)
    runs, progress = load_rows(directory)
    history = anytime.histories(progress)
    meta_path = directory / "study.json"
    meta = json.loads(meta_path.read_text(encoding="utf-8")) if meta_path.exists() else {}
    runs = ordered_runs(runs, meta)
    refused = [r for r in runs if no_yardstick(r)]
    runs = [r for r in runs if not no_yardstick(r)]
    title = f"Study {meta.get('name', directory.name)}"
    markdown_path = html_path.with_suffix(".md")
    html_path.parent.mkdir(parents=True, exist_ok=True)
    doc = _Document(title, html_path.parent / f"{html_path.stem}_files")
    if meta.get("description"):
        doc.paragraph(meta["description"])
    failed = sum(r["outcome"] != "ok" for r in runs)
    unsuccessful = sum(not r.get("success") for r in runs)
    doc.paragraph(f"{len(runs)} runs, {len(runs) - unsuccessful} successful, {unsuccessful} not (of which {failed} "
                  f"produced no result: no path, error or wall-limit timeout; the others collided or ran out of "
                  f"simulated time; counted, never dropped). Mode: {meta.get('mode', '?')}. Statistics compare each planner against the "
                  f"reference planner {meta.get('reference', '?')!r}. Numbers to 4 significant digits, "
                  "p-values to 2.")
    if refused:
        doc.paragraph(f"No yardstick: {len(refused)} runs of the clairvoyant oracle on scenes whose agents react to "
                      "the robot (sees_robot), where no clairvoyant yardstick exists; the oracle refuses them, and "
                      "they are left out of every total and table above and below.")
    claims = [Claim.from_dict(c) for c in meta.get("claims", [])]
    document = claims_document(meta.get("name", directory.name), claims, runs, meta.get("inputs"))
    (html_path.parent / CLAIMS_FILE).write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")
    if claims:
        doc.heading("Claims")
        doc.paragraph("Each claim of the paper the study tests, with its verdict: reproduces (every pair "
                      "significant in the claimed direction), contradicted (a pair significant in the opposite "
                      "direction), underpowered (too few runs for the test to reach alpha after Holm's "
                      "correction, whatever they gave) or inconclusive (enough runs, no significant difference); "
                      "Holm-adjusted over all pairs of all claims, alpha 0.05. A12: "
                      "Vargha-Delaney effect size, the probability that the claimed planner's run is better "
                      "(0.5: no effect), of the weakest pair; difference: claimed minus other (mean, or mean "
                      "paired difference) with its 95% bootstrap interval. n: runs tested / runs per side; a "
                      "deterministic side (one plan repeated) counts once and is compared as a single value.")
        rule = document["seed_rule"]
        doc.paragraph(f"Seed rule: {rule['rule']}. This study: m = {rule['pairs']} pairs, so each side needs at "
                      f"least {rule['seeds_needed']} seeds; this run has {rule['seeds_run']} "
                      f"({'met' if rule['met'] else 'NOT met: its verdicts are underpowered where a test cannot reach alpha'}).")
        doc.table(claims_table(document))
    _against_oracle(doc, runs)
    for scenario, arms in by_scenario(runs).items():
        scenario_rows = [r for rows in arms.values() for r in rows]
        arms, identical = merge_identical(arms)
        doc.heading(f"Scenario {scenario}")
        for sentence in identical:
            doc.paragraph(sentence)
        doc.table(count_table(scenario, arms))
        header, table = paper_table(arms)
        doc.paragraph("One row per planner in the shape of Gong et al. (2022) Table 3, over the completed runs "
                      "(best length: each planner's shortest plan, the paper's 'optimal length'; std: sample; "
                      "their 'standard deviation' column equals mean - best in every row, so that is given too). "
                      "Bends: heading changes between consecutive waypoints, as the paper counts them on grid "
                      "paths; a continuous planner's path is its spline sampled densely, so there every sample "
                      "counts and the figure says little.")
        doc.table(Table(f"{scenario}-paper-table", f"{scenario}: one row per planner (Gong et al. 2022 Table 3)",
                        header, table))
        for summary in summary_tables(scenario, arms):
            doc.table(summary)
        errors = sorted({r["error"] for r in scenario_rows if r.get("error")})
        if errors:
            doc.paragraph("Failures: " + "; ".join(errors[:5]) + (" …" if len(errors) > 5 else ""))
        for item in statistics_section(scenario, arms, meta.get("reference")):
            if isinstance(item, str):
                doc.paragraph(item)
            elif item.rows:
                doc.table(item)
            else:
                doc.paragraph(f"({item.caption}: no completed runs to test.)")
        paper = paper_values_table(scenario, arms, scenario_rows, meta.get("paper", []))
        if paper is not None:
            doc.paragraph("The paper's values beside ours (mean ± std over our completed runs).")
            doc.table(paper)
        geometry = meta.get("scenarios", {}).get(scenario)
        present = [m for m in figures.METRIC_LABELS if any(r.get(m) is not None for r in scenario_rows)]
        doc.figure(figures.box_plots(arms, present), f"{scenario}: distributions over the completed runs")
        doc.figure(figures.outcome_bars(arms), f"{scenario}: outcomes (success: reached with no collision)")
        fig, sentence = figures.anytime_figure(arms, history, (geometry or {}).get("optimum_m"))
        if fig is None:
            doc.paragraph(sentence)
        doc.figure(fig, f"{scenario}: anytime performance. Top: fixed budget, median best cost over runs with the "
                        "interquartile band (each planner's own objective: metres of path, plus any penalty). "
                        f"Bottom: fixed target, the share of (run, target) pairs reached by each budget. {sentence}")
        driven, missing = _driven(arms)
        doc.figure(figures.paths(arms, geometry, driven),
                   f"{scenario}: the plan of one seed per planner" + (", the trajectory it drove" if driven else "")
                   + (f". {missing}" if missing else ""))
    doc.finish(html_path, markdown_path)
    return markdown_path
