"""Starting ``swarmnav`` imports only light modules: each subcommand loads its heavy ones when it runs.

Structural, not timed: a fresh interpreter imports the CLI and builds its whole
parser, and the modules it loaded are checked by name.  ``swarmnav bench cli``
prints the start-up time itself.
"""

import json
import os
import subprocess
import sys

from swarmnav.cli import main as cli

HEAVY_PREFIXES = ("mujoco", "scipy", "dm_control", "dm_env", "gymnasium", "mcap", "foxglove", "matplotlib",
                  "pyarrow", "swarmnav.sim.simulation", "swarmnav.sim.episode", "swarmnav.benchmarks.",
                  "swarmnav.controllers")
# Of the planners package, the CLI needs the error types it maps to exit 3, and nothing else.
LIGHT_PLANNER_MODULES = {"swarmnav.planners", "swarmnav.planners.errors"}


def _modules_after(code: str) -> list[str]:
    out = subprocess.run([sys.executable, "-c", code + "\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.splitlines()[-1])


def _heavy(modules: list[str]) -> list[str]:
    return [m for m in modules if m.startswith(HEAVY_PREFIXES)
            or (m.startswith("swarmnav.planners") and m not in LIGHT_PLANNER_MODULES)]


def test_importing_the_cli_and_building_its_parser_loads_no_heavy_module():
    modules = _modules_after("from swarmnav.cli.main import build_parser\nbuild_parser()")
    assert "swarmnav.cli.main" in modules and "swarmnav.planners.errors" in modules
    assert _heavy(modules) == []


def test_the_check_sees_a_heavy_import():
    # The same check on a subcommand that did run: it names what that subcommand loaded.
    modules = _modules_after("from swarmnav.cli.main import build_parser\nbuild_parser()\n"
                             "from swarmnav.benchmarks import grid")
    heavy = _heavy(modules)
    assert "scipy" in heavy and "swarmnav.planners.problem" in heavy


def test_the_planning_errors_load_without_the_planner_registry():
    modules = _modules_after("from swarmnav.planners.errors import PlanningError, NoPathFound")
    assert "swarmnav.planners.registry" not in modules and "scipy" not in modules


def test_the_registry_names_are_still_importable_from_the_package():
    from swarmnav.planners import PLANNERS, NoPathFound, make_planner
    from swarmnav.planners import registry
    from swarmnav.planners.errors import NoPathFound as from_errors

    assert PLANNERS is registry.PLANNERS and make_planner is registry.make_planner
    assert NoPathFound is from_errors


def test_every_module_subcommand_has_its_options_and_runs_through_its_module():
    parser = cli.build_parser()
    args = parser.parse_args(["bench", "grid", "--quick"])
    assert args.quick and args.func.__module__ == "swarmnav.cli.commands"
    args = parser.parse_args(["replay", "run.mcap", "--verify"])
    assert args.verify and args.log == "run.mcap"


def test_bench_cli_prints_its_figures(capsys):
    assert cli.main(["bench", "cli", "--runs", "1", "--json"]) == 0
    figures = json.loads(capsys.readouterr().out)
    assert figures["runs"] == 1
    assert figures["scenarios_over_bare_s"] == figures["scenarios_s"] - figures["bare_python_s"]
    assert figures["meets_target"] == (figures["scenarios_s"] < figures["target_scenarios_s"])


def test_the_cli_runs_blas_on_one_thread_unless_the_environment_says_otherwise():
    """Set before NumPy loads (the planners' small matrices, multithreaded on a busy machine, ran up to 10x
    slower); a value the user exported wins."""
    code = ("import os, sys; import swarmnav.cli.main; assert 'numpy' not in sys.modules; import numpy; "
            "print(os.environ['OPENBLAS_NUM_THREADS'], os.environ['OMP_NUM_THREADS'])")
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")}
    plain = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert plain.stdout.split() == ["1", "1"]
    mine = subprocess.run([sys.executable, "-c", code], env={**env, "OPENBLAS_NUM_THREADS": "2"},
                          capture_output=True, text=True, check=True)
    assert mine.stdout.split() == ["2", "1"]
