"""The Ray engine on a real local instance (2 CPUs) gives the local engine's rows, timings aside."""

import pandas as pd
import pytest

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
params = { population = 10, iterations = 10 }
"""


def test_ray_rows_equal_local_rows(tmp_path):
    study = parse_study(STUDY)
    local = run_study(study, tmp_path / "local", engine="local", workers=2)
    try:
        on_ray = run_study(study, tmp_path / "ray", engine="ray", workers=2)
    finally:
        ray.shutdown()
    assert local["ran"] == on_ray["ran"] == 8
    frames = [pd.read_parquet(tmp_path / d / "runs.parquet").drop(columns=list(TIMING_COLUMNS))
              .sort_values("config_hash").reset_index(drop=True) for d in ("local", "ray")]
    pd.testing.assert_frame_equal(frames[0], frames[1])
    progress = [pd.read_parquet(tmp_path / d / "progress.parquet").sort_values(["config_hash", "iteration"])
                .reset_index(drop=True) for d in ("local", "ray")]
    pd.testing.assert_frame_equal(progress[0], progress[1])
