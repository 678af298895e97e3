"""Hostile input (issue 9): every value a user can give either works or exits 2 naming
the field, oversized requests are refused before anything of that size is
allocated, and an unanticipated exception is reported as a bug in one line."""

import math
import time
import tracemalloc
from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np
import pytest

from swarmnav.models import scenario as scenario_module
from swarmnav.models.errors import ConfigError
from swarmnav.models.grid_map import parse_map
from swarmnav.models.scenario import load_scenario, parse_scenario
from swarmnav.cli import main as cli
from probe_scenario import PROBE_SCENARIO

from swarmnav.cli.main import main
from swarmnav.sim.scene import compile_scene

BASE = PROBE_SCENARIO  # tests/probe_scenario.py


def write(tmp_path: Path, text: str, name: str = "scenario.toml") -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def run_cli(capsys, *argv):
    try:
        code = main(list(argv))
    except SystemExit as exc:  # argparse refuses an option's value itself
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def bad_input(capsys, *argv) -> str:
    """Run the CLI expecting exit 2 with one line on stderr; return that line."""
    code, _, err = run_cli(capsys, *argv)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


# --- defect 1: any sensor count from 1 to the maximum ---------------------------------

@pytest.mark.parametrize("count", [1, 8, 13, 100, 101, scenario_module.MAX_SENSORS])
def test_any_sensor_count_compiles_with_evenly_spaced_rangefinders(count):
    scenario = replace(parse_scenario(BASE), sensor_count=count)
    scene = compile_scene(scenario)
    assert len(scene.range_sensor_adr) == count
    # In order of angle, evenly spaced around the full circle.
    expected = 2.0 * math.pi * np.arange(count) / count
    np.testing.assert_allclose(scene.range_angles_rad, expected, atol=1e-5)
    assert scene.range_offset_m > scenario.robot_radius_m


def test_a_run_with_seven_sensors_reads_seven_ranges(tmp_path, capsys):
    path = write(tmp_path, BASE.replace("count = 12", "count = 7").replace("time_limit_s = 30.0",
                                                                            "time_limit_s = 2.0"))
    code, out, err = run_cli(capsys, "run", path, "--no-log", "--json")
    assert code == 0, err
    scene = compile_scene(load_scenario(path))
    data = mujoco.MjData(scene.model)
    mujoco.mj_forward(scene.model, data)
    assert data.sensordata[scene.range_sensor_adr].shape == (7,)


@pytest.mark.parametrize("command", ["plan", "run"])
@pytest.mark.parametrize("count", [0, scenario_module.MAX_SENSORS + 1])
def test_plan_and_run_refuse_the_same_sensor_counts(tmp_path, capsys, command, count):
    path = write(tmp_path, BASE.replace("count = 12", f"count = {count}"))
    assert "sensors.count" in bad_input(capsys, command, path, "--no-log" if command == "run" else "--json")


# --- defect 4: sizes beyond a stated maximum are refused up front ---------------------

OVERSIZED = [
    # (edit to BASE, the field the error names, a figure the message must quote)
    (lambda t: t.replace("width_m = 5.0, height_m = 5.0", "width_m = 10000.0, height_m = 10000.0")
     .replace('x = 4.5, y = 4.5', 'x = 9000.0, y = 9000.0'), "arena", "4e+10"),
    (lambda t: t + "\n[sim]\ncell_m = 0.0001\n", "sim.cell_m", "2.5e+09"),
    (lambda t: t.replace("time_limit_s = 30.0", "time_limit_s = 1e12"), "time_limit_s", "5e+14"),
    (lambda t: t.replace("time_limit_s = 30.0", "time_limit_s = 1e300"), "time_limit_s", ""),
    (lambda t: t + "\n[sim]\ntimestep_s = 1e-6\ncontrol_hz = 1e6\n", "time_limit_s", "3e+07"),
    (lambda t: t.replace("radius_m = 0.5\n", "radius_m = 0.5\nmotion = { kind = \"random_walk\", "
                                           "step_m = 0.1, period_s = 1e-9 }\n"),
     "obstacles[0].motion.period_s", "3e+10"),
    (lambda t: t.replace("time_limit_s = 30.0", "time_limit_s = 10000.0") + "".join(
        f"\n[[obstacles]]\nx = {0.1 * k:.1f}\ny = 4.9\nradius_m = 0.05\n"
        f"motion = {{ kind = \"linear\", speed_m_s = 0.1, heading_deg = 0.0, at_edge = \"reflect\" }}\n"
        for k in range(1, 50)), "time_limit_s", "24500049"),
]


@pytest.mark.parametrize("edit, field, figure", OVERSIZED)
def test_oversized_requests_exit_2_naming_the_field_without_allocating_them(tmp_path, capsys, edit, field,
                                                                              figure):
    path = write(tmp_path, edit(BASE))
    tracemalloc.start()
    try:
        line = bad_input(capsys, "plan", path)
        _, peak_bytes = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert f": {field}:" in line
    assert "at most" in line
    assert figure.replace(",", "") in line.replace(",", "")
    assert peak_bytes < 20e6, f"{peak_bytes / 1e6:.0f} MB allocated to refuse {field}"


def test_a_map_header_larger_than_its_file_is_refused_before_allocation():
    text = "type octile\nheight 1\nwidth 1000000000000\nmap\n....\n"
    tracemalloc.start()
    try:
        with pytest.raises(ConfigError) as info:
            parse_map(text)
        _, peak_bytes = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert "map row 0" in str(info.value)
    assert peak_bytes < 1e6


def test_the_largest_arena_within_the_cap_still_loads():
    side_m = math.sqrt(scenario_module.MAX_GRID_CELLS) * 0.05
    text = BASE.replace("width_m = 5.0, height_m = 5.0", f"width_m = {side_m}, height_m = {side_m}")
    assert parse_scenario(text).arena_width_m == pytest.approx(side_m)


# --- defect 5: 10,000 obstacles --------------------------------------------------------

def ten_thousand_discs_text(count: int = 10_000, seed: int = 7) -> str:
    """10,000 discs of 0.2 m spread over a 100 x 100 m arena (4 M cells at 0.05 m)."""
    rng = np.random.default_rng(seed)
    centres = rng.uniform(1.0, 99.0, size=(2 * count, 2))
    clear = (np.hypot(*(centres - 0.5).T) > 1.5) & (np.hypot(*(centres - 99.5).T) > 1.5)
    lines = ['name = "ten-thousand-discs"', "time_limit_s = 10.0", "arena = { width_m = 100.0, height_m = 100.0 }",
             "start = { x = 0.5, y = 0.5 }", "goal = { x = 99.5, y = 99.5 }"]
    lines += [f"[[obstacles]]\nx = {x:.4f}\ny = {y:.4f}\nradius_m = 0.2" for x, y in centres[clear][:count]]
    return "\n".join(lines)


def test_ten_thousand_discs_plan_with_astar_and_build_a_scene():
    from swarmnav.planners.problem import scenario_problem
    from swarmnav.sim.episode import EpisodeSpec, plan_episode

    t0 = time.perf_counter()
    scenario = parse_scenario(ten_thousand_discs_text(), "<10k>")
    t1 = time.perf_counter()
    path = plan_episode(EpisodeSpec(scenario, planner="astar", seed=0)).path
    t2 = time.perf_counter()
    scene = compile_scene(scenario)
    t3 = time.perf_counter()
    print(f"\n10,000 discs, 100 x 100 m at 0.05 m: parse {t1 - t0:.2f} s, astar {t2 - t1:.2f} s, "
          f"scene {t3 - t2:.2f} s ({scene.model.ngeom} geoms)")
    assert len(scenario.obstacles) == 10_000
    assert scenario_problem(scenario).is_collision_free(path.waypoints)
    assert len(scene.obstacles) == 10_000


# --- defect 6: values that slipped past validation ------------------------------------

@pytest.mark.parametrize("seed", ["-1", "1.5", "x", str(2**63)])
def test_bad_seed_options_exit_2_naming_seed(capsys, seed):
    with pytest.raises(SystemExit) as info:
        main(["plan", "gwo-scenario-1", "--seed", seed])
    assert info.value.code == 2
    assert "--seed" in capsys.readouterr().err


@pytest.mark.parametrize("points, field", [
    ('[["1", "2"]]', "obstacles[0].motion.points"),
    ('[[1, true]]', "obstacles[0].motion.points"),
    ('[[1, 1], [50, 1]]', "obstacles[0].motion.points[1]"),
])
def test_bad_waypoints_name_the_field(tmp_path, capsys, points, field):
    text = BASE.replace("radius_m = 0.5\n", f'radius_m = 0.5\nmotion = {{ kind = "waypoints", '
                                            f'speed_m_s = 0.1, points = {points} }}\n')
    assert f": {field}:" in bad_input(capsys, "plan", write(tmp_path, text))


def test_a_binary_map_file_names_the_map(tmp_path, capsys):
    (tmp_path / "binary.map").write_bytes(bytes(range(256)) * 4)
    text = BASE.split("[[obstacles]]")[0] + '\n[map]\nfile = "binary.map"\ncell_m = 0.5\n'
    line = bad_input(capsys, "plan", write(tmp_path, text))
    assert ": map.file:" in line and "not a text map" in line


def test_an_obstacle_centre_outside_the_arena_names_it(tmp_path, capsys):
    line = bad_input(capsys, "plan", write(tmp_path, BASE.replace("x = 2.5", "x = 1e300")))
    assert ": obstacles[0].x:" in line


# --- defect 7: a small robot scales its base; no geom outside the radius --------------

def robot_reach_m(scene) -> float:
    """The farthest any robot collision geom reaches from the base's axis, at rest."""
    model = scene.model
    base = model.body("base_link").id
    reach = 0.0
    for g in scene.robot_geom_ids:
        body = model.geom_bodyid[g]
        offset = model.geom_pos[g][:2] + (model.body_pos[body][:2] if body != base else 0.0)
        reach = max(reach, float(np.hypot(*offset) + model.geom_size[g][0]))
    return reach


@pytest.mark.parametrize("radius_m", [scenario_module.MIN_ROBOT_RADIUS_M, 0.1, 0.15, 0.5])
def test_every_robot_collision_geom_lies_within_the_declared_radius(radius_m):
    scene = compile_scene(replace(parse_scenario(BASE), robot_radius_m=radius_m))
    names = {scene.model.geom(g).name for g in scene.robot_geom_ids}
    assert {"chassis", "left_wheel_tyre", "right_wheel_tyre", "front_caster", "rear_caster"} <= names
    assert robot_reach_m(scene) <= radius_m + 1e-6
    # The wheels still touch the floor and the top speed of the full-size base is kept.
    drive = scene.drive
    assert drive.wheel_radius_m * drive.max_wheel_speed_rad_s == pytest.approx(0.4, rel=1e-4)


def test_a_small_robot_drives_to_the_goal_without_touching_anything(tmp_path, capsys):
    import json
    text = BASE.replace("radius_m = 0.15", "radius_m = 0.05").replace("time_limit_s = 30.0", "time_limit_s = 60.0")
    code, out, err = run_cli(capsys, "run", write(tmp_path, text), "--no-log", "--json")
    assert code == 0, err
    result = json.loads(out)
    assert result["reached"] and result["collisions"] == 0


def test_a_radius_below_the_smallest_base_names_the_field(tmp_path, capsys):
    text = BASE.replace("radius_m = 0.15", "radius_m = 0.01")
    assert ": robot.radius_m:" in bad_input(capsys, "plan", write(tmp_path, text))


# --- defect 9: the name never leaves the output folder --------------------------------

@pytest.mark.parametrize("name", ["../../etc/x y", "a\\\\b", "nul\\u0000byte", "tab\\there", "..", "", "x" * 65])
def test_names_that_cannot_be_a_file_name_part_are_refused(tmp_path, capsys, name):
    text = BASE.replace('name = "probe"', f'name = "{name}"')
    assert ": name:" in bad_input(capsys, "run", write(tmp_path, text), "--no-log")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scenario.toml"]


def test_a_name_with_spaces_writes_its_log_inside_the_logs_folder(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    text = BASE.replace('name = "probe"', 'name = "two words"').replace("time_limit_s = 30.0", "time_limit_s = 1.0")
    code, _, err = run_cli(capsys, "run", write(tmp_path, text))
    assert code == 0, err
    written = [p for p in tmp_path.rglob("*") if p.is_file() and p.name != "scenario.toml"]
    assert len(written) == 1 and written[0].parent == tmp_path / "logs"
    assert written[0].name.startswith("two words_astar_seed0_")


# --- defect 12: bench options ----------------------------------------------------------

@pytest.mark.parametrize("argv, option", [
    (["bench", "sim", "--duration", "0"], "--duration"),
    (["bench", "sim", "--duration", "-5"], "--duration"),
    (["bench", "sim", "--duration", "nan"], "--duration"),
    (["bench", "sim", "--repeats", "0"], "--repeats"),
    (["bench", "planners", "--seeds", "-3"], "--seeds"),
    (["bench", "planners", "--population", "0"], "--population"),
    (["bench", "planners", "--peer-runs", "-1"], "--peer-runs"),
    (["bench", "planners", "--clearance-m", "inf"], "--clearance-m"),
])
def test_bench_options_out_of_range_exit_2(capsys, argv, option):
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 2
    assert f"argument {option}" in capsys.readouterr().err


def test_bench_sim_refuses_a_duration_beyond_the_step_cap(capsys):
    assert "--duration:" in bad_input(capsys, "bench", "sim", "--duration", "1e9", "--repeats", "1")


# --- the rule: a genuine bug is one line, exit 1, traceback saved ----------------------

def test_an_unanticipated_exception_is_reported_as_a_bug_with_its_traceback_saved(tmp_path, capsys, monkeypatch):
    import tempfile

    def broken(args):
        return {}["no such key"]

    monkeypatch.setattr(cli, "cmd_scenarios", broken)  # fault injection: a command with a bug in it
    if hasattr(cli, "_parser"):  # main keeps one parser per process: build one with the broken command
        monkeypatch.setattr(cli, "_parser", cli.build_parser)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    code, _, err = run_cli(capsys, "scenarios")
    assert code == 1
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "bug" in lines[0] and "KeyError" in lines[0]
    saved = list(tmp_path.glob("swarmnav-bug-*.txt"))
    assert len(saved) == 1 and str(saved[0]) in lines[0]
    assert "Traceback" in saved[0].read_text() and "no such key" in saved[0].read_text()


@pytest.mark.parametrize("edit, field", [
    (lambda t: t.replace("radius_m = 0.5", "radius_m = 1e-300"), "obstacles[0].radius_m"),
    (lambda t: t.replace("radius_m = 0.5", "radius_m = 0.5\nheight_m = 1e-300"), "obstacles[0].height_m"),
    (lambda t: t.replace("range_m = 0.4", "range_m = 1e-300"), "sensors.range_m"),
    (lambda t: t + "\n[sim]\ntimestep_s = 1e-300\n", "sim.timestep_s"),
])
def test_sizes_too_small_for_the_mujoco_model_are_refused_not_a_bug(tmp_path, capsys, edit, field):
    # Each parsed before and then failed to compile (MuJoCo's XML rounds them to 0).
    assert f": {field}:" in bad_input(capsys, "run", write(tmp_path, edit(BASE)), "--no-log")


def test_study_quick_without_quick_seeds_says_so_in_one_line(tmp_path, capsys):
    study = tmp_path / "no-quick.toml"
    study.write_text('scenarios = ["gwo-scenario-1"]\nseeds = 1\n[[planners]]\nname = "straight"\n')
    code, out, err = run_cli(capsys, "study", str(study), "--out", str(tmp_path / "rows"), "--workers", "1",
                             "--quick", "--json")
    assert code == 0
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "no quick_seeds" in lines[0] and "full study" in lines[0]
    assert '"cells": 1' in out
