"""A study's tables on disk: ``DIR/runs.parquet`` (one row per run) and ``DIR/progress.parquet``
(best cost per iteration of each run, with the evaluations and wall seconds spent by then).

Each is a *directory* of Parquet part files (a Parquet dataset), one part per
flushed batch, so rows are written as cells finish and a study stopped by
Ctrl-C, SIGTERM or a crash keeps every row it flushed.  A part is written under a
dot-name and renamed into place, so a reader never sees half a file (readers skip
names starting with ``.``).  Read them with ``pandas.read_parquet("DIR/runs.parquet")``,
``pyarrow.parquet.read_table`` or ``pyarrow.dataset.dataset`` as one table.
Every part has the same fixed schema (below), so parts always concatenate.
"""

from __future__ import annotations

import os
import time
import uuid
from pathlib import Path as FilePath
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq

RUNS = "runs.parquet"
PROGRESS = "progress.parquet"

RUN_SCHEMA = pa.schema([
    ("study", pa.string()), ("config_hash", pa.string()), ("scenario", pa.string()), ("scenario_ref", pa.string()),
    ("planner", pa.string()), ("label", pa.string()), ("planner_params", pa.string()),
    ("navigator", pa.string()), ("navigator_label", pa.string()), ("navigator_params", pa.string()),
    ("seed", pa.int64()), ("world_seed", pa.int64()), ("mode", pa.string()), ("versions", pa.string()),
    ("outcome", pa.string()), ("success", pa.bool_()), ("error", pa.string()), ("cell_wall_s", pa.float64()),
    ("straight_line_m", pa.float64()), ("clearance_m", pa.float64()),
    ("plan_length_m", pa.float64()), ("plan_time_s", pa.float64()), ("plan_iterations", pa.int64()),
    ("plan_evaluations", pa.int64()), ("plan_collision_free", pa.bool_()), ("plan_waypoints", pa.string()),
    ("plan_bends", pa.int64()), ("plan_convergence_iteration", pa.int64()), ("plan_extra", pa.string()),
    ("plan_raw_length_m", pa.float64()), ("plan_gates_raised", pa.int64()), ("plan_tunnels_closed", pa.int64()),
    ("plan_arc_cost", pa.float64()),
    ("reached", pa.bool_()), ("run_outcome", pa.string()), ("collisions", pa.int64()),
    ("first_collision_s", pa.float64()), ("sim_time_s", pa.float64()), ("wall_time_s", pa.float64()),
    ("path_length_m", pa.float64()), ("min_clearance_m", pa.float64()), ("log", pa.string()),
    ("time_to_goal_s", pa.float64()), ("spl", pa.float64()), ("time_in_danger_s", pa.float64()),
    ("replans", pa.int64()), ("replan_wall_s", pa.float64()), ("stopped_s", pa.float64()),
    ("safety_triggers", pa.int64()), ("control_steps", pa.int64()), ("navigator_wall_s", pa.float64()),
    ("driven_turns", pa.int64()), ("run_events", pa.string()),
])
PROGRESS_SCHEMA = pa.schema([
    ("config_hash", pa.string()), ("iteration", pa.int64()), ("best_cost", pa.float64()),
    ("evaluations", pa.int64()), ("evaluations_estimated", pa.bool_()), ("wall_s", pa.float64()),
])
# Columns that measure time on the wall clock: they differ between two runs of the same cell.
TIMING_COLUMNS = ("cell_wall_s", "plan_time_s", "wall_time_s", "replan_wall_s", "navigator_wall_s")


def _part_names(directory: FilePath) -> list[FilePath]:
    if not directory.is_dir():
        return []
    return sorted(p for p in directory.glob("*.parquet") if not p.name.startswith((".", "_")))


def _read_part(path: FilePath, schema: pa.Schema) -> pa.Table:
    """One part in ``schema``: a column an older part lacks is null (rows written before it existed)."""
    table = pq.read_table(path)
    columns = [table.column(f.name).cast(f.type) if f.name in table.column_names
               else pa.nulls(len(table), f.type) for f in schema]
    return pa.Table.from_arrays(columns, schema=schema)


def read_table(out_dir: str | os.PathLike, name: str = RUNS) -> pa.Table:
    """All parts of one table (an empty table with the schema when there is none)."""
    schema = RUN_SCHEMA if name == RUNS else PROGRESS_SCHEMA
    parts = [_read_part(p, schema) for p in _part_names(FilePath(out_dir) / name)]
    return pa.concat_tables(parts) if parts else schema.empty_table()


def done_hashes(out_dir: str | os.PathLike) -> set[str]:
    """Configuration hashes of the cells that already have a row."""
    parts = _part_names(FilePath(out_dir) / RUNS)
    return {h for p in parts for h in pq.read_table(p, columns=["config_hash"]).column(0).to_pylist()}


class RowWriter:
    """Buffers finished cells and writes them as part files, at least every ``flush_s`` seconds
    or ``batch`` runs, and on :meth:`flush`."""

    def __init__(self, out_dir: str | os.PathLike, batch: int = 16, flush_s: float = 2.0):
        self.out_dir = FilePath(out_dir)
        self.batch, self.flush_s = batch, flush_s
        self.runs: list[dict[str, Any]] = []
        self.progress: list[dict[str, Any]] = []
        self.last_flush = time.monotonic()
        self.token = uuid.uuid4().hex[:8]
        self.parts = 0
        for name in (RUNS, PROGRESS):
            (self.out_dir / name).mkdir(parents=True, exist_ok=True)

    def add(self, row: dict[str, Any], progress: list[dict[str, Any]]) -> None:
        self.runs.append(row)
        self.progress.extend(progress)
        if len(self.runs) >= self.batch or time.monotonic() - self.last_flush >= self.flush_s:
            self.flush()

    def _write(self, name: str, rows: list[dict[str, Any]], schema: pa.Schema) -> None:
        final = self.out_dir / name / f"part-{time.strftime('%Y%m%d%H%M%S')}-{self.token}-{self.parts:05d}.parquet"
        temporary = final.with_name("." + final.name)
        pq.write_table(pa.Table.from_pylist(rows, schema=schema), temporary)
        os.replace(temporary, final)

    def flush(self) -> None:
        """Write the buffered rows; the progress part goes first, so a run row never lacks its history."""
        self.last_flush = time.monotonic()
        if not self.runs:
            return
        if self.progress:
            self._write(PROGRESS, self.progress, PROGRESS_SCHEMA)
        self._write(RUNS, self.runs, RUN_SCHEMA)
        self.parts += 1
        self.runs, self.progress = [], []
