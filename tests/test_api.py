"""The Python API (``import swarmnav``), plugins by entry points, given paths and the CI checks."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import swarmnav
from swarmnav.cli.main import EXIT_EXPECTATION, main

from plugin_dist import PLUGIN_STUDY, dist_info, example_plugin, python_path

ROOT = Path(__file__).resolve().parent.parent
WALL_CLOCK = {"wall_time_s", "replan_wall_s", "plan_time_s"}


def _swarmnav(*args: str, env: dict[str, str] | None = None, cwd: Path | None = None):
    return subprocess.run([sys.executable, "-m", "swarmnav.cli", *args], capture_output=True, text=True,
                          env={**os.environ, **(env or {})}, cwd=cwd, timeout=600)


def _without_wall_clock(value):
    if isinstance(value, dict):
        return {k: _without_wall_clock(v) for k, v in value.items() if k not in WALL_CLOCK}
    return value


def test_import_swarmnav_is_light_and_public():
    code = ("import sys, swarmnav; "
            "print(sorted(m for m in ('mujoco', 'scipy', 'dm_control') if m in sys.modules)); "
            "print(callable(swarmnav.run), callable(swarmnav.plan), swarmnav.Problem.__name__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split("\n")
    assert out[0] == "[]"
    assert out[1] == "True True Problem"


def test_a_folder_named_swarmnav_in_the_working_directory(tmp_path):
    (tmp_path / "swarmnav" / "models").mkdir(parents=True)  # a clone of the repository, say
    # installed as `make install` does (the package on the path): the installed package wins
    done = subprocess.run([sys.executable, "-c", "import swarmnav; print(callable(swarmnav.run))"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=60)
    assert done.stdout.strip() == "True", done.stderr
    # with the editable install's import hook alone the folder shadows the package: one line naming it, exit 2
    hook_only = "import sys; sys.path = [p for p in sys.path if not p.endswith('/typing')]; import swarmnav.cli.main"
    done = subprocess.run([sys.executable, "-c", hook_only], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    if "shadows" not in done.stderr and done.returncode == 0:
        pytest.skip("swarmnav is not an editable install here: nothing can shadow it")
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert f"the folder {tmp_path / 'swarmnav'} shadows the installed swarmnav package" in done.stderr


def test_the_readme_limits_name_every_max_constant():
    import re
    text = (ROOT / "docs" / "reference" / "cli.md").read_text()  # the README's "Limits", moved into the docs
    limits = text[text.index("## Limits"):]
    limits = limits[:limits.index("\n## ")] if "\n## " in limits else limits
    defined = set()
    for layer in ("models", "planners", "controllers", "sim"):
        for path in (ROOT / layer).rglob("*.py"):
            defined |= set(re.findall(r"^(MAX_[A-Z0-9_]+)\s*(?::[^=\n]*)?=", path.read_text(), re.MULTILINE))
    assert len(defined) > 40
    assert sorted(name for name in defined if f"`{name}`" not in limits and f"`{name}` (" not in limits) == []


def test_run_to_dict_is_what_run_json_prints(capsys):
    result = swarmnav.run("gwo-scenario-1", planner="astar", seed=0)
    assert result.outcome == result.to_dict()["outcome"] == "goal_reached"
    assert main(["run", "gwo-scenario-1", "--planner", "astar", "--seed", "0", "--no-log", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert _without_wall_clock(printed) == _without_wall_clock(result.to_dict())
    figure = result.plot()
    labels = {line.get_label() for line in figure.axes[0].get_lines()}
    assert {"planned path", "driven"} <= labels


def test_plan_returns_the_path_plan_json_prints(capsys):
    planned = swarmnav.plan("gwo-scenario-3", planner="astar", seed=1)
    assert main(["plan", "gwo-scenario-3", "--planner", "astar", "--seed", "1", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["waypoints"] == planned.to_dict()["waypoints"]


def test_given_waypoints_reproduce_the_planned_run(tmp_path, capsys):
    assert main(["plan", "gwo-scenario-3", "--planner", "astar", "--seed", "0", "--json"]) == 0
    plan_file = tmp_path / "plan.json"
    plan_file.write_text(capsys.readouterr().out)
    assert main(["run", "gwo-scenario-3", "--planner", "astar", "--seed", "0", "--no-log", "--json"]) == 0
    planned_run = json.loads(capsys.readouterr().out)
    assert main(["run", "gwo-scenario-3", "--waypoints", str(plan_file), "--no-log", "--json"]) == 0
    given_run = json.loads(capsys.readouterr().out)
    for key in ("outcome", "collisions", "sim_time_s", "path_length_m", "min_clearance_m"):
        assert given_run[key] == planned_run[key], key
    assert given_run["plan"]["details"]["given"] == str(plan_file)
    # The same path as a CSV file drives the same run.
    csv_file = tmp_path / "plan.csv"
    csv_file.write_text("x,y\n" + "\n".join(f"{x!r},{y!r}" for x, y in planned_run["plan"]["waypoints"]) + "\n")
    assert swarmnav.run("gwo-scenario-3", waypoints=csv_file).result.path_length_m == given_run["path_length_m"]


def test_a_path_through_an_obstacle_reports_the_collision_and_fails_expect(tmp_path, capsys):
    path = tmp_path / "through.json"
    path.write_text("[[0, 0], [10, 10]]")  # gwo-scenario-1 has a disc at (1, 1)
    code = main(["run", "gwo-scenario-1", "--waypoints", str(path), "--no-log", "--json", "--stop-on-collision",
                 "--expect", "success"])
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert code == EXIT_EXPECTATION
    assert out["plan"]["collision_free"] is False
    assert out["collisions"] >= 1 and out["first_collision_s"] is not None
    contact = out["first_contact"]  # the disc at (1, 1), radius 0.2: obstacles[0] of gwo-scenario-1
    assert contact["obstacle"] == "obstacle_00" and contact["time_s"] == out["first_collision_s"]
    assert 0.5 < contact["x_m"] < 1.0 and abs(contact["x_m"] - contact["y_m"]) < 0.05
    assert captured.err.count("\n") == 1 and "--expect success" in captured.err
    # reached-with-contacts passes --expect reached but not --expect success
    assert main(["run", "gwo-scenario-2", "--planner", "astar", "--no-log", "--expect", "reached"]) == 0
    assert main(["run", "gwo-scenario-2", "--planner", "astar", "--no-log", "--expect", "success"]) == EXIT_EXPECTATION


def test_a_given_path_that_leaves_the_arena_is_no_success(tmp_path, capsys):
    # gwo-scenario-1's arena is [0, 10] x [0, 10]: (0, -3) is 3 m outside; the robot follows and leaves it
    outside = tmp_path / "outside.json"
    outside.write_text("[[0, 0], [0, -3], [10, 10]]")
    code = main(["run", "gwo-scenario-1", "--waypoints", str(outside), "--no-log", "--json", "--expect", "success"])
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert code == EXIT_EXPECTATION
    assert out["outcome"] == "left_arena" and out["success"] is False and out["reached"] is False
    assert out["plan"]["collision_free"] is False
    assert "left_arena" in captured.err and captured.err.count("\n") == 1
    # 0.1 m outside, less than the robot's radius: the robot stays within a radius of the arena and reaches the
    # goal, but along a path that leaves the arena: no success either
    slightly = swarmnav.run("gwo-scenario-1", waypoints=[[0, 0], [5, -0.1], [10, 10]])
    assert slightly.reached and slightly.outcome == "left_arena" and not slightly.success
    assert "given='waypoints'" in repr(slightly)
    assert main(["run", "gwo-scenario-1", "--waypoints", str(outside), "--no-log"]) == 0
    assert capsys.readouterr().out.startswith(f"gwo-scenario-1: given path {str(outside)!r} + follow")


def test_the_bulk_readers_of_waypoint_files_agree_with_the_row_reader(tmp_path):
    from swarmnav.sim.given_path import _from_csv, _from_json, read_waypoints
    points = np.random.default_rng(3).uniform(-5.0, 15.0, (500, 2))
    csv_file, json_file = tmp_path / "w.csv", tmp_path / "w.json"
    csv_file.write_text("y, x ,speed\n" + "".join(f"{y!r},{x!r},1\n\n" for x, y in points.tolist()))
    json_file.write_text(json.dumps({"waypoints": points.tolist(), "collision_free": True}))
    assert np.array_equal(read_waypoints(csv_file), points) and np.array_equal(read_waypoints(json_file), points)
    # the row-by-row readers (what a file the bulk readers refuse goes through) give the same numbers
    quoted = "".join(f'"{y!r}",{x!r},1\n' for x, y in points.tolist())
    assert np.array_equal(np.asarray(_from_csv("y,x,speed\n" + quoted, "q")), points)
    assert np.array_equal(np.asarray(_from_json([[1, 2.5], *points.tolist()], "j")), [[1.0, 2.5], *points])
    with pytest.raises(swarmnav.ConfigError, match=r"\[1\]: expected an \[x, y\] pair"):
        _from_json([[1.0, 2.0], [True, 3.0]], "j")  # a boolean is no number, in bulk as row by row


@pytest.mark.parametrize("text,where", [("x,y\n0,0\nfoo,1\n", "row 3"), ("a,b\n0,0\n", "row 1"),
                                        ("[[0, 0], [1]]", "[1]"), ('{"path": []}', "--waypoints"),
                                        ("[[0, 0]]", "at least two"), ("[[0, 0], [NaN, 1]]", "must be finite")])
def test_bad_waypoint_files_are_one_line(tmp_path, capsys, text, where):
    path = tmp_path / "w.txt"
    path.write_text(text)
    assert main(["run", "gwo-scenario-1", "--waypoints", str(path), "--no-log"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(path) in err and where in err


def _plugin_path(tmp_path: Path, broken: bool = False) -> dict[str, str]:
    """The example plugin installed as far as the path goes (``plugin_dist``), with a broken and a clashing
    plugin beside it if ``broken``."""
    entries = example_plugin(tmp_path)
    if broken:
        dist_info(tmp_path, "broken-plugin", "1.0", {"swarmnav.planners": {"broken": "no_such_module_here:Planner"},
                                                     "swarmnav.navigators": {"follow": "clashing_plugin:Follow"}})
        (tmp_path / "clashing_plugin.py").write_text(
            "from swarmnav.controllers.navigators.follow import FollowNavigator\n\n"
            "class Follow(FollowNavigator):\n    pass\n")
    return python_path(*entries)


def test_an_installed_plugin_is_listed_and_runs(tmp_path):
    env = _plugin_path(tmp_path)
    listed = json.loads(_swarmnav("planners", "--json", env=env).stdout)
    mine = next(row for row in listed if row["name"] == "random_detour")
    assert mine["package"] == "swarmnav-plugin-example 0.1.0"
    assert {"name": "samples", "type": "int", "default": 2000} in mine["parameters"]
    assert next(row for row in listed if row["name"] == "astar")["package"] == "swarmnav"
    navigators = json.loads(_swarmnav("navigators", "--json", env=env).stdout)
    assert "slow_follow" in {row["name"] for row in navigators}
    run = _swarmnav("run", "plugin-corridor", "--navigator", "slow_follow", "--no-log", "--json",
                    "--expect", "success", env=env)
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout)
    assert out["planner"] == "random_detour" and out["success"] is True and out["plan"]["collision_free"]
    study = tmp_path / "plugin-study.toml"
    study.write_text(PLUGIN_STUDY)
    # spawned workers (two: the batches split) know the plugin's planner and scenario: no error row
    done = _swarmnav("study", str(study), "--out", str(tmp_path / "rows"), "--workers", "2", "--json",
                     "--junit", str(tmp_path / "junit.xml"), env=env)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["outcomes"] == {"ok": 8}
    rows = pd.read_parquet(tmp_path / "rows" / "runs.parquet")
    assert rows.groupby(["planner", "scenario", "outcome"]).size().to_dict() == {
        (planner, scenario, "ok"): 2 for planner in ("astar", "random_detour")
        for scenario in ("gwo-scenario-3", "plugin-corridor")}
    cases = ElementTree.parse(tmp_path / "junit.xml").getroot().iter("testcase")
    assert sum("random_detour" in case.get("name") for case in cases) == 4


def test_a_broken_plugin_is_one_warning_and_the_rest_works(tmp_path):
    env = _plugin_path(tmp_path, broken=True)
    run = _swarmnav("run", "gwo-scenario-1", "--planner", "astar", "--no-log", env=env)
    assert run.returncode == 0
    warnings = [line for line in run.stderr.splitlines() if "warning" in line]
    assert len(warnings) == 2, run.stderr
    assert any("broken-plugin 1.0" in w and "cannot be imported" in w for w in warnings)
    assert any("'follow' is taken by swarmnav" in w for w in warnings)  # a clash keeps the bundled one
    assert "random_detour" in _swarmnav("planners", env=env).stdout


def test_study_junit_and_min_success(tmp_path):
    study = tmp_path / "smoke.toml"
    study.write_text('name = "smoke"\nscenarios = ["gwo-scenario-1"]\nmode = "physics"\nseeds = 2\n'
                     '[[planners]]\nname = "astar"\n[[planners]]\nname = "straight"\n')
    junit = tmp_path / "ci" / "smoke.xml"
    done = _swarmnav("study", str(study), "--out", str(tmp_path / "rows"), "--workers", "2", "--junit", str(junit),
                     "--min-success", "0.5")
    assert done.returncode == EXIT_EXPECTATION, done.stderr
    assert "straight + follow: success 0/2" in done.stderr and "astar" not in done.stderr
    root = ElementTree.parse(junit).getroot()
    cases = list(root.iter("testcase"))
    failed = [case for case in cases if case.find("failure") is not None]
    assert len(cases) == 4 and root.get("tests") == "4"
    assert {case.get("name").split(" +")[0] for case in failed} == {"straight"} and root.get("failures") == "2"
    # astar succeeds on scenario 1: the same study passes a lower bar
    again = _swarmnav("study", str(study), "--out", str(tmp_path / "rows"), "--min-success", "0")
    assert again.returncode == 0


def test_junit_tells_errors_from_failures_and_its_counts_add_up(tmp_path):
    junitparser = pytest.importorskip("junitparser")
    # plan-only: gwo raises on iaco-simple's grid map (an error row), straight cuts an obstacle on both (a failure)
    study = tmp_path / "mixed.toml"
    study.write_text('name = "mixed"\nscenarios = ["gwo-scenario-1", "iaco-simple"]\nmode = "plan"\n'
                     '[[planners]]\nname = "astar"\n[[planners]]\nname = "straight"\n'
                     '[[planners]]\nname = "gwo"\nparams = { population = 10, iterations = 5 }\n')
    junit = tmp_path / "junit.xml"
    assert main(["study", str(study), "--out", str(tmp_path / "rows"), "--workers", "1", "--junit", str(junit)]) == 0
    rows = pd.read_parquet(tmp_path / "rows" / "runs.parquet")
    expected = {(r.scenario, r.planner): "error" if r.outcome == "error" else "ok" if r.success else "failure"
                for r in rows.itertuples()}
    assert expected[("iaco-simple", "gwo")] == "error" and expected[("gwo-scenario-1", "straight")] == "failure"
    document = junitparser.JUnitXml.fromfile(str(junit))
    found, totals = {}, {"tests": 0, "failures": 0, "errors": 0}
    for suite in document:
        kinds = []
        for case in suite:
            results = [type(r).__name__ for r in case.result]
            assert len(results) <= 1
            kinds.append({"Error": "error", "Failure": "failure"}.get(results[0], "?") if results else "ok")
            found[(suite.name.split(".", 1)[1], case.name.split(" +")[0])] = kinds[-1]
        assert (suite.tests, suite.failures, suite.errors) == (len(kinds), kinds.count("failure"), kinds.count("error"))
        assert suite.time == pytest.approx(sum(case.time for case in suite), abs=1e-6)
        for key in totals:
            totals[key] += getattr(suite, key)
    assert found == expected
    root = ElementTree.parse(junit).getroot()
    assert {key: int(root.get(key)) for key in totals} == totals
    assert totals["errors"] == sum(v == "error" for v in expected.values()) >= 1


@pytest.mark.parametrize("argv", [["run", "gwo-scenario-1", "--planner", "straight", "--no-log", "--json-out", "{dir}"],
                                  ["study", "gwo-vs-abc", "--out", "{dir}/rows", "--junit", "{dir}"]])
def test_an_output_file_naming_a_folder_is_refused_before_any_work(tmp_path, capsys, argv):
    assert main([a.format(dir=tmp_path) for a in argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Is a directory" in err
    assert not (tmp_path / "rows").exists()  # the study did not start
