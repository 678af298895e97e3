"""Studies survive their workers, their folder is written by one study at a time, and damaged or duplicated
parts are set aside or counted once: every case on real worker processes and real Parquet files."""

import dataclasses
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from swarmnav.cli.main import main
from swarmnav.study.execute import run_study
from swarmnav.study.grid import expand
from swarmnav.study.rows import RUNS, RowWriter, compact, read_table
from swarmnav.study.spec import Component, load_study, parse_study

TESTS_DIR = str(Path(__file__).parent)
PHYSICS = ('name = "{name}"\nscenarios = ["gwo-scenario-1", "restaurant-table-2"]\nmode = "physics"\n'
           'time_limit_s = {limit}\nseeds = {seeds}\n[[planners]]\nname = "astar"\n')
PLAN = 'name = "plan"\nscenarios = ["gwo-scenario-1", "gwo-scenario-2"]\nseeds = 6\n[[planners]]\nname = "astar"\n'


def parts(out: Path) -> list[Path]:
    return sorted((out / RUNS).glob("*.parquet"))


def rows_of(out: Path) -> list[dict]:
    return pq.read_table(out / RUNS).to_pylist()


def test_cells_that_kill_their_worker_are_error_rows_and_the_study_goes_on(tmp_path, monkeypatch):
    """Half the cells run a policy that calls os._exit(3) at its first step: each is an error row naming the
    exit code, every other cell is a row, a resume runs nothing, --retry-errors runs only the error cells."""
    monkeypatch.syspath_prepend(TESTS_DIR)  # spawned workers start with this process's sys.path
    study = parse_study(PHYSICS.format(name="dying", limit=2.0, seeds=3))
    dying = Component(name="policy", label="dying", params={"policy": "dying_policy:act"}, swept=())
    study = dataclasses.replace(study, navigators=(study.navigators[0], dying))
    summary = run_study(study, tmp_path, workers=2)
    assert summary["ran"] == 12 and summary["outcomes"] == {"ok": 6, "error": 6}, summary
    rows = rows_of(tmp_path)
    assert len(rows) == 12 and len({r["config_hash"] for r in rows}) == 12
    for row in rows:
        if row["navigator_label"] == "dying":
            assert row["outcome"] == "error" and row["error"] == "the worker running this cell died (exit code 3)"
        else:
            assert row["outcome"] == "ok" and row["sim_time_s"] > 0
    assert run_study(study, tmp_path, workers=2)["ran"] == 0
    again = run_study(study, tmp_path, workers=2, retry_errors=True)
    assert again["ran"] == 6 and again["outcomes"] == {"error": 6} and again["skipped"] == 6
    assert len(rows_of(tmp_path)) == 12 and len(parts(tmp_path)) == 1  # compacted, each cell once


def _workers_of(pid: int) -> list[int]:
    children = Path(f"/proc/{pid}/task/{pid}/children").read_text().split()
    return [int(c) for c in children
            if b"multiprocessing.spawn" in Path(f"/proc/{c}/cmdline").read_bytes()
            and b"resource_tracker" not in Path(f"/proc/{c}/cmdline").read_bytes()]


def test_a_worker_killed_from_outside_is_one_error_row_and_the_study_finishes(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(PHYSICS.format(name="killed", limit=3.0, seeds=4))
    out = tmp_path / "out"
    command = [sys.executable, "-m", "swarmnav.cli", "study", str(path), "--out", str(out), "--workers", "2"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not parts(out) and time.monotonic() < deadline:  # a first row: the workers are running cells
        time.sleep(0.05)
    victim = _workers_of(process.pid)[0]
    os.kill(victim, signal.SIGKILL)
    stdout, stderr = process.communicate(timeout=300)
    assert process.returncode == 0, stderr
    assert "8 cells" in stdout and "1 failed (error 1)" in stdout
    rows = rows_of(out)
    assert len(rows) == 8 and len({r["config_hash"] for r in rows}) == 8
    errors = [r for r in rows if r["outcome"] != "ok"]
    assert [r["error"] for r in errors] == ["the worker running this cell died (killed by signal SIGKILL)"]
    assert main(["study", str(path), "--out", str(out), "--json"]) == 0  # a resume runs nothing
    assert len(rows_of(out)) == 8


def test_a_second_study_into_a_folder_in_use_exits_2_naming_it_and_the_holder(tmp_path, capsys):
    path = tmp_path / "study.toml"
    path.write_text(PHYSICS.format(name="locked", limit=2.0, seeds=3))
    out = tmp_path / "out"
    command = [sys.executable, "-m", "swarmnav.cli", "study", str(path), "--out", str(out), "--workers", "1",
               "--json"]
    first = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not (out / ".lock").exists() or not (out / ".lock").read_text().strip():
        assert time.monotonic() < deadline
        time.sleep(0.02)
    started = time.monotonic()
    assert main(["study", str(path), "--out", str(out), "--workers", "1"]) == 2
    assert time.monotonic() - started < 5  # at once, not after the first one
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(out) in err and f"PID {first.pid}" in err
    stdout, _ = first.communicate(timeout=300)
    assert first.returncode == 0 and json.loads(stdout)["ran"] == 6
    rows = rows_of(out)
    assert len(rows) == 6 and len({r["config_hash"] for r in rows}) == 6
    assert main(["study", str(path), "--out", str(out), "--json"]) == 0  # released by the first at its end


def test_the_lock_of_a_killed_study_is_released(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(PHYSICS.format(name="killed-holder", limit=2.0, seeds=3))
    out = tmp_path / "out"
    holder = subprocess.Popen([sys.executable, "-m", "swarmnav.cli", "study", str(path), "--out", str(out),
                               "--workers", "1"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while not (out / ".lock").exists() or not (out / ".lock").read_text().strip():
        assert time.monotonic() < deadline
        time.sleep(0.02)
    holder.send_signal(signal.SIGKILL)
    holder.wait()
    assert main(["study", str(path), "--out", str(out), "--workers", "2", "--json"]) == 0
    assert len(rows_of(out)) == 6


@pytest.fixture()
def plan_folder(tmp_path):
    """A finished plan-only study of 12 cells, its rows split over two parts by hand."""
    path = tmp_path / "plan.toml"
    path.write_text(PLAN)
    out = tmp_path / "out"
    assert main(["study", str(path), "--out", str(out), "--workers", "2", "--json"]) == 0
    [single] = parts(out)
    table = pq.read_table(single)
    single.unlink()
    pq.write_table(table.slice(0, 8), out / RUNS / "part-a.parquet")
    pq.write_table(table.slice(8), out / RUNS / "part-b.parquet")
    return path, out, table


def test_damaged_parts_are_set_aside_reported_on_and_their_cells_run_again(plan_folder, capsys):
    path, out, table = plan_folder
    lost = set(table.slice(8).column("config_hash").to_pylist())
    data = (out / RUNS / "part-b.parquet").read_bytes()
    (out / RUNS / "part-b.parquet").write_bytes(data[: len(data) // 2])  # truncated
    (out / RUNS / "part-c.parquet").write_bytes(b"")  # empty
    pq.write_table(pa.table({"x": [1, 2]}), out / RUNS / "part-d.parquet")  # another table's
    capsys.readouterr()
    assert main(["report", str(out)]) == 0
    warnings = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert len(warnings) == 3
    for name in ("part-b", "part-c", "part-d"):
        assert sum(name in w for w in warnings) == 1
        assert (out / "damaged" / f"runs.parquet-{name}.parquet").exists()
    assert "8 runs" in (out / "report.md").read_text()
    assert main(["study", str(path), "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["ran"] == 4 and summary["skipped"] == 8
    rows = rows_of(out)
    assert len(rows) == 12 and {r["config_hash"] for r in rows} >= lost and len(parts(out)) == 1


def test_duplicated_rows_are_counted_once_and_said_so(plan_folder, capsys):
    path, out, table = plan_folder
    pq.write_table(table, out / RUNS / "part-c.parquet")  # every row again, as two writers would leave it
    capsys.readouterr()
    assert main(["report", str(out)]) == 0
    err = capsys.readouterr().err
    assert "12 duplicate rows of 24" in err
    assert "12 runs" in (out / "report.md").read_text()
    assert main(["study", str(path), "--out", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["ran"] == 0
    assert len(rows_of(out)) == 12 and len(parts(out)) == 1  # the finished study compacted them away


def test_compaction_keeps_each_cell_once_the_last_written(tmp_path):
    """Forty parts of one row each, a cell written twice with different outcomes: one part, twelve rows, the
    later row of the cell written twice, the same rows as before otherwise."""
    cells = expand(parse_study(PLAN))
    writer = RowWriter(tmp_path, flush_s=0.0)
    base = {"study": "plan", "mode": "plan", "seed": 0}
    for i, cell in enumerate(cells + cells[:1]):
        outcome = "error" if i == 0 else "ok"
        writer.add({**base, "config_hash": cell.config_hash, "outcome": outcome, "seed": cell.seed},
                   [{"config_hash": cell.config_hash, "iteration": 0, "best_cost": float(i)}])
    writer.flush()
    assert len(parts(tmp_path)) == 13
    before = read_table(tmp_path).sort_by("config_hash")
    assert compact(tmp_path) == {"progress.parquet": 13, "runs.parquet": 13}
    assert len(parts(tmp_path)) == 1
    after = read_table(tmp_path).sort_by("config_hash")
    assert after.num_rows == 12 and after.equals(before)
    first = [r for r in after.to_pylist() if r["config_hash"] == cells[0].config_hash]
    assert [r["outcome"] for r in first] == ["ok"]
    progress = read_table(tmp_path, "progress.parquet").to_pylist()
    assert len(progress) == 12 and {p["best_cost"] for p in progress if p["config_hash"] == cells[0].config_hash} == {12.0}


def test_cliffs_delta_counts_every_pair_with_ties():
    import numpy as np

    from swarmnav.study.statistics import cliffs_delta
    rng = np.random.default_rng(7)
    for n, m in ((1, 1), (5, 9), (40, 33)):
        a, b = rng.integers(0, 6, n).astype(float), rng.integers(0, 6, m).astype(float)  # many ties
        pairs = [int(x > y) - int(x < y) for x in a for y in b]
        assert cliffs_delta(a, b) == pytest.approx(sum(pairs) / len(pairs), abs=1e-15)


def test_a_batch_sent_to_a_worker_that_just_died_stays_queued_for_the_next_worker():
    """The driver can send to a worker that died after its last wait (a broken pipe): the batch stays in the
    worker's queue, where the death handling finds it, instead of ending the study with BrokenPipeError."""
    import multiprocessing

    from swarmnav.study.engines import _LocalWorker
    study = parse_study(PHYSICS.format(name="late", limit=2.0, seeds=1))
    cells = list(expand(study))[:2]
    worker = _LocalWorker(multiprocessing.get_context("spawn"), None)
    worker.process.kill()
    worker.process.join()
    for _ in range(50):  # the first sends may still fill the pipe's buffer; a broken pipe comes soon
        worker.send(cells)
    assert len(worker.queued) == 100 and list(worker.queued)[:2] == cells
    worker.stop(terminate=True)
