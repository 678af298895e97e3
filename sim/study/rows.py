"""A study's tables on disk: ``DIR/runs.parquet`` (one row per run) and ``DIR/progress.parquet``
(best cost per iteration of each run, with the evaluations and wall seconds spent by then).

Each is a *directory* of Parquet part files (a Parquet dataset), one part per
flush (every ``flush_s`` seconds while cells finish), so a study stopped by
Ctrl-C, SIGTERM or a crash keeps every row it flushed.  A part is written under a
dot-name and renamed into place, so a reader never sees half a file (readers skip
names starting with ``.``).  When a study finishes, :func:`compact` rewrites the
parts into a few large ones.  Read them with ``pandas.read_parquet("DIR/runs.parquet")``,
``pyarrow.parquet.read_table`` or ``pyarrow.dataset.dataset`` as one table.
Every part has the same fixed schema (below), so parts always concatenate.

Rows are keyed by their cell (``config_hash``; progress rows by cell and
iteration).  Part names sort in writing order, and where a key appears twice (a
folder written by two studies at once before folders were locked, a retried
``error`` cell, a crash during compaction) the readers keep the last row and say
so on stderr.  A part that cannot be read (truncated, empty, not this table's) is
moved to ``DIR/damaged/`` with one warning naming it; its cells have no row, so
a resume runs them again.
"""

from __future__ import annotations

import math
import os
import sys
import time
import uuid
from pathlib import Path as FilePath
from typing import Any

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from swarmnav.models.contained_files import check_no_link, folder as contained_folder

RUNS = "runs.parquet"
PROGRESS = "progress.parquet"

RUN_SCHEMA = pa.schema([
    ("study", pa.string()), ("config_hash", pa.string()), ("scenario", pa.string()), ("scenario_ref", pa.string()),
    ("planner", pa.string()), ("label", pa.string()), ("planner_params", pa.string()),
    ("navigator", pa.string()), ("navigator_label", pa.string()), ("navigator_params", pa.string()),
    ("seed", pa.int64()), ("world_seed", pa.int64()), ("mode", pa.string()), ("versions", pa.string()),
    ("outcome", pa.string()), ("success", pa.bool_()), ("error", pa.string()), ("cell_wall_s", pa.float64()),
    ("straight_line_m", pa.float64()), ("clearance_m", pa.float64()),
    ("map_knowledge", pa.string()), ("pose_source", pa.string()),
    ("plan_length_m", pa.float64()), ("plan_time_s", pa.float64()), ("plan_iterations", pa.int64()),
    ("plan_evaluations", pa.int64()), ("plan_collision_free", pa.bool_()), ("plan_waypoints", pa.string()),
    ("plan_bends", pa.int64()), ("plan_convergence_iteration", pa.int64()), ("plan_extra", pa.string()),
    ("plan_raw_length_m", pa.float64()), ("plan_gates_raised", pa.int64()), ("plan_tunnels_closed", pa.int64()),
    ("plan_arc_cost", pa.float64()), ("plan_map_arc_cost", pa.float64()), ("plan_moves", pa.int64()), ("plan_cell_clearance_m", pa.float64()),
    ("plan_nodes_visited", pa.int64()),
    ("reached", pa.bool_()), ("run_outcome", pa.string()), ("collisions", pa.int64()),
    ("first_collision_s", pa.float64()), ("sim_time_s", pa.float64()), ("wall_time_s", pa.float64()),
    ("path_length_m", pa.float64()), ("min_clearance_m", pa.float64()), ("log", pa.string()),
    ("time_to_goal_s", pa.float64()), ("spl", pa.float64()), ("time_in_danger_s", pa.float64()),
    ("replans", pa.int64()), ("replan_wall_s", pa.float64()), ("stopped_s", pa.float64()),
    ("safety_triggers", pa.int64()), ("control_steps", pa.int64()), ("navigator_wall_s", pa.float64()),
    ("driven_turns", pa.int64()), ("run_events", pa.string()),
    ("budget", pa.string()), ("budget_evaluations", pa.int64()), ("budget_time_s", pa.float64()),
    ("budgeted", pa.bool_()), ("plan_mode", pa.string()), ("planner_resolved", pa.string()),
    # against the clairvoyant oracle, physics rows of dynamic scenarios (sim/study/yardstick.py)
    ("oracle_verdict", pa.string()), ("oracle_reason", pa.string()), ("oracle_t_star_s", pa.float64()),
    ("oracle_cell_m", pa.float64()), ("time_score", pa.float64()), ("static_density", pa.float64()),
    ("dispersion", pa.float64()), ("survivability", pa.float64()), ("dynamic_traversability", pa.float64()),
    ("t_star_ratio", pa.float64()), ("difficulty_error", pa.string()), ("run_cpu_s", pa.float64()),
    # among agents (orca / social_force obstacles) only: sim/crowd_stepping.crowd_metrics
    ("discomfort_frequency", pa.float64()), ("min_separation_m", pa.float64()),
    ("path_irregularity_rad_m", pa.float64()),
])
PROGRESS_SCHEMA = pa.schema([
    ("config_hash", pa.string()), ("iteration", pa.int64()), ("best_cost", pa.float64()),
    ("evaluations", pa.int64()), ("evaluations_estimated", pa.bool_()), ("wall_s", pa.float64()),
])
# Columns that measure time on the wall clock: they differ between two runs of the same cell.
TIMING_COLUMNS = ("cell_wall_s", "plan_time_s", "wall_time_s", "replan_wall_s", "navigator_wall_s", "run_cpu_s")
PROGRESS_TIMING_COLUMNS = ("wall_s",)  # the same, of progress.parquet


DAMAGED = "damaged"
KEYS = {RUNS: ("config_hash",), PROGRESS: ("config_hash", "iteration")}
COMPACT_FILE_ROWS = 1_000_000  # rows per compacted part: a million-cell study ends with one or two files
COMPACT_GROUP_ROWS = 16_384  # rows per Parquet row group of a compacted part


def warn(message: str) -> None:
    print(f"swarmnav: warning: {message}", file=sys.stderr)


def _schema(name: str) -> pa.Schema:
    return RUN_SCHEMA if name == RUNS else PROGRESS_SCHEMA


def part_name(token: str, index: int) -> str:
    """A part's file name; names sort in writing order (nanoseconds, then the writer's counter)."""
    now = time.time_ns()
    return f"part-{time.strftime('%Y%m%d%H%M%S', time.gmtime(now // 10**9))}{now % 10**9:09d}-{token}-{index:05d}.parquet"


def _part_names(directory: FilePath) -> list[FilePath]:
    if not directory.is_dir():
        return []
    return sorted(p for p in directory.glob("*.parquet") if not p.name.startswith((".", "_")))


class DamagedPart(Exception):
    """A part file that is not a readable part of its table."""


def _read_part(path: FilePath, schema: pa.Schema, columns: list[str] | None = None) -> pa.Table:
    """One part in ``schema`` (or its ``columns``): a column an older part lacks is null (rows written before it
    existed).  Raises ``DamagedPart`` for a file that is no Parquet or holds another table."""
    wanted = [f for f in schema if columns is None or f.name in columns]
    try:
        present = set(pq.read_schema(path).names)
        if "config_hash" not in present:
            raise DamagedPart("it holds no config_hash column (not a part of this table)")
        table = pq.read_table(path, columns=[f.name for f in wanted if f.name in present], use_threads=False)
        arrays = [table.column(f.name).cast(f.type) if f.name in present else pa.nulls(len(table), f.type)
                  for f in wanted]
    except FileNotFoundError:
        raise
    except (pa.ArrowException, OSError, ValueError) as exc:
        raise DamagedPart(f"{type(exc).__name__}: {exc}".splitlines()[0]) from None
    return pa.Table.from_arrays(arrays, schema=pa.schema(wanted))


def set_aside(path: FilePath, reason: str) -> None:
    """Move a damaged part to ``DIR/damaged/`` (``DIR`` the study folder), with one warning naming it."""
    folder = path.parent.parent / DAMAGED
    target = folder / f"{path.parent.name}-{path.name}"
    try:
        check_no_link(folder, "--out")  # a planted link would carry the part out of the study folder
        folder.mkdir(exist_ok=True)
        os.replace(path, target)
        where = f"moved to {target}"
    except OSError as exc:  # a read-only copy of a results folder: skipped, left in place
        where = f"skipped (could not move it aside: {exc.strerror or exc})"
    warn(f"{path}: unreadable part ({reason}); {where}; its cells have no row (a resume runs them again)")


def _readable_parts(paths: list[FilePath], schema: pa.Schema, columns: list[str] | None):
    """``(path, table)`` of each readable part of ``paths``; damaged parts are set aside on the way."""
    for path in paths:
        try:
            yield path, _read_part(path, schema, columns)
        except FileNotFoundError:  # removed by a compaction meanwhile: its rows are in the compacted part
            continue
        except DamagedPart as exc:
            set_aside(path, str(exc))


def _last_of_each(table: pa.Table, keys: tuple[str, ...]) -> pa.Table:
    """The table with one row per key, the last one (later parts supersede earlier ones)."""
    if table.num_rows == 0:
        return table
    indexed = table.select(list(keys)).append_column("_row", pa.array(range(table.num_rows), pa.int64()))
    last = indexed.group_by(list(keys), use_threads=False).aggregate([("_row", "max")]).column("_row_max")
    if len(last) == table.num_rows:
        return table
    return table.take(pc.take(last, pc.sort_indices(last)))


def read_table(out_dir: str | os.PathLike, name: str = RUNS, columns: list[str] | None = None) -> pa.Table:
    """All parts of one table, each key once (an empty table with the schema when there is none);
    ``columns`` reads only those (the key columns are always read)."""
    schema = _schema(name)
    keys = KEYS[name]
    if columns is not None:
        columns = list(dict.fromkeys([*keys, *columns]))
    directory = FilePath(out_dir) / name
    names = _part_names(directory)
    parts = [table for _, table in _readable_parts(names, schema, columns)]
    if any(not p.exists() for p in names):  # a compaction replaced parts meanwhile: read the new ones
        parts = [table for _, table in _readable_parts(_part_names(directory), schema, columns)]
    if not parts:
        wanted = [f for f in schema if columns is None or f.name in columns]
        return pa.schema(wanted).empty_table()
    table = pa.concat_tables(parts)
    unique = _last_of_each(table, keys)
    if unique.num_rows < table.num_rows:
        warn(f"{directory}: {table.num_rows - unique.num_rows} duplicate rows of {table.num_rows} "
             f"(the same {'cell' if name == RUNS else 'cell and iteration'} written twice); each key counted once, "
             "the last written kept")
    return unique


def done_hashes(out_dir: str | os.PathLike, except_outcomes: tuple[str, ...] = ()) -> set[str]:
    """Configuration hashes of the cells that already have a row (the last row of each cell, when a cell was
    written twice), leaving out the cells whose row has an outcome in ``except_outcomes``."""
    table = read_table(out_dir, RUNS, ["outcome"])
    if except_outcomes:
        table = table.filter(pc.invert(pc.is_in(table.column("outcome"), pa.array(except_outcomes, pa.string()))))
    return set(table.column("config_hash").to_pylist())


# Columns a report never reads (provenance and raw details kept for the user): left on disk by load_runs.
NOT_REPORTED = ("study", "scenario_ref", "planner_params", "navigator_params", "versions", "plan_extra",
                "run_events")


def load_runs(out_dir: str | os.PathLike, skip: tuple[str, ...] = NOT_REPORTED) -> list[dict[str, Any]]:
    """The run rows as dicts (each cell once), without the ``skip`` columns: only the columns wanted are read
    from the Parquet files, and the dicts are built column by column."""
    return _as_dicts(read_table(out_dir, RUNS, [f.name for f in RUN_SCHEMA if f.name not in skip]))


def _as_dicts(table: pa.Table) -> list[dict[str, Any]]:
    """The rows as dicts, built column by column (faster and leaner than ``Table.to_pylist``)."""
    names = table.column_names
    columns = [table.column(n).to_pylist() for n in names]
    return [dict(zip(names, values)) for values in zip(*columns)]


def load_progress_rows(out_dir: str | os.PathLike) -> list[dict[str, Any]]:
    """The progress rows as dicts (each cell and iteration once), in the order written."""
    return _as_dicts(read_table(out_dir, PROGRESS))


def load_progress(out_dir: str | os.PathLike) -> dict[str, list[tuple[int, float, int, bool]]]:
    """Each cell's best-cost history, ``config_hash -> [(iteration, best_cost, evaluations, estimated)]`` (each
    cell and iteration once), in the order written."""
    progress: dict[str, list[tuple[int, float, int, bool]]] = {}
    for p in load_progress_rows(out_dir):
        progress.setdefault(p["config_hash"], []).append((p["iteration"], p["best_cost"], p["evaluations"],
                                                          bool(p["evaluations_estimated"])))
    return progress


class RowWriter:
    """Buffers finished cells and writes them as part files: the first row at once, then at most every
    ``flush_s`` seconds (or ``max_rows`` runs), and on :meth:`flush`."""

    def __init__(self, out_dir: str | os.PathLike, flush_s: float = 2.0, max_rows: int = 65_536):
        self.out_dir = FilePath(out_dir)
        self.flush_s, self.max_rows = flush_s, max_rows
        self.runs: list[dict[str, Any]] = []
        self.progress: list[dict[str, Any]] = []
        self.last_flush = -math.inf  # the first row is written at once: a study shows its first row early
        self.token = uuid.uuid4().hex[:8]
        self.parts = 0
        for name in (RUNS, PROGRESS):
            contained_folder(self.out_dir / name, "--out")  # a planted link is refused, never written through

    def add(self, row: dict[str, Any], progress: list[dict[str, Any]]) -> None:
        self.runs.append(row)
        self.progress.extend(progress)
        if len(self.runs) >= self.max_rows or time.monotonic() - self.last_flush >= self.flush_s:
            self.flush()

    def _write(self, name: str, rows: list[dict[str, Any]], schema: pa.Schema) -> None:
        final = self.out_dir / name / part_name(self.token, self.parts)
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


def compact(out_dir: str | os.PathLike) -> dict[str, int]:
    """Rewrite each table's parts as a few large parts, each key once; return the parts before, per table.

    Streamed part by part (memory stays that of one row group).  The new parts are written under dot-names,
    renamed into place when all are complete, and only then are the old parts removed: a crash in between
    leaves each row twice, never lost, and the readers keep one of each."""
    before = {}
    for name in (PROGRESS, RUNS):  # progress first: a crash in between never leaves a run without its history
        directory = FilePath(out_dir) / name
        parts = _part_names(directory)
        before[name] = len(parts)
        if len(parts) > 1:
            _compact_table(directory, name, parts)
    return before


def _compact_table(directory: FilePath, name: str, parts: list[FilePath]) -> None:
    schema, token = _schema(name), uuid.uuid4().hex[:8]
    owner: set[str] = set()  # cells already taken from a later part (the last written row wins)
    finished: list[FilePath] = []
    writer: pq.ParquetWriter | None = None
    rows_in_file, pending_rows = 0, 0

    def write(tables: list[pa.Table]) -> None:
        nonlocal writer, rows_in_file
        table = pa.concat_tables(tables)
        if writer is None or rows_in_file + table.num_rows > COMPACT_FILE_ROWS:
            if writer is not None:
                writer.close()
            final = directory / part_name(token, len(finished))
            finished.append(final)
            writer, rows_in_file = pq.ParquetWriter(directory / ("." + final.name), schema), 0
        writer.write_table(table, row_group_size=COMPACT_GROUP_ROWS)
        rows_in_file += table.num_rows

    kept: list[pa.Table] = []
    seen: set[str] = set()  # cells already taken from a newer part: the last written row of a cell wins
    readable = []
    for path, table in _readable_parts(list(reversed(parts)), schema, None):
        readable.append(path)
        hashes = pc.unique(table.column("config_hash")).to_pylist()
        new = [h for h in hashes if h not in seen]
        seen.update(new)
        if len(new) < len(hashes):
            table = table.filter(pc.is_in(table.column("config_hash"), pa.array(new, pa.string())))
        table = _last_of_each(table, KEYS[name])
        if table.num_rows:
            kept.append(table)
            pending_rows += table.num_rows
        if pending_rows >= COMPACT_GROUP_ROWS:
            write(kept)
            kept, pending_rows = [], 0
    if kept or writer is None:
        write(kept or [schema.empty_table()])
    writer.close()
    for final in finished:
        os.replace(final.with_name("." + final.name), final)
    for path in readable:
        path.unlink(missing_ok=True)
