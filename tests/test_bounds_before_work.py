"""Bounds before work (issue 36): every count, size and duration has a stated maximum in
models/scenario_limits.py, checked before anything of that size is allocated or run.

The time bounds below are on this process's CPU time (time.process_time), the work done, not on wall time: a
run that took 53 s of wall time beside three benchmarks (load ~5) was not a run that did unbounded work."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from swarmnav.models import scenario_limits as limits
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import parse_scenario
from swarmnav.cli.main import main
from probe_scenario import PROBE_SCENARIO


def exit_and_line(capsys, argv: list[str]) -> tuple[int, str]:
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse refuses an option's own value
        code = exc.code
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert len(err.splitlines()) <= 1 and "bug:" not in err, (argv, err)
    exit_and_line.out = captured.out
    return code, err


def refused(capsys, argv: list[str]) -> str:
    code, err = exit_and_line(capsys, argv)
    assert code == 2 and err, (argv, err)
    return err


@pytest.mark.parametrize("planner", ["aco", "iaco", "mmas"])
def test_colony_steps_times_ants_is_bounded(capsys, planner):
    err = refused(capsys, ["plan", "immas-env1-scattered", "--planner", planner, "--set", "max_steps=100000000"])
    assert "max_steps" in err and "MAX_COLONY_WALK_CELLS" in err


def discs_text(count: int, side_m: float = 150.0) -> str:
    base = PROBE_SCENARIO.split("[[obstacles]]")[0]
    base = base.replace("width_m = 5.0, height_m = 5.0", f"width_m = {side_m}, height_m = {side_m}")
    base = base.replace("x = 4.5, y = 4.5", f"x = {side_m - 0.5}, y = {side_m - 0.5}")
    base = base.replace("time_limit_s = 30.0", "time_limit_s = 0.2")
    cols = int(count ** 0.5) + 1
    step = (side_m - 4.0) / cols
    entries = [f"[[obstacles]]\nx = {2 + step * (i % cols) + step / 2:.3f}\ny = {2 + step * (i // cols) + step / 2:.3f}\n"
               "radius_m = 0.05\n" for i in range(count)]
    return base + "\n".join(entries)


def test_more_static_obstacles_than_the_maximum_are_refused_before_they_are_placed():
    text = discs_text(limits.MAX_STATIC_OBSTACLES + 1)
    t0 = time.process_time()
    with pytest.raises(ConfigError, match="MAX_STATIC_OBSTACLES"):
        parse_scenario(text, "many.toml")
    assert time.process_time() - t0 < 30


def test_an_exact_tangent_graph_beyond_its_maximum_is_refused_and_a_run_takes_theta_star_for_spl(capsys, tmp_path):
    path = tmp_path / "discs.toml"
    path.write_text(discs_text(limits.MAX_TANGENT_GRAPH_DISCS + 1, side_m=60.0))
    err = refused(capsys, ["plan", str(path), "--planner", "optimal"])
    assert "MAX_TANGENT_GRAPH_DISCS" in err
    t0 = time.process_time()
    code, err = exit_and_line(capsys, ["run", str(path), "--planner", "straight", "--no-log", "--json"])
    out = exit_and_line.out
    assert code == 0 and time.process_time() - t0 < 30, err
    import json
    # L* from Theta* beyond the exact graph's maximum (sim.reference), not the refused tangent graph
    assert json.loads(out)["spl"] is not None


def test_a_sweep_is_counted_from_its_lists_before_it_is_expanded(capsys, tmp_path):
    values = ", ".join(str(v) for v in range(4, 3004))
    study = tmp_path / "huge.toml"
    study.write_text(f'name = "huge"\nscenarios = ["gwo-scenario-1"]\n[[planners]]\nname = "gwo"\n'
                     f'params = {{ iterations = [{values}], population = [{values}] }}\n')
    t0 = time.perf_counter()
    err = refused(capsys, ["study", str(study), "--out", str(tmp_path / "out")])
    assert "9,000,000 settings (3000 x 3000)" in err and "MAX_STUDY_RUNS" in err
    assert time.perf_counter() - t0 < 10 and not (tmp_path / "out").exists()


@pytest.mark.parametrize("argv", [
    ["bench", "sim", "--repeats", "1000000000"], ["bench", "render", "--frames", "1000000000"],
    ["bench", "cli", "--runs", "1000000000"], ["bench", "navigation", "--per-group", "1000000000"],
    ["bench", "navigation", "--seeds", "1000000000"], ["bench", "env", "--duration", "1e300"],
    ["bench", "log", "--duration", "1e300"], ["bench", "study", "--cells", "99999999999"],
    ["bench", "planners", "--seeds", "1000000000"], ["bench", "grid", "--runs", "1000000000"],
])
def test_every_bench_count_and_duration_has_a_maximum(capsys, argv):
    assert "must be" in refused(capsys, argv)


@pytest.mark.parametrize("argv, field", [
    (["plan", "gwo-scenario-1", "--planner", "optimal", "--set", "arc_bulge_m=1e-300"], "arc_bulge_m"),
    (["run", "gwo-scenario-1", "--navigator", "dwa", "--navigator-set", "horizon_s=1e-300", "--no-log"], "horizon_s"),
    (["run", "gwo-scenario-1", "--navigator", "dstar_replan", "--navigator-set", "cell_m=1e-300", "--no-log"],
     "cell_m"),
])
def test_tiny_in_range_values_are_refused_naming_the_field(capsys, argv, field):
    assert field in refused(capsys, argv)


@pytest.mark.parametrize("option, value", [
    ("--radius-max-m", "nan"), ("--radius-max-m", "inf"), ("--arena-m", "inf"),
    ("--obstacles", "99999999999999999999"), ("--sensor-count", "100000"), ("--time-limit-s", "1e300"),
    ("--planner", "nan"), ("--navigator", "nan"), ("--name", "x" * 200_000), ("--seed", str(2**64)),
    ("--seed", "-1"),
])
def test_every_generator_option_is_checked_against_its_range(capsys, option, value):
    argv = ["scenarios", "generate", "crowd", "--seed", "1", option, value]
    assert option in refused(capsys, argv)


@pytest.mark.parametrize("seed", ["-1", str(2**64)])
def test_scenarios_info_world_seed_is_a_seed(capsys, seed):
    assert "--world-seed" in refused(capsys, ["scenarios", "info", "gwo-scenario-1", "--world-seed", seed])


@pytest.mark.parametrize("table, field", [('{ name = "nosuch", params = {} }', "planner.name"),
                                          ('{ name = "astar", params = { nosuch = 1 } }', "planner.params.nosuch")])
def test_a_scenario_is_validated_on_load_even_when_the_planner_is_overridden(capsys, tmp_path, table, field):
    path = tmp_path / "bad.toml"
    path.write_text(PROBE_SCENARIO.replace('{ name = "astar", params = {} }', table))
    err = refused(capsys, ["plan", str(path), "--planner", "straight"])
    assert err.startswith(f"swarmnav: error: {path}: {field}:"), err


def test_the_memory_limit_holds_for_the_unbounded_cases_of_the_issue(tmp_path):
    """The cases that asked for unbounded memory, each in a process under a 3 GB address-space limit."""
    import subprocess
    import sys
    zero_waypoints = ["run", "gwo-scenario-1", "--waypoints", "/dev/zero", "--no-log"]
    colony = ["plan", "immas-env1-scattered", "--planner", "aco", "--set", "max_steps=100000000"]
    script = ("import resource, sys\nresource.setrlimit(resource.RLIMIT_AS, (3_000_000_000, 3_000_000_000))\n"
              "from swarmnav.cli.main import main\nsys.exit(main(sys.argv[1:]))\n")
    for argv in (zero_waypoints, colony):
        done = subprocess.run([sys.executable, "-c", script, *argv], capture_output=True, text=True, timeout=60)
        assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1, (argv, done.stderr)
