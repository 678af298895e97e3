"""The CLI contract: JSON keys, exit codes, and one clear line for every bad input."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from probe_scenario import PROBE_SCENARIO

from swarmnav.cli.main import main

BASE = PROBE_SCENARIO.replace("time_limit_s = 30.0", "time_limit_s = 60.0")  # tests/probe_scenario.py

PLAN_KEYS = {"scenario", "planner", "seed", "waypoints", "length_m", "plan_time_s", "iterations",
             "evaluations", "collision_free"}
RUN_KEYS = {"scenario", "planner", "seed", "reached", "collisions", "first_collision_s", "sim_time_s",
            "wall_time_s", "path_length_m", "min_clearance_m", "plan", "log"}


def write(tmp_path: Path, text: str) -> str:
    path = tmp_path / "scenario.toml"
    path.write_text(text)
    return str(path)


def run_cli(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_plan_json_has_the_contract_keys(capsys):
    code, out, err = run_cli(capsys, "plan", "gwo-scenario-1", "--json")
    assert code == 0, err
    obj = json.loads(out)
    assert PLAN_KEYS <= set(obj)
    assert obj["collision_free"] is True
    assert obj["waypoints"][0] == [0.0, 0.0] and obj["waypoints"][-1] == [10.0, 10.0]


def test_plan_reports_a_straight_line_through_an_obstacle_as_not_collision_free(tmp_path, capsys):
    code, out, _ = run_cli(capsys, "plan", write(tmp_path, BASE), "--planner", "straight", "--json")
    assert code == 0
    assert json.loads(out)["collision_free"] is False


def test_run_json_has_the_contract_keys(tmp_path, capsys):
    code, out, err = run_cli(capsys, "run", write(tmp_path, BASE), "--json", "--out", str(tmp_path / "run.mcap"))
    assert code == 0, err
    obj = json.loads(out)
    assert RUN_KEYS <= set(obj)
    assert PLAN_KEYS <= set(obj["plan"])
    assert obj["reached"] is True and obj["collisions"] == 0
    assert obj["log"] == str(tmp_path / "run.mcap") and Path(obj["log"]).stat().st_size > 0


def test_unreachable_goal_exits_3(tmp_path, capsys):
    walled = BASE.replace('radius_m = 0.5', 'radius_m = 0.3') + "".join(
        f"\n[[obstacles]]\nx = {4.5 + 0.45 * __import__('math').cos(a / 8 * 6.2832):.3f}\n"
        f"y = {4.5 + 0.45 * __import__('math').sin(a / 8 * 6.2832):.3f}\nradius_m = 0.12\n" for a in range(8))
    code, _, err = run_cli(capsys, "plan", write(tmp_path, walled))
    assert code == 3
    assert "NoPathFound" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("mutation, field", [
    (lambda t: t.replace('name = "probe"', 'name = "probe'), "toml"),
    (lambda t: t.replace("seed = 0", "seed = 0\ncolour = 3"), "colour"),
    (lambda t: t.replace("y = 2.5\nradius_m = 0.5", "y = 2.5\nradius_m = 0.5\nmass_kg = 1.0"), "obstacles[0].mass_kg"),
    (lambda t: t.replace('start = { x = 0.5, y = 0.5, heading_deg = 45.0 }', 'start = { y = 0.5 }'), "start.x"),
    (lambda t: t.replace('arena = { width_m = 5.0, height_m = 5.0, walls = false }\n', ''), "arena"),
    (lambda t: t.replace("radius_m = 0.5", "radius_m = 0.0"), "obstacles[0].radius_m"),
    (lambda t: t.replace("radius_m = 0.5", "radius_m = -1.0"), "obstacles[0].radius_m"),
    (lambda t: t.replace("radius_m = 0.15", "radius_m = -0.15"), "robot.radius_m"),
    (lambda t: t.replace("x = 2.5", "x = nan"), "obstacles[0].x"),
    (lambda t: t.replace("time_limit_s = 60.0", "time_limit_s = inf"), "time_limit_s"),
    (lambda t: t.replace("goal = { x = 4.5, y = 4.5", "goal = { x = 2.6, y = 2.4"), "goal"),
    (lambda t: t.replace("start = { x = 0.5, y = 0.5", "start = { x = 2.5, y = 3.1"), "start"),
    (lambda t: t.replace("goal = { x = 4.5, y = 4.5", "goal = { x = 7.0, y = 4.5"), "goal"),
    (lambda t: t.replace("start = { x = 0.5, y = 0.5", "start = { x = -0.5, y = 0.5"), "start"),
    (lambda t: t.replace('name = "astar"', 'name = "teleport"'), "planner.name"),
    (lambda t: t.replace('params = {}', 'params = { cell_m = "fine" }'), "planner.params.cell_m"),
    (lambda t: t.replace('params = {}', 'params = { warp = 9 }'), "planner.params.warp"),
    (lambda t: t + 'motion = { kind = "teleport" }\n', "obstacles[0].motion.kind"),
    (lambda t: t + 'motion = { kind = "linear", speed_m_s = 0.1, heading_deg = 0.0 }\n',
     "obstacles[0].motion.at_edge"),
    (lambda t: t.replace("count = 12", "count = 0"), "sensors.count"),
    (lambda t: t.replace("seed = 0", "seed = 1.5"), "seed"),
    (lambda t: t.replace("time_limit_s = 60.0", "time_limit_s = 0.051"), "time_limit_s"),
])
def test_bad_input_gets_one_line_naming_the_field_and_exit_2(tmp_path, capsys, mutation, field):
    path = write(tmp_path, mutation(BASE))
    code, out, err = run_cli(capsys, "plan", path, "--json")
    assert code == 2, (out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert path in lines[0] and field in lines[0], lines[0]
    assert "Traceback" not in err and out == ""


def test_missing_scenario_file_exits_2(tmp_path, capsys):
    code, _, err = run_cli(capsys, "run", str(tmp_path / "nope.toml"))
    assert code == 2 and "nope.toml" in err and "does not exist" in err


def test_unknown_bundled_name_and_planner_on_the_command_line_exit_2(capsys):
    code, _, err = run_cli(capsys, "plan", "no-such-scenario")
    assert code == 2 and "no-such-scenario" in err
    code, _, err = run_cli(capsys, "plan", "gwo-scenario-1", "--planner", "teleport")
    assert code == 2 and "planner.name" in err


def test_console_script_exits_2_without_traceback(tmp_path):
    bad = write(tmp_path, BASE.replace("radius_m = 0.5", "radius_m = 0"))
    proc = subprocess.run([sys.executable, "-m", "swarmnav.cli", "plan", bad], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and "obstacles[0].radius_m" in proc.stderr


def test_scenarios_lists_the_bundled_files(capsys):
    code, out, _ = run_cli(capsys, "scenarios", "--json")
    names = {row["name"] for row in json.loads(out)}
    assert code == 0 and {"gwo-scenario-1", "restaurant-table-2", "dense-field-30"} <= names


def test_an_output_path_the_file_system_refuses_is_one_line_and_exit_2(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    code, out, err = run_cli(capsys, "run", write(tmp_path, BASE), "--out", str(blocker / "run.mcap"))
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and str(blocker) in err


@pytest.mark.parametrize("planner, setting, field", [
    ("gwo", "population=-5", "planner.params.population"),
    ("astar", "cell_m=-1", "planner.params.cell_m"),
    ("iaco", "ants=0", "planner.params.ants"),
    ("maco", "p0=2", "planner.params.p0"),
    ("abc", "colour=3", "planner.params.colour"),
])
def test_bad_planner_parameters_from_set_exit_2(capsys, planner, setting, field):
    code, out, err = run_cli(capsys, "plan", "gwo-scenario-1", "--planner", planner, "--set", setting)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and field in err and "Traceback" not in err
    assert err.startswith("swarmnav: error: --set: ")


@pytest.mark.parametrize("argv", [["run", "gwo-scenario-1", "--seed", "abc"], ["bogus"], ["log"],
                                  ["plan", "gwo-scenario-1", "--camera", "side"]])
def test_a_malformed_command_line_is_one_line_and_exit_2(capsys, argv):
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    err = capsys.readouterr().err
    assert exit_info.value.code == 2
    assert err.count("\n") == 1 and "error:" in err


def test_out_naming_a_directory_is_one_line_and_leaves_it_alone(tmp_path, capsys):
    before = sorted(tmp_path.iterdir())
    code = main(["run", "gwo-scenario-1", "--planner", "straight", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Is a directory" in err and str(tmp_path) in err
    assert sorted(tmp_path.iterdir()) == before


def test_plan_json_says_which_mode_a_continuous_planner_used(capsys):
    # The default is the paper's algorithm (with the penalty its results need): a weight-1 penalty ends inside a disc.
    assert main(["plan", "gwo-scenario-1", "--planner", "gwo", "--set", "penalty_weight=1.0",
                 "--set", "penalty_margin_m=0.0", "--json"]) == 3
    assert "gwo (paper mode)" in capsys.readouterr().err
    assert main(["plan", "gwo-scenario-1", "--planner", "gwo", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["details"]["mode"] == "paper" and out["details"]["settings"]["penalty_weight"] == 1000.0
    assert out["planner_params"]["population"] == 50
    assert main(["plan", "dense-field-30", "--planner", "gwo", "--set", "iterations=20", "--set", "mode='robust'",
                 "--json"]) == 0
    details = json.loads(capsys.readouterr().out)["details"]
    assert details["mode"] == "robust"
    json.dumps(details, allow_nan=False)


def test_run_refuses_a_time_limit_between_control_periods_before_running(tmp_path, capsys):
    """0.051 s at 50 Hz used to end after 0.04 s: now one line naming the file and the field, exit 2, no log."""
    path = write(tmp_path, BASE.replace("time_limit_s = 60.0", "time_limit_s = 0.051"))
    code, out, err = run_cli(capsys, "run", path, "--out", str(tmp_path / "x.mcap"))
    assert code == 2 and out == "" and not (tmp_path / "x.mcap").exists()
    assert len(err.strip().splitlines()) == 1 and path in err and "time_limit_s" in err and "0.051 s" in err
    code, out, err = run_cli(capsys, "run", write(tmp_path, BASE.replace("time_limit_s = 60.0", "time_limit_s = 0.06")),
                             "--no-log", "--json")
    assert code == 0, err
    assert json.loads(out)["sim_time_s"] == pytest.approx(0.06)
