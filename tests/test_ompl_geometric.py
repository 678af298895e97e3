"""OMPL's other geometric planners (planners/ompl_geometric.py) on the real bindings: registered one name each
with their parameters, the exact check of every path, the budget in collision checks, seeding, no path."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from swarmnav.models.scenario import load_scenario
from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.ompl_geometric import OMPL_GEOMETRIC_PLANNERS
from swarmnav.planners.problem import scenario_problem
from swarmnav.planners.registry import PLANNERS, make_planner
from swarmnav.planners.sampling_ompl import OMPL_PLANNERS
from swarmnav.cli import main as cli
from swarmnav.sim.defaults import BENCH_PLANNERS_SAMPLING_CHOICES

from test_ompl_planners import RING_SCENARIO

NAMES = [cls.name for cls in OMPL_GEOMETRIC_PLANNERS]
BUDGET = {"max_evaluations": 3000, "round_evaluations": 100}  # FMT*: 1000 samples need about 2000
# A bundled disc field, a grid map (boxes) and a dense field.
SCENARIOS = ("gwo-scenario-1", "iaco-simple", "dense-field-30")


def test_each_planner_has_a_name_and_is_listed_with_its_parameters(capsys):
    assert len(NAMES) == len(set(NAMES)) == 9
    assert all(PLANNERS[cls.name] is cls for cls in OMPL_GEOMETRIC_PLANNERS)
    assert set(BENCH_PLANNERS_SAMPLING_CHOICES) == {cls.name for cls in (*OMPL_PLANNERS, *OMPL_GEOMETRIC_PLANNERS)}
    assert cli.main(["planners", "--json"]) == 0
    listed = {row["name"]: row for row in json.loads(capsys.readouterr().out)}
    classes = {json.dumps(sorted(p["name"] for p in listed[name]["parameters"])) for name in NAMES}
    assert len(classes) >= 6  # their own parameters, not one shared list
    for name in NAMES:
        parameters = {p["name"]: p for p in listed[name]["parameters"]}
        assert {"max_evaluations", "time_s", "round_evaluations", "attempts"} <= set(parameters), name
        assert listed[name]["description"].startswith(f"``{name}``: OMPL's"), name
    assert parameters_of(listed, "rrt_connect") == {"max_evaluations", "time_s", "round_evaluations", "attempts", "range_m"}
    assert "num_samples" in parameters_of(listed, "fmt_star") and "range" in {
        k for p in listed["kpiece1"]["parameters"] if p["name"] == "goal_bias" for k in p}


def parameters_of(listed: dict, name: str) -> set[str]:
    return {p["name"] for p in listed[name]["parameters"]}


@pytest.mark.parametrize("name", NAMES)
def test_paths_pass_the_exact_check_within_the_budget_and_repeat_by_seed(name):
    for scenario in SCENARIOS:
        problem = scenario_problem(load_scenario(scenario))
        path = make_planner(name, BUDGET).plan(problem, np.random.default_rng(0))
        assert problem.is_collision_free(path.waypoints), scenario
        assert np.array_equal(path.waypoints[0], problem.start.xy) and np.array_equal(path.waypoints[-1], problem.goal.xy)
        assert path.stats.evaluations <= BUDGET["max_evaluations"], scenario
        costs = np.array(path.stats.cost_history)
        assert len(costs) == len(path.stats.evaluation_history) == path.stats.iterations + 1
        assert np.all(costs[1:] <= costs[:-1]) and costs[-1] == pytest.approx(path.stats.length_m, rel=1e-9)
        assert path.stats.extra["ompl_planner"] == PLANNERS[name].ompl_class
    again = make_planner(name, BUDGET).plan(problem, np.random.default_rng(0))
    assert again.same_as(path)


def test_attempts_return_the_shortest_of_single_plans_drawn_in_turn_on_one_budget():
    problem = scenario_problem(load_scenario("dense-field-30"))
    rng = np.random.default_rng(0)
    singles = [make_planner("rrt_connect", {}).plan(problem, rng) for _ in range(4)]  # the same seeds in turn
    lengths = [p.stats.length_m for p in singles]
    assert len(set(lengths)) == 4  # first solutions are draws: the choice matters
    best = make_planner("rrt_connect", {"attempts": 4}).plan(problem, np.random.default_rng(0))
    chosen = int(np.argmin(lengths))
    assert np.array_equal(best.waypoints, singles[chosen].waypoints) and chosen > 0
    assert best.stats.cost_history == singles[chosen].stats.cost_history
    before = sum(p.stats.evaluations for p in singles[:chosen])  # its checks counted after the earlier attempts'
    assert best.stats.evaluation_history == tuple(before + c for c in singles[chosen].stats.evaluation_history)
    assert best.stats.extra["attempt_lengths_m"] == lengths
    assert best.stats.evaluations == sum(p.stats.evaluations for p in singles)
    one = make_planner("rrt_connect", {"attempts": 1}).plan(problem, np.random.default_rng(0))
    assert one.same_as(singles[0]) and "attempt_lengths_m" not in one.stats.extra
    # The attempts share the budget: the later ones get what the earlier left, and none exceeds it.
    tight = make_planner("rrt_connect", {"attempts": 4, "max_evaluations": singles[0].stats.evaluations + 1})
    shared = tight.plan(problem, np.random.default_rng(0))
    assert shared.stats.evaluations <= singles[0].stats.evaluations + 1
    assert np.array_equal(shared.waypoints, singles[0].waypoints)
    assert shared.stats.extra["attempt_lengths_m"] == [lengths[0], math.inf]  # one check left: none found, stop


@pytest.mark.parametrize("name", NAMES)
def test_a_goal_enclosed_by_discs_is_no_path_found_within_the_budget(name, tmp_path):
    path = tmp_path / "ring.toml"
    path.write_text(RING_SCENARIO)
    problem = scenario_problem(load_scenario(str(path)))
    with pytest.raises(NoPathFound, match="budget of 800 collision checks"):
        make_planner(name, {"max_evaluations": 800}).plan(problem, np.random.default_rng(0))


@pytest.mark.parametrize("setting, field", [("range_m=-1", "range_m"), ("goal_bias=2", "goal_bias"),
                                            ("num_samples=0", "num_samples"), ("border_fraction=0", "border_fraction"),
                                            ("max_nearest_neighbors=0", "max_nearest_neighbors"),
                                            ("attempts=0", "attempts"), ("attempts=101", "attempts")])
def test_bad_parameters_are_one_line_config_errors(setting, field, capsys):
    planner = {"range_m": "rrt", "goal_bias": "kpiece1", "num_samples": "fmt_star", "border_fraction": "lbkpiece1",
               "max_nearest_neighbors": "prm", "attempts": "rrt_connect"}[field]
    assert cli.main(["plan", "gwo-scenario-1", "--planner", planner, "--set", setting]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"planner.params.{field}" in err and not math.isnan(len(err))
