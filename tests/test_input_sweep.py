"""The sweep of issue 36: every CLI option (of every subcommand), every planner and navigator parameter, every
scenario, study and suite field, tried with the worst values of every type (tests/input_sweep.py finds them;
nothing is listed by name).  Each must end in exit 0, 2, 3 or 5 with at most one line on stderr, never
``bug:``, within its budget and the memory bound.  A failure prints the argv that caused it."""

from __future__ import annotations

import argparse
import os
import time
import tomllib
from pathlib import Path

import pytest

import input_sweep as sweep_lib
from input_sweep import (PARAMETER_VALUES, Sweep, cli_cases, cli_options, component_parameters, document_values,
                         leaves, no_new_processes, replaced, toml_text)
from swarmnav.cli import main as cli_main

FAST_SCENARIO = """
name = "sweep"
seed = 0
time_limit_s = 0.1
arena = { width_m = 2.0, height_m = 2.0, walls = false }
robot = { radius_m = 0.15, max_speed_m_s = 0.2, clearance_m = 0.0 }
start = { x = 0.3, y = 0.3, heading_deg = 45.0 }
goal = { x = 1.7, y = 1.7, tolerance_m = 0.1 }
sensors = { model = "rangefinder", count = 4, range_m = 0.4 }
planner = { name = "straight", params = {} }
navigator = { name = "follow", params = {} }
sim = { timestep_s = 0.002, control_hz = 50.0, stop_on_collision = false, cell_m = 0.1, danger_m = 0.1 }

[[obstacles]]
x = 1.0
y = 1.0
radius_m = 0.2
height_m = 0.5
motion = { kind = "linear", speed_m_s = 0.05, heading_deg = 180.0, at_edge = "reflect" }

[[obstacles]]
x = 1.5
y = 0.5
radius_m = 0.1
"""
MEMORY_BOUND_MB = 3_000  # the process's peak resident memory over the whole sweep
EXERCISE_BUDGET_S = 0.1  # a plan or a short run with an accepted extreme parameter value
BUDGET_S = 0.2  # each invocation: past this it is working, not validating, and is stopped


# The accepted values worth a plan or a run: the extremes (1.5 or "x" accepted are ordinary values).
EXERCISED = [v for v in PARAMETER_VALUES if isinstance(v, (int, float)) and not isinstance(v, bool)
             and v in (0, -1, 1e-300, 1e300, 10**20)]


def failure_report(failures) -> str:
    labels = sorted({o.label for o in failures})
    return (f"{len(failures)} hostile inputs failed, at {len(labels)} options ({', '.join(labels)}):\n"
            + "\n".join(o.describe() for o in failures[:40]))


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, str]:
    """The cheapest valid inputs, by the name of the positional or option that takes them."""
    from swarmnav.models.scenario import parse_scenario
    from swarmnav.sim.episode import EpisodeSpec, run_episode
    from swarmnav.log.writer import McapRecorder
    folder = tmp_path_factory.mktemp("sweep")
    scenario = folder / "sweep.toml"
    scenario.write_text(FAST_SCENARIO)
    log = folder / "sweep.mcap"
    run_episode(EpisodeSpec(parse_scenario(FAST_SCENARIO, str(scenario))), [McapRecorder(log)], time_limit_s=0.1)
    study = folder / "study.toml"
    study.write_text(f'name = "sweep"\nscenarios = ["{scenario}"]\nmode = "plan"\n[[planners]]\nname = "straight"\n')
    (folder / "empty").mkdir()
    os.mkfifo(folder / "fifo")
    sweep_lib.SPECIAL_PATHS[:] = [str(folder / "fifo"), str(folder / "empty")]  # a FIFO, a folder
    return {"scenario": str(scenario), "file": str(study), "log": str(log), "source": str(log),
            "target": str(folder / "recovered.mcap"), "dir": str(folder / "empty"), "kind": "crowd",
            "seed": "1", "out": str(folder / "out.png"), "default": str(scenario), "folder": str(folder)}


def cheap_settings(files: dict[str, str]) -> dict[tuple[str, ...], list[str]]:
    """The smallest work for the commands known today (a command added later runs with its defaults, stopped
    by the budget once past validation)."""
    s = files["scenario"]
    return {("run",): ["--planner", "straight"], ("plan",): ["--planner", "straight"],
            ("bench", "sim"): ["--scenario", s, "--duration", "0.1", "--repeats", "1"],
            ("bench", "env"): ["--scenario", s, "--duration", "0.1", "--repeats", "1"],
            ("bench", "render"): ["--scenario", s, "--frames", "1", "--width", "16", "--height", "16"],
            ("bench", "navigation"): ["--scenario", s, "--seeds", "1", "--navigator", "follow"],
            ("bench", "planners"): ["--scenarios", s, "--seeds", "1", "--population", "4", "--iterations", "1",
                                    "--peer-runs", "0", "--fields", "0"],
            ("bench", "grid"): ["--runs", "1", "--swarm-sample", "1"],
            ("bench", "sensed-map"): ["--scenario", s, "--only", "dstar_replan"],
            ("bench", "study"): ["--seeds", "1", "--iterations", "1", "--rounds", "1", "--no-ray"],
            ("study",): ["--workers", "1", "--out", str(Path(files["folder"]) / "study-out")],
            ("replay",): ["--verify"]}


@pytest.fixture
def cached_parser(monkeypatch):
    """A parser of its own for the sweep, built once and used by every main() call of the test (main keeps one
    per process, ``_parser``; a scratch option added here never reaches the other tests)."""
    parser = cli_main.build_parser()
    if hasattr(cli_main, "_parser"):
        monkeypatch.setattr(cli_main, "_parser", lambda: parser)
    monkeypatch.setattr(cli_main, "build_parser", lambda: parser)
    return parser


def sweep_cli(parser: argparse.ArgumentParser, files: dict[str, str], sweep: Sweep) -> None:
    with no_new_processes():
        for label, argv in cli_cases(parser, files, cheap_settings(files)):
            sweep.cli(cli_main.main, label, argv)


def test_every_cli_option_of_every_subcommand(files, cached_parser, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # default outputs (logs/, studies/) land here
    sweep = Sweep(BUDGET_S)
    t0, cpu0 = time.perf_counter(), time.process_time()
    sweep_cli(cached_parser, files, sweep)
    options = cli_options(cached_parser)
    commands = {o.words for o in options}
    stopped = sum(o.code == "stopped" for o in sweep.outcomes)
    with capsys.disabled():
        print(f"\nCLI sweep: {len(sweep.outcomes):,} invocations over {len(options)} options and positionals of "
              f"{len(commands)} subcommands in {time.perf_counter() - t0:.1f} s wall, {time.process_time() - cpu0:.1f} s CPU ({stopped} stopped past "
              f"validation); peak memory {sweep_lib.peak_rss_mb():.0f} MB; slowest: {sweep.slowest()}")
    assert len(sweep.outcomes) > 1_000 and len(commands) >= 20
    assert not sweep.failures(), failure_report(sweep.failures())
    assert sweep_lib.peak_rss_mb() < MEMORY_BOUND_MB


def test_every_planner_and_navigator_parameter(files, capsys):
    from swarmnav.controllers.navigators import make_navigator
    from swarmnav.models.scenario import parse_scenario
    from swarmnav.planners.registry import make_planner
    from swarmnav.sim.episode import EpisodeSpec, plan_episode, run_episode
    scenario = parse_scenario(FAST_SCENARIO, files["scenario"])
    sweep, exercised = Sweep(BUDGET_S), 0
    t0, cpu0 = time.perf_counter(), time.process_time()
    rows = list(component_parameters())
    for kind, name, row in rows:
        make = make_planner if kind == "planner" else make_navigator
        for value in PARAMETER_VALUES:
            params = {row["name"]: value}
            argv = [kind, name, f"{row['name']}={value!r}"[:120]]
            built = sweep.call(f"{kind} {name}.{row['name']}", argv,
                               lambda: make(name, params, "<sweep>", trust_code=False))
            if built.code != 0 or not any(value is v for v in EXERCISED) or value == row["default"]:
                continue  # an accepted extreme is planned or run; an ordinary accepted value only built
            exercised += 1
            if kind == "planner":
                sweep.call(f"plan with {name}.{row['name']}", argv,
                           lambda: plan_episode(EpisodeSpec(scenario, planner=name, planner_params=params)),
                           EXERCISE_BUDGET_S)
            else:
                sweep.call(f"run with {name}.{row['name']}", argv,
                           lambda: run_episode(EpisodeSpec(scenario, planner="straight", navigator=name,
                                                           navigator_params=params), [], time_limit_s=0.1),
                           EXERCISE_BUDGET_S)
    with capsys.disabled():
        print(f"\nparameter sweep: {len(sweep.outcomes):,} calls over {len(rows)} parameters ({exercised} accepted "
              f"values planned or run) in {time.perf_counter() - t0:.1f} s wall, {time.process_time() - cpu0:.1f} s CPU; slowest: {sweep.slowest()}")
    assert len(rows) > 200 and len(sweep.outcomes) > 3_000
    assert not sweep.failures(), failure_report(sweep.failures())


def test_every_scenario_study_and_suite_field(files, tmp_path, capsys):
    from swarmnav.models.scenario import parse_scenario
    from swarmnav.models.suites import load_suite
    from swarmnav.sim.episode import EpisodeSpec, run_episode
    from swarmnav.study.spec import study_from_tables
    sweep = Sweep(BUDGET_S)
    t0, cpu0 = time.perf_counter(), time.process_time()
    scenario_doc = tomllib.loads(FAST_SCENARIO)
    study_doc = {"name": "s", "description": "d", "scenarios": [files["scenario"]], "mode": "plan", "seeds": 1,
                 "world_seeds": [0], "quick_seeds": 1, "wall_limit_s": 10.0, "time_limit_s": 0.1,
                 "reference": "straight", "planners": [{"name": "straight", "label": "s", "params": {}}],
                 "navigators": [{"name": "follow", "params": {}}]}
    suite_doc = {"name": "s", "version": 1, "description": "d", "prefix": "p",
                 "defaults": {"arena_m": 8.0, "sensor_model": "detector", "range_m": 2.0, "sensor_count": 12,
                              "planner": "astar"},
                 "groups": [{"name": "g", "kind": "crossing", "seeds": [0, 2],
                             "options": {"obstacles": 3, "speed_ratio": 0.6}}]}
    suite_path = tmp_path / "suite.toml"
    counts = {}

    def scenario_case(text: str) -> None:
        scenario = parse_scenario(text, "<sweep>")
        run_episode(EpisodeSpec(scenario), [], time_limit_s=0.1)

    def suite_case(text: str) -> None:
        suite_path.write_text(text)
        load_suite(str(suite_path)).scenes[0].text()

    for what, doc, check in (("scenario", scenario_doc, lambda d: scenario_case(toml_text(d))),
                             ("study", study_doc, lambda d: study_from_tables(d, "<sweep>")),
                             ("suite", suite_doc, lambda d: suite_case(toml_text(d)))):
        paths = list(leaves(doc))
        counts[what] = len(paths)
        for path in paths:
            current = doc
            for key in path:
                current = current[key]
            for value in document_values(current):
                label = f"{what} {'.'.join(map(str, path))}"
                sweep.call(label, [what, ".".join(map(str, path)), repr(value)[:80]],
                           lambda: check(replaced(doc, path, value)))
    with capsys.disabled():
        print(f"\ndocument sweep: {len(sweep.outcomes):,} documents over {counts} fields in "
              f"{time.perf_counter() - t0:.1f} s; slowest: {sweep.slowest()}")
    assert counts["scenario"] > 25 and counts["study"] > 10 and counts["suite"] > 8
    assert not sweep.failures(), failure_report(sweep.failures())


def test_an_option_added_later_is_swept_without_a_new_case(files, cached_parser, tmp_path, monkeypatch):
    """A scratch option (and a scratch component parameter) join the sweep by themselves, and the sweep
    names the argv of the failure they bring."""
    plan = next(sub for words, sub in sweep_lib.walk_parser(cached_parser) if words == ("plan",))
    plan.add_argument("--scratch-count", type=int, default=0, help="added by a test")
    original = cli_main.cmd_plan

    def plan_with_scratch(args):
        if args.scratch_count:
            _ = [0] * min(args.scratch_count, 10**6) * 0 if args.scratch_count < 10**7 else 1 / 0  # a careless use
        return original(args)
    plan.set_defaults(func=plan_with_scratch)
    assert any(o.flag == "--scratch-count" for o in cli_options(cached_parser))
    monkeypatch.chdir(tmp_path)
    sweep = Sweep(BUDGET_S)
    with no_new_processes():
        for label, argv in cli_cases(cached_parser, files, cheap_settings(files)):
            if "--scratch-count" in label:
                sweep.cli(cli_main.main, label, argv)
    assert len(sweep.outcomes) >= 10
    failures = sweep.failures()
    assert failures and all("--scratch-count" in o.describe() for o in failures)
    assert "bug" in failures[0].describe() and "ZeroDivisionError" in failures[0].describe()


def test_a_handful_in_their_own_process_under_a_3_gb_address_space(files, tmp_path):
    """In-process the sweep bounds time; these few run as the user runs them, under ``ulimit -v`` (3 GB), so
    an allocation the bounds missed would fail here rather than be absorbed by the test process."""
    import subprocess
    import sys
    fifo = tmp_path / "waypoints.fifo"
    os.mkfifo(fifo)
    discs = tmp_path / "discs.toml"
    discs.write_text(FAST_SCENARIO.split("[[obstacles]]")[0]
                     + "".join(f"[[obstacles]]\nx = 1.0\ny = 1.0\nradius_m = 0.01\n" for _ in range(12_000)))
    values = ", ".join(str(v) for v in range(4, 3004))
    study = tmp_path / "huge.toml"
    study.write_text(f'name = "huge"\nscenarios = ["{files["scenario"]}"]\n[[planners]]\nname = "gwo"\n'
                     f'params = {{ iterations = [{values}], population = [{values}] }}\n')
    script = ("import resource, sys\nresource.setrlimit(resource.RLIMIT_AS, (3_000_000_000, 3_000_000_000))\n"
              "from swarmnav.cli.main import main\nsys.exit(main(sys.argv[1:]))\n")
    cases = [["run", files["scenario"], "--waypoints", str(fifo), "--no-log"],
             ["plan", files["scenario"], "--set", "x=" + sweep_lib.DEEP],
             ["plan", str(discs)], ["study", str(study), "--out", str(tmp_path / "out")]]
    for argv in cases:
        t0 = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", script, *argv], capture_output=True, text=True, timeout=60,
                              cwd=tmp_path)
        lines = done.stderr.strip().splitlines()
        assert done.returncode == 2 and len(lines) == 1 and "bug:" not in lines[0], (argv[:3], done.stderr[-500:])
        assert time.perf_counter() - t0 < 60


def test_a_parameter_added_later_is_swept_without_a_new_case(files, monkeypatch):
    """A scratch planner registered now, with a parameter declared with no range and used carelessly: the
    parameter sweep finds it through the registry and names the failure it brings."""
    from dataclasses import dataclass

    import numpy as np

    from swarmnav.models.scenario import parse_scenario
    from swarmnav.planners import registry
    from swarmnav.planners.registry import make_planner
    from swarmnav.planners.straight import StraightPlanner
    from swarmnav.sim.episode import EpisodeSpec, plan_episode

    @dataclass
    class ScratchPlanner(StraightPlanner):
        cells: float = 1.0  # no declared range

        def plan(self, problem, rng):
            np.zeros(int(self.cells))  # careless: 1e300 cells
            return super().plan(problem, rng)

    ScratchPlanner.name = "scratch"
    monkeypatch.setitem(registry.PLANNERS, "scratch", ScratchPlanner)
    rows = [(kind, name, row) for kind, name, row in component_parameters() if name == "scratch"]
    assert [row["name"] for _, _, row in rows] == ["cells"]
    scenario = parse_scenario(FAST_SCENARIO, files["scenario"])
    sweep = Sweep(BUDGET_S)
    for _, name, row in rows:
        for value in EXERCISED:
            params = {row["name"]: value}
            if sweep.call("build", [name], lambda: make_planner(name, params)).code == 0:
                sweep.call(f"plan with {name}.{row['name']}", ["planner", name, f"cells={value!r}"],
                           lambda: plan_episode(EpisodeSpec(scenario, planner=name, planner_params=params)))
    failures = sweep.failures()
    described = "\n".join(o.describe() for o in failures)
    assert "swarmnav planner scratch cells=-1" in described and "swarmnav planner scratch cells=1e+300" in described
    assert all("bug" in o.describe() for o in failures)
