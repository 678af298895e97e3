"""Plugins in a study's workers through ``swarmnav.run_study`` in a user's script, and a script that calls it at
its top level without a main guard (each spawned worker would run the script again)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd

from plugin_dist import PLUGIN_STUDY, example_plugin, python_path


def _script(tmp_path: Path, body: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    script = tmp_path / "lab_study.py"
    script.write_text(textwrap.dedent(body))
    return subprocess.run([sys.executable, str(script)], capture_output=True, text=True, cwd=tmp_path,
                          env={**os.environ, **(env or {})}, timeout=300)


def test_run_study_in_a_script_knows_the_plugins_in_its_workers(tmp_path):
    (tmp_path / "plugin-study.toml").write_text(PLUGIN_STUDY)
    done = _script(tmp_path, """
        import json, pandas, swarmnav

        if __name__ == "__main__":
            summary = swarmnav.run_study("plugin-study.toml", "rows", workers=2)
            rows = pandas.read_parquet("rows/runs.parquet")
            by = rows.groupby(["planner", "scenario", "outcome"]).size()
            print(json.dumps({"outcomes": summary["outcomes"], "by": {" ".join(k): int(v) for k, v in by.items()}}))
        """, python_path(*example_plugin(tmp_path / "site")))
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    assert out["outcomes"] == {"ok": 8}
    assert out["by"] == {f"{p} {s} ok": 2 for p in ("astar", "random_detour")
                         for s in ("gwo-scenario-3", "plugin-corridor")}


def test_run_study_at_a_scripts_top_level_stops_at_once_with_one_line(tmp_path):
    done = _script(tmp_path, """
        import swarmnav
        summary = swarmnav.run_study("gwo-vs-abc", "rows", workers=2, quick=True)
        print(summary)
        """)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.count("\n") == 1, done.stderr
    assert "lab_study.py:3" in done.stderr and 'if __name__ == "__main__":' in done.stderr
    assert not (tmp_path / "rows").exists()  # nothing started


def test_a_planner_registered_only_in_the_driver_ends_the_study_without_error_rows(tmp_path):
    done = _script(tmp_path, """
        import swarmnav
        from swarmnav.study.cell import ComponentMissing

        if __name__ == "__main__":
            from swarmnav.planners.straight import StraightPlanner

            @swarmnav.register_planner
            class Mine(StraightPlanner):  # registered in this process only: the spawned workers do not know it
                name = "mine"

            tables = {"name": "mine", "scenarios": ["gwo-scenario-3"], "seeds": 2, "planners": [{"name": "mine"}]}
            try:
                swarmnav.run_study(tables, "rows", workers=1)
            except ComponentMissing as exc:
                print(exc)
        """)
    assert done.returncode == 0, done.stderr
    assert "a worker does not know the planner 'mine'" in done.stdout
    assert len(pd.read_parquet(tmp_path / "rows" / "runs.parquet")) == 0  # no row, no error row
