"""The Ray engine on a real local instance (2 CPUs): the local engine's rows, timings aside; the wall limit
enforced inside a task; no token-authentication warning at start-up."""

import logging

import pandas as pd
import pytest

from swarmnav.sim.study.engines import RAY_AUTH_LOGGER, start_ray
from swarmnav.sim.study.execute import run_study
from swarmnav.sim.study.rows import TIMING_COLUMNS
from swarmnav.sim.study.spec import parse_study

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
def ray_start_log():
    """Start one local instance for the module; yield what Ray's authentication set-up logged meanwhile."""
    if ray.is_initialized():
        pytest.skip("a Ray instance is already running in this process")
    records = _Records()
    logger = logging.getLogger(RAY_AUTH_LOGGER)
    logger.addHandler(records)
    try:
        start_ray(None, 2)
    finally:
        logger.removeHandler(records)
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
    progress = [pd.read_parquet(tmp_path / d / "progress.parquet").sort_values(["config_hash", "iteration"])
                .reset_index(drop=True) for d in ("local", "ray")]
    pd.testing.assert_frame_equal(progress[0], progress[1])


def test_the_wall_limit_interrupts_a_ray_task(ray_start_log, tmp_path):
    # 20000 GWO iterations take minutes; a Ray task runs on its worker's main thread, where the timer is armed.
    study = parse_study('name = "ray-wall"\nscenarios = ["gwo-scenario-1"]\nwall_limit_s = 1.0\n'
                        '[[planners]]\nname = "gwo"\nparams = { population = 50, iterations = 20000 }\n')
    assert run_study(study, tmp_path, engine="ray", workers=2)["outcomes"] == {"timeout": 1}
    row = pd.read_parquet(tmp_path / "runs.parquet").iloc[0]
    assert row.error == "exceeded the wall limit of 1 s" and row.cell_wall_s < 5
