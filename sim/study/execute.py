"""Run a study into a directory: expand, skip the cells already there, run the rest, write rows as they finish.

``DIR/study.json`` records the study's name, description, mode, reference
planner, the paper's values and, per scenario, what the report draws under the
paths (arena, start, goal, the obstacle footprints at t = 0): a report needs only
the rows and this file, so it works on a copied results folder;
``DIR/runs.parquet`` and ``DIR/progress.parquet`` hold the rows (see ``rows``); physics rows of dynamic
scenarios carry the clairvoyant oracle's verdict, a time score and the scene's difficulty metrics, each scene
measured once by the driver and kept in ``DIR/difficulty.json`` (see ``yardstick``).
"""

from __future__ import annotations

import dataclasses
import json
import os
import sys
import time
from pathlib import Path as FilePath
from typing import Any, Iterator, TextIO

from swarmnav.models.contained_files import check_no_link, folder as contained_folder, loads_json, replace_file
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import load_scenario
from swarmnav.study.engines import run_inline, run_local
from swarmnav.study.grid import Cell, count_cells, iter_cells
from swarmnav.study.lock import FolderLock
from swarmnav.study.main_guard import check_main_guard
from swarmnav.study.rows import RowWriter, compact, done_hashes, read_table
from swarmnav.study.spec import Study, study_from_tables
from swarmnav.study.yardstick import Yardstick

METADATA = "study.json"


def scenario_geometry(ref: str, world_seed: int | None = None) -> dict[str, Any]:
    """What the report's path plot needs of one scenario: arena size, start, goal, and the obstacle
    footprints at t = 0 (discs as [x, y, r], boxes as [x_min, y_min, x_max, y_max], in metres)."""
    scenario = load_scenario(ref)
    if world_seed is not None:
        scenario = scenario.with_world_seed(world_seed)
    return {"arena_m": [scenario.arena_width_m, scenario.arena_height_m],
            "start": [scenario.start.x_m, scenario.start.y_m], "goal": [scenario.goal.x_m, scenario.goal.y_m],
            "robot_radius_m": scenario.robot_radius_m,
            "discs_t0": [[d.x_m, d.y_m, d.radius_m] for d in scenario.discs_at(0.0)],
            "boxes": [[b.x_min_m, b.y_min_m, b.x_max_m, b.y_max_m] for b in scenario.boxes]}


def _scenario_entry(ref: str, world_seed: int | None, study: Study) -> dict[str, Any]:
    """The geometry of one scenario and what the report's anytime and path figures need of it."""
    from swarmnav.study.scenario_facts import scenario_facts
    scenario = load_scenario(ref)
    if world_seed is not None:
        scenario = scenario.with_world_seed(world_seed)
    return {**scenario_geometry(ref, world_seed), **scenario_facts(scenario, study.clearance_m, study.time_limit_s)}


def study_metadata(study: Study) -> dict[str, Any]:
    from swarmnav.study.provenance import study_inputs
    world_seed = study.world_seeds[0]
    return {"inputs": study_inputs(study), "claims": [c.as_dict() for c in study.claims], "name": study.name, "description": study.description, "source": study.source, "mode": study.mode,
            "reference": study.reference, "planners": [p.label for p in study.planners],
            "navigators": [n.label for n in study.navigators],
            "paper": [dataclasses.asdict(p) for p in study.paper],
            "scenarios": {FilePath(s).stem: _scenario_entry(s, world_seed, study) for s in study.scenarios}}


def _write_metadata(study: Study, out_dir: FilePath) -> None:
    path = out_dir / METADATA
    metadata = study_metadata(study)
    check_no_link(path, "--out")  # a link planted in the folder is neither read nor written through
    if path.exists():
        try:
            old = loads_json(path.read_text(encoding="utf-8"), str(path))
        except (OSError, ValueError):
            old = {}
        old = old if isinstance(old, dict) else {}
        previous = old.get("name")
        # rows of an earlier version of the study stay in the folder: keep the geometry of their scenarios
        metadata["scenarios"] = {**old.get("scenarios", {}), **metadata["scenarios"]}
        metadata["inputs"] = resumed_inputs(old.get("inputs"), metadata["inputs"], out_dir)
        if previous != study.name:
            raise ConfigError("--out", f"holds the rows of study {previous!r}, not {study.name!r} "
                                       "(choose another directory)", str(out_dir))
    out_dir.mkdir(parents=True, exist_ok=True)
    replace_file(path, json.dumps(metadata, indent=2) + "\n", "--out")


def resumed_inputs(old: dict[str, Any] | None, new: dict[str, Any], out_dir: FilePath) -> dict[str, Any]:
    """The inputs a resumed folder records: today's, unless rows already there were made by sources,
    scenarios or a swarmnav version that have changed since; then the old record stays (with today's study
    file, whose claims and comments decide no row, and the files of newly used components added), so that
    ``report --check-fresh`` calls the mixed rows stale, and a warning says to start the folder afresh."""
    from swarmnav.study.provenance import stale_inputs
    if not old or not (out_dir / "runs.parquet").exists():
        return new
    changes = [c for c in stale_inputs(old, new)[0] if not c.startswith("study file")
               and not c.endswith("newly used") and not c.endswith("no longer used")]
    if not changes:
        return {**new, "sources": {**old.get("sources", {}), **new["sources"]},
                "scenarios": {**old.get("scenarios", {}), **new["scenarios"]}}
    print(f"swarmnav: warning: {out_dir} holds rows made before {'; '.join(changes)}: its verdicts will be stale "
          "(delete the folder to rerun the study afresh)", file=sys.stderr)
    return {**old, "study_file": new["study_file"],
            "sources": {**new["sources"], **old.get("sources", {})},
            "scenarios": {**new["scenarios"], **old.get("scenarios", {})}}


class ProgressBar:
    """done / total, failures, rate and time left, redrawn on one stderr line."""

    def __init__(self, total: int, stream: TextIO):
        self.total, self.stream = total, stream
        self.started = time.monotonic()

    def update(self, done: int, failed: int) -> None:
        elapsed = time.monotonic() - self.started
        rate = done / elapsed if elapsed > 0 else 0.0
        left = (self.total - done) / rate if rate > 0 else float("nan")
        width = 30
        filled = int(width * done / self.total) if self.total else width
        self.stream.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{self.total}  failed {failed}  "
                          f"{rate:.2f} runs/s  {left:.0f} s left ")
        self.stream.flush()

    def close(self) -> None:
        self.stream.write("\n")
        self.stream.flush()


def pending_cells(study: Study, out_dir: FilePath, retry_errors: bool = False) -> tuple[Iterator[Cell], int, int]:
    """The cells without a row yet (lazily), how many they are, and how many the study has in all.  A cell whose
    row is an ``error`` counts as done, unless ``retry_errors``."""
    done = done_hashes(out_dir, ("error",) if retry_errors else ())
    pending = sum(1 for c in iter_cells(study) if c.config_hash not in done) if done else count_cells(study)
    return (c for c in iter_cells(study) if c.config_hash not in done), pending, count_cells(study)


def run_study(study: Study, out_dir: str | os.PathLike, *, engine: str = "local", workers: int | None = None,
              address: str | None = None, logs: bool | str = False, show_progress: bool = False,
              retry_errors: bool = False) -> dict[str, Any]:
    """Run every cell of ``study`` that ``out_dir`` does not hold yet; return a summary of this invocation.

    The folder is locked while the study runs (a second study into it is refused, naming this one's PID);
    when every cell has a row, the parts are compacted.  ``logs``: keep each physics run's MCAP log in
    ``out_dir/logs``, of format ``swarmnav`` (``True``) or the format named (``"ros2"``)."""
    out_dir = FilePath(out_dir)
    if engine == "local":
        check_main_guard()  # a script's unguarded top level: each spawned worker would run it again
    if engine == "ray" and address:
        from swarmnav.study.ray_engine import check_reachable
        check_reachable(address)  # before anything is written
    with FolderLock(out_dir):
        return _run_locked(study, out_dir, engine, workers, address, logs, show_progress, retry_errors)


def _run_locked(study: Study, out_dir: FilePath, engine: str, workers: int | None, address: str | None,
                logs: bool | str, show_progress: bool, retry_errors: bool) -> dict[str, Any]:
    _write_metadata(study, out_dir)
    todo, pending, total = pending_cells(study, out_dir, retry_errors)
    workers = workers or os.cpu_count() or 1
    logs_dir = str(contained_folder(out_dir / "logs", "--out").resolve()) if logs else None
    log_format = logs if isinstance(logs, str) else "swarmnav"
    nodes: set[str] = set()
    if engine == "ray":
        from swarmnav.study.ray_engine import run_ray
        results: Iterator = run_ray(todo, address, None if address else workers, logs_dir, nodes, log_format)
    elif engine == "inline":
        results = run_inline(todo, logs_dir, log_format)
    else:
        results = run_local(todo, workers, logs_dir, log_format)
    writer = RowWriter(out_dir)
    yardstick = Yardstick(out_dir, study.time_limit_s, study.trust_code)
    bar = ProgressBar(pending, sys.stderr) if show_progress and pending else None
    counts: dict[str, int] = {}
    started = time.perf_counter()
    try:
        for row, progress in results:
            writer.add(yardstick.annotate(row), progress)
            counts[row["outcome"]] = counts.get(row["outcome"], 0) + 1
            if bar:
                bar.update(sum(counts.values()), sum(v for k, v in counts.items() if k != "ok"))
    finally:
        writer.flush()
        if bar:
            bar.close()
        if hasattr(results, "close"):
            results.close()
    wall_s = time.perf_counter() - started
    parts = compact(out_dir)  # reached only when every cell has run: an interrupted study keeps its parts
    ran = sum(counts.values())
    return {"study": study.name, "out": str(out_dir), "cells": total, "skipped": total - pending, "ran": ran,
            "failed": ran - counts.get("ok", 0), "outcomes": counts, "engine": engine, "workers": workers,
            "wall_s": round(wall_s, 3), "parts_compacted": parts, "driver_peak_mb": round(_peak_rss_mb(), 1), **({"ray_nodes": len(nodes)} if nodes else {})}


def _peak_rss_mb() -> float:
    """This process's peak resident memory so far (the driver's; workers are processes of their own)."""
    import resource
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # KiB on Linux


def run_study_tables(tables: dict[str, Any], out_dir: str | os.PathLike, *, workers: int = 1,
                     source: str = "swarmnav bench", show_progress: bool = False, engine: str = "local",
                     address: str | None = None) -> list[dict[str, Any]]:
    """Validate a study built in code (the tables its TOML file would hold), run it into ``out_dir`` (in this
    process with ``workers=1``, else on that many local processes; ``engine="ray"``: on Ray, a local instance
    of ``workers`` CPUs or the cluster at ``address``), and return every run row of the folder (what the
    benchmarks tabulate)."""
    # Tables built in code from the command line's options (bench navigation's --navigator-set policy=...): their
    # code is the user's; the scenario files they name are still data (a cell whose file names code is an error).
    study = study_from_tables(tables, source, str(tables.get("name", "study")), trust_code=True)
    study = dataclasses.replace(study, trust_code=False)
    if engine == "ray":
        run_study(study, out_dir, engine="ray", workers=workers, address=address, show_progress=show_progress)
    else:
        run_study(study, out_dir, engine="inline" if workers == 1 else "local", workers=workers,
                  show_progress=show_progress)
    return read_table(out_dir).to_pylist()
