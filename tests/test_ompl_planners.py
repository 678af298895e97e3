"""OMPL's RRT*, Informed RRT*, BIT* and PRM* behind the planner seam (planners/sampling_ompl.py), run on the
real OMPL bindings: the exact collision check, seeding, the budget, failures and the CLI."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from swarmnav.models.geometry import segment_disc_distance, segment_disc_distances
from swarmnav.models.scenario import list_scenarios, load_scenario
from swarmnav.planners.errors import NoPathFound, PlanningError
from swarmnav.planners.problem import scenario_problem
from swarmnav.planners.registry import PLANNERS, make_planner
from swarmnav.planners.sampling_ompl import OMPL_PLANNERS
from swarmnav.cli import main as cli

NAMES = [cls.name for cls in OMPL_PLANNERS]
BUDGET = {"max_evaluations": 2000, "round_evaluations": 100}

# A goal inside a closed ring of twelve discs (neighbours overlap once inflated): no path exists.
RING_SCENARIO = """
name = "ring"
arena = { width_m = 10.0, height_m = 10.0, walls = true }
robot = { radius_m = 0.2, max_speed_m_s = 0.5 }
start = { x = 1.0, y = 1.0, heading_deg = 0.0 }
goal = { x = 7.0, y = 7.0, tolerance_m = 0.1 }
""" + "".join(f"""
[[obstacles]]
x = {7.0 + 1.5 * math.cos(a):.6f}
y = {7.0 + 1.5 * math.sin(a):.6f}
radius_m = 0.5
""" for a in np.linspace(0.0, 2.0 * math.pi, 12, endpoint=False))


def disc_scenarios_with_a_path() -> list[str]:
    """Bundled scenarios with discs only where the exact planner finds a path."""
    names = []
    for name in list_scenarios():
        problem = scenario_problem(load_scenario(name))
        if problem.obstacle_kinds != {"discs"}:
            continue
        try:
            make_planner("optimal").plan(problem, np.random.default_rng(0))
        except PlanningError:
            continue
        names.append(name)
    return names


def test_the_four_planners_are_registered():
    assert set(NAMES) == {"rrt_star", "informed_rrt_star", "bit_star", "prm_star"}
    assert all(PLANNERS[name] is cls for name, cls in zip(NAMES, OMPL_PLANNERS))


def test_importing_the_registry_does_not_import_ompl():
    code = "import sys, swarmnav.planners.registry, swarmnav.cli.main; print('ompl' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


@pytest.mark.parametrize("name", NAMES)
def test_every_bundled_disc_scenario_with_a_path_is_planned_collision_free(name):
    scenarios = disc_scenarios_with_a_path()
    assert len(scenarios) >= 10
    for scenario in scenarios:
        problem = scenario_problem(load_scenario(scenario))
        path = make_planner(name, BUDGET).plan(problem, np.random.default_rng(0))
        assert problem.is_collision_free(path.waypoints), scenario
        assert np.array_equal(path.waypoints[0], problem.start.xy)
        assert np.array_equal(path.waypoints[-1], problem.goal.xy)
        optimum = make_planner("optimal").plan(problem, np.random.default_rng(0)).stats.extra["optimum_length_m"]
        assert optimum - 1e-9 <= path.stats.length_m < 1.5 * optimum, scenario
        assert path.stats.evaluations <= BUDGET["max_evaluations"]


@pytest.mark.parametrize("name", NAMES)
def test_same_seed_same_path_after_other_plans_and_in_another_process(name):
    problem = scenario_problem(load_scenario("gwo-scenario-1"))
    first = make_planner(name, BUDGET).plan(problem, np.random.default_rng(7))
    other = make_planner(name, BUDGET).plan(problem, np.random.default_rng(8))
    again = make_planner(name, BUDGET).plan(problem, np.random.default_rng(7))
    assert first.same_as(again)
    assert not np.array_equal(first.waypoints, other.waypoints)
    args = [sys.executable, "-m", "swarmnav.cli", "plan", "gwo-scenario-1", "--planner", name, "--seed", "7",
            "--json"] + [f"--set={k}={v}" for k, v in BUDGET.items()]
    fresh = json.loads(subprocess.run(args, capture_output=True, text=True, check=True).stdout)
    # the CLI plans with default_rng(--seed), in a process where OMPL has planned nothing before
    assert np.array_equal(np.array(fresh["waypoints"]), first.waypoints)


@pytest.mark.parametrize("name", NAMES)
def test_the_history_records_rounds_of_collision_checks(name):
    problem = scenario_problem(load_scenario("gwo-scenario-1"))
    stats = make_planner(name, BUDGET).plan(problem, np.random.default_rng(1)).stats
    costs, spent = np.array(stats.cost_history), np.array(stats.evaluation_history)
    assert len(costs) == len(spent) == stats.iterations + 1 >= 10
    assert np.all(costs[1:] <= costs[:-1])                   # the best never gets worse (inf before a path)
    assert costs[-1] == pytest.approx(stats.length_m, rel=1e-9)
    assert spent[-1] == stats.evaluations == BUDGET["max_evaluations"]
    steps = np.diff(spent)
    assert np.all(steps > 0) and np.median(steps) >= BUDGET["round_evaluations"]


@pytest.mark.parametrize("name", NAMES)
def test_a_goal_enclosed_by_discs_is_no_path_found_within_the_budget(name, tmp_path, capsys):
    path = tmp_path / "ring.toml"
    path.write_text(RING_SCENARIO)
    problem = scenario_problem(load_scenario(str(path)))
    with pytest.raises(NoPathFound, match="budget of 1000 collision checks"):
        make_planner(name, {"max_evaluations": 1000}).plan(problem, np.random.default_rng(0))
    code = cli.main(["plan", str(path), "--planner", name, "--set", "max_evaluations=1000", "--json"])
    err = capsys.readouterr().err
    assert code == 3 and "NoPathFound" in err


def test_a_time_budget_stops_the_search():
    problem = scenario_problem(load_scenario("dense-field-30"))
    path = make_planner("rrt_star", {"max_evaluations": 0, "time_s": 0.3}).plan(problem, np.random.default_rng(0))
    assert path.stats.plan_time_s < 2.0
    assert problem.is_collision_free(path.waypoints)


def test_plan_through_the_cli_prints_only_swarmnav_output():
    """``swarmnav plan SCENARIO --planner rrt_star --json``: OMPL's console and nanobind's exit-time
    messages stay out of stdout and stderr."""
    proc = subprocess.run([sys.executable, "-m", "swarmnav.cli", "plan", "restaurant-table-5", "--planner",
                           "rrt_star", "--json", "--set", "max_evaluations=1500"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""
    out = json.loads(proc.stdout)
    assert out["collision_free"] and out["evaluations"] <= 1500
    assert out["details"]["ompl_planner"] == "RRTstar"


@pytest.mark.parametrize("setting, field", [("max_evaluations=0", "planner.params.max_evaluations"),
                                            ("time_s=-1", "planner.params.time_s"),
                                            ("round_evaluations=0", "planner.params.round_evaluations"),
                                            ("goal_bias=2", "planner.params.goal_bias")])
def test_bad_parameters_are_one_line_config_errors(setting, field, capsys):
    code = cli.main(["plan", "gwo-scenario-1", "--planner", "rrt_star", "--set", setting])
    err = capsys.readouterr().err
    assert code == 2 and field in err and len(err.strip().splitlines()) == 1


def test_the_scalar_segment_disc_distance_agrees_with_the_vectorised_one():
    rng = np.random.default_rng(5)
    a, b, c = rng.uniform(-3, 3, (200, 2)), rng.uniform(-3, 3, (200, 2)), rng.uniform(-3, 3, (200, 2))
    b[:20] = a[:20]                                            # points as zero-length segments
    vectorised = np.diag(segment_disc_distances(a, b, c))
    scalar = [segment_disc_distance(*a[k], *b[k], *c[k]) for k in range(200)]
    np.testing.assert_allclose(scalar, vectorised, rtol=1e-12, atol=1e-12)
