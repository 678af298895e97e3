"""The Ray engine on a real local instance (2 CPUs): the local engine's rows, timings aside; the wall limit
enforced inside a task; no token-authentication warning at start-up; a task whose worker dies (by its own
hand or killed from outside) is an error row and the study goes on."""

import dataclasses
import json
import logging
import os
import signal
import threading
import time
from pathlib import Path

import pandas as pd
import pytest

from swarmnav.study.ray_engine import RAY_AUTH_LOGGER, start_ray
from swarmnav.study.execute import run_study
from swarmnav.study.rows import PROGRESS_TIMING_COLUMNS, TIMING_COLUMNS
from swarmnav.study.spec import parse_study

from plugin_dist import PLUGIN_STUDY, dist_info, example_plugin, python_path

ray = pytest.importorskip("ray", reason="the ray extra is not installed (pip install 'swarmnav[ray]')")

STUDY = """
name = "ray-vs-local"
scenarios = ["restaurant-table-2", "gwo-scenario-1"]
mode = "physics"
time_limit_s = 3.0
seeds = [0, 1]
[[planners]]
name = "astar"
[[planners]]
name = "gwo"
params = { population = 10, iterations = 10, mode = "robust" }   # the paper mode ends inside a disc here
"""


class _Records(logging.Handler):
    def __init__(self):
        super().__init__()
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage())


@pytest.fixture(scope="module")
def plugin_site(tmp_path_factory) -> list[str]:
    """The path entries of the example plugin (``plugin_dist``), installed on the instance's workers."""
    return example_plugin(tmp_path_factory.mktemp("plugin-site"))


@pytest.fixture(scope="module")
def ray_start_log(plugin_site):
    """Start one local instance for the module; yield what Ray's authentication set-up logged meanwhile."""
    if ray.is_initialized():
        pytest.skip("a Ray instance is already running in this process")
    records = _Records()
    logger = logging.getLogger(RAY_AUTH_LOGGER)
    logger.addHandler(records)
    saved = os.environ.get("PYTHONPATH")
    # the instance's workers inherit this environment: they can import the tests' dying policy, and they have
    # the example plugin installed (this process does not load it: its registries stay the bundled ones)
    os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (str(Path(__file__).parent), *plugin_site, saved) if p)
    try:
        start_ray(None, 2)
    finally:
        logger.removeHandler(records)
        if saved is None:
            os.environ.pop("PYTHONPATH")
        else:
            os.environ["PYTHONPATH"] = saved
    yield records.messages
    ray.shutdown()


def test_a_local_instance_starts_without_the_token_warning(ray_start_log):
    assert ray.is_initialized()
    assert not [m for m in ray_start_log if "Token authentication is enabled" in m]


def test_ray_rows_equal_local_rows(ray_start_log, tmp_path):
    study = parse_study(STUDY)
    local = run_study(study, tmp_path / "local", engine="local", workers=2)
    on_ray = run_study(study, tmp_path / "ray", engine="ray", workers=2)
    assert local["ran"] == on_ray["ran"] == 8
    frames = [pd.read_parquet(tmp_path / d / "runs.parquet").drop(columns=list(TIMING_COLUMNS))
              .sort_values("config_hash").reset_index(drop=True) for d in ("local", "ray")]
    pd.testing.assert_frame_equal(frames[0], frames[1])
    progress = [pd.read_parquet(tmp_path / d / "progress.parquet").drop(columns=list(PROGRESS_TIMING_COLUMNS))
                .sort_values(["config_hash", "iteration"]).reset_index(drop=True) for d in ("local", "ray")]
    pd.testing.assert_frame_equal(progress[0], progress[1])


def test_the_wall_limit_interrupts_a_ray_task(ray_start_log, tmp_path):
    # 20000 GWO iterations take minutes; a Ray task runs on its worker's main thread, where the timer is armed.
    study = parse_study('name = "ray-wall"\nscenarios = ["gwo-scenario-1"]\nwall_limit_s = 1.0\n'
                        '[[planners]]\nname = "gwo"\nparams = { population = 50, iterations = 20000 }\n')
    assert run_study(study, tmp_path, engine="ray", workers=2)["outcomes"] == {"timeout": 1}
    row = pd.read_parquet(tmp_path / "runs.parquet").iloc[0]
    assert row.error == "exceeded the wall limit of 1 s" and row.cell_wall_s < 5


def test_ray_tasks_that_kill_their_worker_are_error_rows(ray_start_log, tmp_path):
    from swarmnav.study.spec import Component
    study = parse_study(STUDY.replace('seeds = [0, 1]', 'seeds = [0]'))
    dying = Component(name="policy", label="dying", params={"policy": "dying_policy:act"}, swept=())
    study = dataclasses.replace(study, navigators=(study.navigators[0], dying))
    summary = run_study(study, tmp_path, engine="ray", workers=2)
    assert summary["ran"] == 8 and summary["outcomes"] == {"ok": 4, "error": 4}, summary
    rows = pd.read_parquet(tmp_path / "runs.parquet")
    dead = rows[rows.navigator_label == "dying"]
    assert (dead.outcome == "error").all()
    assert dead.error.str.endswith("1 try, Ray's own retries are off)").all()
    assert (rows[rows.navigator_label != "dying"].outcome == "ok").all()
    assert run_study(study, tmp_path, engine="ray", workers=2)["ran"] == 0


def processes_with(text: str) -> list[int]:
    """PIDs of this machine's processes whose command line contains ``text`` (from /proc)."""
    pids = []
    for entry in Path("/proc").iterdir():
        try:
            if entry.name.isdigit() and text.encode() in (entry / "cmdline").read_bytes():
                pids.append(int(entry.name))
        except OSError:  # ended meanwhile
            continue
    return pids


def test_a_ray_worker_killed_from_outside_is_one_error_row(ray_start_log, tmp_path, monkeypatch):
    # One cell per task, as for cells long enough to travel alone: a killed batch of several quick cells runs
    # again one cell per task (the killed cell then succeeds), which the next test's self-killing cells cover.
    from swarmnav.study import engines
    monkeypatch.setattr(engines.BatchSizer, "size", lambda self: 1)
    # The straight line runs into gwo-scenario-1's first disc and stays there to the time limit: every cell
    # takes the same, long enough (2,000 control steps) to be killed inside it on a quiet machine too.
    study = parse_study('name = "killed"\nscenarios = ["gwo-scenario-1"]\nmode = "physics"\ntime_limit_s = 40.0\n'
                        'seeds = 8\n[[planners]]\nname = "straight"\n')
    killed: list[int] = []

    def kill_one_task() -> None:
        deadline = time.monotonic() + 120
        while not killed and time.monotonic() < deadline:
            for pid in processes_with("ray::run_batch"):
                time.sleep(0.1)  # inside its cell by now
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
                return
            time.sleep(0.05)
    killer = threading.Thread(target=kill_one_task)
    killer.start()
    summary = run_study(study, tmp_path, engine="ray", workers=2)
    killer.join()
    assert killed and summary["ran"] == 8 and summary["outcomes"] == {"ok": 7, "error": 1}, summary
    rows = pd.read_parquet(tmp_path / "runs.parquet")
    assert len(rows) == 8 and rows.config_hash.is_unique
    error = rows[rows.outcome == "error"].error.iloc[0]
    assert error.startswith("the worker running this cell died (WorkerCrashedError")
    assert error.endswith("1 try, Ray's own retries are off)")


def _study_on_the_instance(tmp_path: Path, env: dict[str, str]):
    """``swarmnav study`` of the plugin study, a driver of its own joining this module's instance."""
    import subprocess
    import sys
    (tmp_path / "plugin-study.toml").write_text(PLUGIN_STUDY)
    address = ray.get_runtime_context().gcs_address
    return subprocess.run([sys.executable, "-m", "swarmnav.cli", "study", "plugin-study.toml", "--out", "rows",
                           "--engine", "ray", "--address", address, "--json"], capture_output=True, text=True,
                          cwd=tmp_path, env={**os.environ, **env}, timeout=300)


def test_a_plugin_planner_and_scenario_run_on_ray_workers(ray_start_log, plugin_site, tmp_path):
    done = _study_on_the_instance(tmp_path, python_path(*plugin_site))
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["outcomes"] == {"ok": 8}
    rows = pd.read_parquet(tmp_path / "rows" / "runs.parquet")
    assert rows.groupby(["planner", "scenario", "outcome"]).size().to_dict() == {
        (planner, scenario, "ok"): 2 for planner in ("astar", "random_detour")
        for scenario in ("gwo-scenario-3", "plugin-corridor")}


def test_a_plugin_missing_on_the_ray_workers_fails_the_study_naming_it(ray_start_log, plugin_site, tmp_path):
    # the driver has one more plugin distribution than the instance's workers
    dist_info(tmp_path / "extra", "lab-extra-plugin", "2.1", {"swarmnav.planners": {"astar2": "lab_extra:Astar2"}})
    (tmp_path / "extra" / "lab_extra.py").write_text(
        "from swarmnav.planners.grid_search import AStarPlanner\n\nclass Astar2(AStarPlanner):\n    name = 'astar2'\n")
    done = _study_on_the_instance(tmp_path, python_path(str(tmp_path / "extra"), *plugin_site))
    said = [line for line in done.stderr.splitlines() if line.startswith("swarmnav:")]  # Ray logs its connection
    assert done.returncode == 2 and len(said) == 1, done.stderr
    assert "plugins: lab-extra-plugin not installed (driver 2.1)" in said[0] and "--address: node " in said[0]
    assert len(pd.read_parquet(tmp_path / "rows" / "runs.parquet")) == 0  # no error rows


def test_sigterm_ends_a_ray_study_with_one_line_and_keeps_its_rows(tmp_path):
    import subprocess
    import sys
    path = tmp_path / "study.toml"
    path.write_text('name = "terminated"\nscenarios = ["gwo-scenario-1", "gwo-scenario-2"]\nseeds = 400\n'
                    '[[planners]]\nname = "astar"\n')
    out = tmp_path / "out"
    command = [sys.executable, "-m", "swarmnav.cli", "study", str(path), "--out", str(out)]
    process = subprocess.Popen(command + ["--engine", "ray", "--workers", "2"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not list((out / "runs.parquet").glob("part-*.parquet")) and time.monotonic() < deadline:
        time.sleep(0.05)
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 128 + signal.SIGTERM, err[-4000:]
    assert "SIGTERM received" not in err and "PC: @" not in err and "Traceback" not in err
    assert [line for line in err.splitlines() if line.startswith("swarmnav:")] == [
        f"swarmnav: study stopped (SIGTERM); the rows of the finished cells are kept in {out}: run the same command "
        "to resume"]
    kept = len(pd.read_parquet(out / "runs.parquet"))
    assert 0 < kept < 800
    subprocess.run(command + ["--workers", "2"], check=True, capture_output=True, timeout=300)
    rows = pd.read_parquet(out / "runs.parquet")
    assert len(rows) == 800 and rows.config_hash.is_unique


def test_bench_navigation_on_ray_gives_the_local_table(ray_start_log, tmp_path):
    """``bench navigation --engine ray``: the same runs as the local engine, so the same table, timings aside."""
    from swarmnav.benchmarks.navigation import benchmark_navigation
    from swarmnav.models.scenario_generator import GeneratorOptions, generate
    path = tmp_path / "short.toml"
    path.write_text(generate("crossing", 5, GeneratorOptions(obstacles=2, arena_m=5.0, sensor_model="detector")))
    tables = [benchmark_navigation(1, ["follow", "velocity_obstacle"], [str(path)], out_dir=str(tmp_path / d),
                                   speed=False, workers=2, engine=engine)
              for d, engine in (("local", "local"), ("ray", "ray"))]
    kept = ("navigator", "runs", "success_rate", "collision_rate", "timeout_rate", "mean_spl", "solved_share",
            "time_score", "oracle_solvable_runs")
    assert [{k: r.get(k) for k in kept} for r in tables[0]] == [{k: r.get(k) for k in kept} for r in tables[1]]
    assert [r["navigator"] for r in tables[1]] == ["follow", "velocity_obstacle", "oracle"]
