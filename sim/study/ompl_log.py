"""A study's rows as OMPL benchmark logs, for OMPL's ``ompl_benchmark_statistics`` and Planner Arena.

``swarmnav report DIR --ompl-log OUT`` writes ``OUT/<scenario>.log``, one log per scenario, because a
log holds one experiment (the format of OMPL's "How to Benchmark Planners" page, section "The benchmark
logfile format", the grammar its ``ompl_benchmark_statistics`` parses).  Then::

    ompl_benchmark_statistics OUT/*.log -d bench.db

(installed with the ``ompl`` wheel) builds the SQLite database Planner Arena plots: one experiment per
scenario, one planner configuration per study planner label (with its navigator when the study has more
than one), one run per study row, in the study's order.

Each run reports (runs that found no path have empty values where there is no plan):

* ``time REAL``: the plan time in seconds (the cell's wall time for a run without a plan);
* ``solved BOOLEAN``: whether the planner found a plan (the row has one: OMPL's meaning, the planner's own
  outcome); ``correct solution BOOLEAN``: the exact collision check of that plan;
* ``solution length REAL`` (m), ``solution segments INTEGER``;
* ``solution clearance REAL``: the smallest gap in metres between the planned path and the obstacle
  footprints at t = 0 beyond the robot radius (OMPL's "distance to invalid regions" for a disc robot),
  from the path and ``study.json``'s geometry;
* ``evaluations INTEGER``, ``iterations INTEGER``, ``seed INTEGER``;
* physics studies also ``drive success BOOLEAN`` (the goal reached with no collision: the physics outcome, a
  property of its own, so a plan whose drive failed still reads as solved), ``reached BOOLEAN``,
  ``collisions INTEGER``, ``driven length REAL`` and ``driven clearance REAL`` (the simulated run's minimum
  clearance).

Progress properties (the run's best-cost history from ``progress.parquet``): ``best cost REAL``,
``evaluations INTEGER``, ``iteration INTEGER`` and ``time REAL``.  The study records evaluations, not
clock times, per iteration, so ``time`` (the column Planner Arena plots progress against) is the run's
plan time spread in proportion to the evaluations spent: an estimate, as the experiment's setup text
says.  ``inf`` costs (no path yet) are written as ``inf``, which the reader stores as NULL.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path as FilePath
from typing import Any

import numpy as np

from swarmnav.models.geometry import segment_box_distances, segment_disc_distances
from swarmnav.study.report import ordered_runs
from swarmnav.study.rows import PROGRESS, RUNS, read_table

RUN_PROPERTIES = (("time", "REAL"), ("solved", "BOOLEAN"), ("correct solution", "BOOLEAN"),
                  ("solution length", "REAL"), ("solution segments", "INTEGER"), ("solution clearance", "REAL"),
                  ("evaluations", "INTEGER"), ("iterations", "INTEGER"), ("seed", "INTEGER"))
PHYSICS_PROPERTIES = (("drive success", "BOOLEAN"), ("reached", "BOOLEAN"), ("collisions", "INTEGER"), ("driven length", "REAL"),
                      ("driven clearance", "REAL"))
PROGRESS_PROPERTIES = (("time", "REAL"), ("best cost", "REAL"), ("evaluations", "INTEGER"),
                       ("iteration", "INTEGER"))


def _token(text: str) -> str:
    """A name the log's single-token fields (experiment name, host) can hold: no whitespace."""
    return re.sub(r"\s+", "_", text.strip()) or "unnamed"


def _value(value: Any) -> str:
    """One measurement: booleans as 0/1, floats in full precision, missing as empty."""
    if value is None:
        return ""
    if isinstance(value, (bool, np.bool_)):
        return "1" if value else "0"
    if isinstance(value, float):
        return "nan" if math.isnan(value) else ("inf" if math.isinf(value) else repr(value))
    return str(value)


def path_clearance_m(waypoints: list[list[float]], geometry: dict[str, Any]) -> float | None:
    """Smallest gap between the polyline and the footprints of ``geometry`` (``study.json``'s scenario
    entry) beyond its robot radius; None without obstacles or waypoints."""
    pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    if pts.shape[0] == 0:
        return None
    if pts.shape[0] == 1:
        pts = np.vstack([pts, pts])
    gaps = []
    discs = np.asarray(geometry.get("discs_t0", []), dtype=float).reshape(-1, 3)
    if discs.size:
        gaps.append(float(np.min(segment_disc_distances(pts[:-1], pts[1:], discs[:, :2]) - discs[None, :, 2])))
    boxes = np.asarray(geometry.get("boxes", []), dtype=float).reshape(-1, 4)
    if boxes.size:
        gaps.append(float(np.min(segment_box_distances(pts[:-1], pts[1:], boxes))))
    return min(gaps) - float(geometry["robot_radius_m"]) if gaps else None


def _run_values(row: dict[str, Any], geometry: dict[str, Any] | None, physics: bool) -> list[Any]:
    waypoints = json.loads(row["plan_waypoints"]) if row.get("plan_waypoints") else None
    time_s = row["plan_time_s"] if row.get("plan_time_s") is not None else row.get("cell_wall_s")
    values = [time_s, bool(waypoints) and row.get("outcome") == "ok", row.get("plan_collision_free"), row.get("plan_length_m"),
              len(waypoints) - 1 if waypoints else None,
              path_clearance_m(waypoints, geometry) if waypoints and geometry else None,
              row.get("plan_evaluations"), row.get("plan_iterations"), row.get("seed")]
    if physics:
        values += [bool(row.get("success")), row.get("reached"), row.get("collisions"), row.get("path_length_m"), row.get("min_clearance_m")]
    return values


def _progress_line(row: dict[str, Any], entries: list[dict[str, Any]]) -> str:
    """One run's progress samples, ``time,best cost,evaluations,iteration,`` each followed by ``;``.
    A sample whose estimated time repeats the previous one is left out (the database keys progress by
    run and time)."""
    if not entries or row.get("plan_time_s") is None:
        return ""
    total = max(entries[-1]["evaluations"], 1)
    samples, last_time = [], None
    for p in entries:
        time_s = row["plan_time_s"] * p["evaluations"] / total
        if time_s == last_time:
            continue
        last_time = time_s
        samples.append(",".join(_value(v) for v in (time_s, p["best_cost"], p["evaluations"], p["iteration"])) + ",")
    return ";".join(samples) + (";" if samples else "")


def _config_name(row: dict[str, Any], several_navigators: bool) -> str:
    label = row.get("label") or row["planner"]
    return f"{label} + {row.get('navigator_label') or row.get('navigator')}" if several_navigators else label


def _common_properties(row: dict[str, Any]) -> list[str]:
    lines = [f"planner = {row['planner']}"]
    lines += [f"params.{k} = {json.dumps(v)}" for k, v in sorted(json.loads(row.get("planner_params") or "{}").items())]
    if row.get("navigator"):
        lines.append(f"navigator = {row['navigator']}")
        lines += [f"navigator.{k} = {json.dumps(v)}"
                  for k, v in sorted(json.loads(row.get("navigator_params") or "{}").items())]
    return lines


def experiment_log(study: str, scenario: str, rows: list[dict[str, Any]], progress: dict[str, list[dict]],
                   meta: dict[str, Any]) -> str:
    """The OMPL benchmark log of one scenario's rows (already in the study's order)."""
    physics = meta.get("mode") == "physics"
    properties = RUN_PROPERTIES + (PHYSICS_PROPERTIES if physics else ())
    geometry = meta.get("scenarios", {}).get(scenario)
    several_navigators = len({r.get("navigator_label") for r in rows}) > 1
    configs: dict[str, list[dict[str, Any]]] = {}
    for row in rows:
        configs.setdefault(_config_name(row, several_navigators), []).append(row)
    counts = {len(runs) for runs in configs.values()}
    total_s = sum(r.get("cell_wall_s") or 0.0 for r in rows)
    lines = ["swarmnav version 0.1.0",
             f"Experiment {_token(study)}.{_token(scenario)}",
             "Running on unknown",  # the rows do not record the host
             "Starting at unknown",
             "<<<|",
             f"swarmnav study {study}, scenario {scenario}, mode {meta.get('mode', '?')}.",
             "Progress 'time' is the plan time spread in proportion to the evaluations (an estimate): "
             "the study records evaluations per iteration, not clock times.",
             "|>>>",
             "0 is the random seed",  # each run's own seed is its 'seed' property
             f"{float(meta.get('wall_limit_s', 0.0))} seconds per run",
             "0 MB per run"]
    if len(counts) == 1:
        lines.append(f"{counts.pop()} runs per planner")
    lines += [f"{total_s!r} seconds spent to collect the data", f"{len(configs)} planners"]
    for name, runs in configs.items():
        common = _common_properties(runs[0])
        lines += [name, f"{len(common)} common properties", *common,
                  f"{len(properties)} properties for each run", *(f"{p} {t}" for p, t in properties),
                  f"{len(runs)} runs"]
        lines += ["".join(f"{_value(v)}; " for v in _run_values(r, geometry, physics)) for r in runs]
        histories = [progress.get(r["config_hash"], []) for r in runs]
        if any(histories):
            lines += [f"{len(PROGRESS_PROPERTIES)} progress properties for each run",
                      *(f"{p} {t}" for p, t in PROGRESS_PROPERTIES), f"{len(runs)} runs"]
            lines += [_progress_line(r, h) for r, h in zip(runs, histories)]
        lines.append(".")
    return "\n".join(lines) + "\n"


def _progress_by_run(directory: FilePath) -> dict[str, list[dict[str, Any]]]:
    out: dict[str, dict[int, dict[str, Any]]] = {}
    for p in read_table(directory, PROGRESS).to_pylist():
        out.setdefault(p["config_hash"], {})[p["iteration"]] = p  # a resumed part may repeat an entry
    return {h: [entries[i] for i in sorted(entries)] for h, entries in out.items()}


def write_ompl_logs(directory: str | FilePath, out_dir: str | FilePath) -> list[FilePath]:
    """Write ``out_dir/<scenario>.log`` for each scenario of the study in ``directory``; return the paths."""
    directory, out_dir = FilePath(directory), FilePath(out_dir)
    meta_path = directory / "study.json"
    meta = json.loads(meta_path.read_text(encoding="utf-8")) if meta_path.exists() else {}
    runs = ordered_runs(read_table(directory, RUNS).to_pylist(), meta)
    progress = _progress_by_run(directory)
    study = meta.get("name", directory.name)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    for scenario in dict.fromkeys(r["scenario"] for r in runs):
        path = out_dir / f"{_token(scenario)}.log"
        rows = [r for r in runs if r["scenario"] == scenario]
        path.write_text(experiment_log(study, scenario, rows, progress, meta), encoding="utf-8")
        paths.append(path)
    return paths

