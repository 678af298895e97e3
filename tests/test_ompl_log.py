"""``swarmnav report DIR --ompl-log OUT``: a real study's rows as OMPL benchmark logs, read back by OMPL's own
``ompl_benchmark_statistics`` (the console script of the ``ompl`` wheel) into its SQLite database."""

from __future__ import annotations

import json
import math
import sqlite3
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from swarmnav.models.scenario import load_scenario
from swarmnav.planners.problem import scenario_problem
from swarmnav.cli import main as cli
from swarmnav.study.rows import PROGRESS, RUNS, read_table

STUDY = """
name = "ompl export"
scenarios = ["gwo-scenario-1", "restaurant-table-2", "adl-abc-path-1"]
mode = "plan"
seeds = 2
reference = "gwo"

[[planners]]
name = "gwo"
params = { population = 10, iterations = 8, mode = "robust" }   # the paper mode ends inside a disc here

[[planners]]
name = "rrt_star"
params = { max_evaluations = 600, round_evaluations = 100 }

[[planners]]
name = "rrt_star"
label = "rrt_star-more"
params = { max_evaluations = 900, round_evaluations = 100 }

[[planners]]
name = "optimal"
"""


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """A study run for real, reported with --ompl-log, and the database OMPL's script builds from the logs."""
    folder = tmp_path_factory.mktemp("ompl-export")
    (folder / "study.toml").write_text(STUDY)
    assert cli.main(["study", str(folder / "study.toml"), "--out", str(folder / "out")]) == 0
    assert cli.main(["report", str(folder / "out"), "--ompl-log", str(folder / "logs")]) == 0
    logs = sorted((folder / "logs").glob("*.log"))
    script = Path(sys.executable).with_name("ompl_benchmark_statistics")
    subprocess.run([str(script), *map(str, logs), "-d", str(folder / "bench.db")], check=True,
                   capture_output=True, text=True)
    return folder, sqlite3.connect(folder / "bench.db")


def test_one_experiment_per_scenario_one_config_per_label_one_run_per_row(exported):
    folder, db = exported
    rows = read_table(folder / "out", RUNS).to_pylist()
    assert len(rows) == 3 * 4 * 2
    experiments = dict(db.execute("SELECT id, name FROM experiments"))
    assert sorted(experiments.values()) == sorted(f"ompl_export.{s}" for s in {r["scenario"] for r in rows})
    configs = dict(db.execute("SELECT id, name FROM plannerConfigs"))
    assert sorted(configs.values()) == sorted({r["label"] for r in rows})
    runs = db.execute("SELECT experimentid, plannerid, seed, solved, solution_length, time, evaluations, "
                      "solution_clearance FROM runs").fetchall()
    assert len(runs) == len(rows)
    by_key = {(f"ompl_export.{r['scenario']}", r["label"], r["seed"]): r for r in rows}
    seen = set()
    for experiment, planner, seed, solved, length, time_s, evaluations, clearance in runs:
        key = (experiments[experiment], configs[planner], seed)
        row = by_key[key]
        seen.add(key)
        assert bool(solved) == (row["outcome"] == "ok" and bool(row["plan_waypoints"]))  # a plan was found
        if solved:
            assert length == pytest.approx(row["plan_length_m"], rel=1e-12)
            assert time_s == pytest.approx(row["plan_time_s"], rel=1e-12)
            assert evaluations == row["plan_evaluations"]
            problem = scenario_problem(load_scenario(row["scenario"]), clearance_m=0.0)
            exact = problem.path_clearance_m(np.array(json.loads(row["plan_waypoints"])))
            assert clearance == pytest.approx(exact, abs=1e-9)
        else:
            assert length is None and clearance is None      # no plan: empty measurements
    assert len(seen) == len(rows)
    # the paper scenario without a collision-free path: every planner's rows are failures, still runs
    assert not any(r["success"] for r in rows if r["scenario"] == "adl-abc-path-1")


def test_the_best_cost_histories_are_progress_properties(exported):
    folder, db = exported
    rows = {r["config_hash"]: r for r in read_table(folder / "out", RUNS).to_pylist()}
    history: dict[str, list[dict]] = {}
    for p in read_table(folder / "out", PROGRESS).to_pylist():
        history.setdefault(p["config_hash"], []).append(p)
    expected = sorted((r["scenario"], r["label"], r["seed"], len(history[h]))
                      for h, r in rows.items() if history.get(h) and r["plan_time_s"] is not None)
    got = db.execute("""SELECT e.name, c.name, r.seed, COUNT(p.runid), MIN(p.evaluations), MAX(p.evaluations),
                               MIN(p.time), MAX(p.time), r.time
                        FROM progress p JOIN runs r ON p.runid = r.id JOIN experiments e ON r.experimentid = e.id
                        JOIN plannerConfigs c ON r.plannerid = c.id GROUP BY p.runid""").fetchall()
    assert sorted((e.split(".", 1)[1], c, s, n) for e, c, s, n, *_ in got) == expected
    assert any(c.startswith("rrt_star") for _, c, *_ in got) and any(c == "gwo" for _, c, *_ in got)
    for *_, low_evals, high_evals, low_time, high_time, run_time in got:
        assert low_evals < high_evals and 0 <= low_time < high_time == pytest.approx(run_time, rel=1e-12)
    # rrt_star's history starts before its first path: that best cost is inf in swarmnav, NULL in the database
    nulls = db.execute("""SELECT COUNT(*) FROM progress p JOIN runs r ON p.runid = r.id
                          JOIN plannerConfigs c ON r.plannerid = c.id
                          WHERE c.name = 'rrt_star' AND p.best_cost IS NULL""").fetchone()[0]
    assert nulls >= 1
    finals = db.execute("""SELECT r.solution_length, p.best_cost FROM progress p JOIN runs r ON p.runid = r.id
                           JOIN plannerConfigs c ON r.plannerid = c.id
                           WHERE c.name LIKE 'rrt_star%' AND r.solved = 1 AND p.evaluations = r.evaluations""")
    for length, best in finals.fetchall():
        assert math.isclose(length, best, rel_tol=1e-9)


def test_a_missing_study_is_one_line(tmp_path, capsys):
    code = cli.main(["report", str(tmp_path), "--ompl-log", str(tmp_path / "logs")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
