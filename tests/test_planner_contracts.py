"""Contracts every registered planner keeps, run over the ``PLANNERS`` registry and every
bundled scenario: what it returns, what it supports, its evaluation budget and its
resource caps."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import list_scenarios, load_scenario
from swarmnav.planners.registry import PLANNERS, make_planner, register
from swarmnav.planners.errors import BudgetExceeded, NoPathFound, PlanningError
from swarmnav.planners.problem import Planner, scenario_problem
from swarmnav.cli import main as cli

SCENARIOS = list_scenarios()


def fields_of(name: str) -> set[str]:
    return {f.name for f in dataclasses.fields(PLANNERS[name]) if f.init}


def small_budget(name: str) -> dict:
    """Parameters that keep a run short, chosen by the fields a planner has."""
    fields = fields_of(name)
    params = {}
    if "population" in fields:
        params.update(population=20, iterations=20)
    if "ants" in fields:
        params.update(ants=10, iterations=10)
    if "round_evaluations" in fields:  # the OMPL planners: a budget of collision checks
        params.update(max_evaluations=1000)
    if "num_samples" in fields:  # FMT*'s batch: sampled (and checked) before it searches, so within the budget
        params.update(num_samples=300)
    return params


@pytest.fixture(scope="module")
def problems():
    return {name: scenario_problem(load_scenario(name)) for name in SCENARIOS}


def test_every_planner_declares_its_name_and_the_obstacles_it_supports():
    for name, cls in PLANNERS.items():
        assert cls.name == name
        assert cls.supports and cls.supports <= {"discs", "boxes"}, name

    @dataclasses.dataclass
    class Undeclared:
        name = "undeclared"

        def plan(self, problem, rng):
            raise NotImplementedError

    with pytest.raises(TypeError):
        register(Undeclared)
    with pytest.raises(ValueError):
        register(PLANNERS["astar"])


def test_the_registry_holds_and_builds_planners_only():
    """``make_planner`` returns a :class:`Planner` (its declared type): a class without ``plan`` is refused when it
    registers, and every registered name builds an object the protocol recognises."""
    class Planless:
        name = "planless"
        supports = frozenset({"discs"})

    with pytest.raises(TypeError, match="no plan"):
        register(Planless)
    assert "planless" not in PLANNERS

    class Plain:  # its parameters would be its dataclass fields: a plain class could not be built by name
        name = "plain"
        supports = frozenset({"discs"})

        def plan(self, problem, rng):
            raise NotImplementedError

    with pytest.raises(TypeError, match="must be a dataclass"):
        register(Plain)
    assert "plain" not in PLANNERS
    for name in PLANNERS:
        assert isinstance(make_planner(name), Planner), name


@pytest.mark.parametrize("planner_name", sorted(PLANNERS))
def test_every_planner_on_every_bundled_scenario_it_supports(planner_name, problems):
    """A returned path starts and ends exactly at the endpoints and passes the exact check
    (``straight`` returns the bare segment); failures are typed; a scenario with an obstacle
    kind the planner does not support is a ConfigError naming the planner."""
    cls = PLANNERS[planner_name]
    planned = 0
    for scenario_name, problem in problems.items():
        planner = make_planner(planner_name, small_budget(planner_name))
        if not problem.obstacle_kinds <= cls.supports:
            with pytest.raises(ConfigError) as err:
                planner.plan(problem, np.random.default_rng(0))
            assert err.value.field == "planner.name"
            continue
        try:
            path = planner.plan(problem, np.random.default_rng(0))
        except PlanningError:
            continue
        planned += 1
        assert np.array_equal(path.waypoints[0], problem.start.xy), scenario_name
        assert np.array_equal(path.waypoints[-1], problem.goal.xy), scenario_name
        if planner_name == "straight":
            assert len(path.waypoints) == 2
        else:
            assert problem.is_collision_free(path.waypoints), scenario_name
        assert path.stats.length_m >= np.hypot(*(problem.goal.xy - problem.start.xy)) - 1e-9
    assert planned >= 3, planner_name


def budgeted_planners() -> list[str]:
    return sorted(name for name in PLANNERS if "max_evaluations" in fields_of(name))


def test_the_swarm_planners_are_the_budgeted_ones():
    assert {"abc", "adl_abc", "gwo", "pso", "iaco", "immas", "maco", "aco"} <= set(budgeted_planners())


@pytest.mark.parametrize("planner_name", budgeted_planners())
@pytest.mark.parametrize("scenario_name", ["dense-field-30", "restaurant-table-5"])
def test_max_evaluations_holds_repair_included(planner_name, scenario_name, capsys):
    """``swarmnav plan S --planner P --set max_evaluations=100 --json`` reports at most 100."""
    code = cli.main(["plan", scenario_name, "--planner", planner_name, "--set", "max_evaluations=100",
                     "--json", "--seed", "1"])
    out, err = capsys.readouterr()
    if code == 3:
        assert "BudgetExceeded" in err or "NoPathFound" in err
        return
    assert code == 0, err
    assert json.loads(out)["evaluations"] <= 100


def test_the_repair_counts_against_the_budget():
    """Without a budget the repair would spend its own evaluations; with one it stops at it."""
    problem = scenario_problem(load_scenario("dense-field-30"))
    # the robust mode's grid guess and plain fit (its tangent guess needs no repair here)
    params = {"population": 10, "iterations": 5, "guess": "grid", "fit_push_rounds": 0, "mode": "robust"}
    unlimited = make_planner("abc", params)
    repaired = None
    for seed in range(20):
        try:
            path = unlimited.plan(problem, np.random.default_rng(seed))
        except NoPathFound:
            continue
        if path.stats.extra["repaired"] == "fine_penalty":
            repaired = (seed, path.stats.evaluations)
            break
    assert repaired is not None, "no seed needed the fine-penalty repair"
    seed, spent = repaired
    search_only = spent - path.stats.extra["repair_rounds"] * 10 - 1
    assert search_only > 0
    budget = search_only + 3          # room for the repair's first evaluation and a part of one batch
    limited = make_planner("abc", dict(params, max_evaluations=budget))
    try:
        path = limited.plan(problem, np.random.default_rng(seed))
    except BudgetExceeded:
        return
    assert path.stats.evaluations <= budget


def test_budget_spent_without_a_path_is_budget_exceeded():
    problem = scenario_problem(load_scenario("dense-field-30"))
    with pytest.raises(BudgetExceeded):   # the robust mode's grid guess, plain fit (the tangent one finds it)
        make_planner("gwo", {"max_evaluations": 60, "guess": "grid", "fit_push_rounds": 0, "mode": "robust"}).plan(
            problem, np.random.default_rng(1))
    # Without a budget the same failure is NoPathFound (the paper's gwo: the robust mode's
    # seeded start would find a path even with four wolves and one iteration).
    with pytest.raises(NoPathFound) as err:
        make_planner("gwo", {"population": 4, "iterations": 1, "repair_rounds": 0, "mode": "paper"}).plan(
            problem, np.random.default_rng(1))
    assert not isinstance(err.value, BudgetExceeded)


@pytest.mark.parametrize("planner_name", sorted(PLANNERS))
def test_same_seed_same_path(planner_name, problems):
    problem = problems["restaurant-table-2" if "discs" in PLANNERS[planner_name].supports else "iaco-complex"]
    params = small_budget(planner_name)
    try:
        one = make_planner(planner_name, params).plan(problem, np.random.default_rng(7))
    except PlanningError as exc:
        with pytest.raises(type(exc)):
            make_planner(planner_name, params).plan(problem, np.random.default_rng(7))
        return
    two = make_planner(planner_name, params).plan(problem, np.random.default_rng(7))
    assert one.same_as(two)


# -- caps: each oversized request is refused before anything is allocated ----------

@pytest.mark.parametrize("planner_name, setting, field, needed", [
    ("gwo", "population=100000000", "planner.params.population", "10,000,000,000"),
    ("abc", "population=100000000", "planner.params.population", "10,000,000,000"),
    ("maco", "nodes=1000000", "planner.params.nodes", "1000000"),
    ("maco", "ants=100000000", "planner.params.ants", "100000000"),
    ("iaco", "ants=100000000", "planner.params.ants", "100000000"),
    ("astar", "cell_m=0.0001", "planner.params.cell_m", "10,000,000,000"),
    ("immas", "cell_m=0.0001", "planner.params.cell_m", "10,000,000,000"),
    ("iaco", "cell_m=0.005", "planner.params.cell_m", "4,000,000"),
    ("gwo", "iterations=nan", "planner.params.iterations", "nan"),
    ("iaco", "iterations=nan", "planner.params.iterations", "nan"),
])
def test_oversized_or_bad_numbers_are_config_errors_naming_the_field(planner_name, setting, field, needed, capsys):
    code = cli.main(["plan", "gwo-scenario-1", "--planner", planner_name, "--set", setting, "--json"])
    err = capsys.readouterr().err
    assert code == 2
    assert field in err and needed in err
    assert len(err.strip().splitlines()) == 1


# -- evaluation histories: what each recorded iteration had spent ---------------------

@pytest.mark.parametrize("planner_name", sorted(PLANNERS))
def test_evaluation_history_is_cumulative_and_matches_the_cost_history(planner_name, problems):
    """Same length as the best-cost history, non-decreasing, never past the run's total; it ends at the
    total unless evaluations came after the search (repair rounds, the robust mode's polish)."""
    problem = problems["restaurant-table-2" if "discs" in PLANNERS[planner_name].supports else "iaco-complex"]
    params = small_budget(planner_name)
    if "polish_rounds" in fields_of(planner_name):
        params.update(polish_rounds=0, repair_rounds=0, penalty_weight=1000.0, penalty_margin_m=0.02)
    try:
        path = make_planner(planner_name, params).plan(problem, np.random.default_rng(3))
    except PlanningError:
        pytest.skip(f"{planner_name} found no path here")
    stats = path.stats
    history = np.array(stats.evaluation_history)
    assert len(history) == len(stats.cost_history)
    if not stats.cost_history:
        return
    assert len(history) == stats.iterations + 1
    assert np.all(np.diff(history) >= 0) and history[-1] > history[0]
    assert history[-1] == stats.evaluations


def test_the_repair_and_polish_come_after_the_last_recorded_iteration():
    problem = scenario_problem(load_scenario("restaurant-table-2"))
    params = {"population": 20, "iterations": 20, "mode": "robust"}
    bare = make_planner("gwo", dict(params, polish_rounds=0)).plan(problem, np.random.default_rng(3))
    polished = make_planner("gwo", params).plan(problem, np.random.default_rng(3))
    assert polished.stats.extra["polish_rounds"] > 0
    # The search is the same; only the polish after it differs.
    assert polished.stats.evaluation_history == bare.stats.evaluation_history
    assert polished.stats.evaluations > polished.stats.evaluation_history[-1] == bare.stats.evaluations


def test_bee_colony_history_counts_employed_onlookers_and_scouts():
    """Karaboga's ABC: SN to score the first sources, then 2 SN a cycle plus the scout (Kamil et al. 2020
    abandon the worst exhausted source only: at most one a cycle), so cycles differ (an even spread of the
    total would not); ``scouts = "all"`` abandons every exhausted source."""
    problem = scenario_problem(load_scenario("restaurant-table-2"))
    sources = 20
    params = {"population": sources, "iterations": 20, "limit": 6, "mode": "robust", "stall_evaluations": 0}
    path = make_planner("abc", params).plan(problem, np.random.default_rng(3))
    history = np.array(path.stats.evaluation_history)
    steps = np.diff(history)
    assert history[0] == sources
    assert np.all(steps >= 2 * sources) and np.all(steps <= 2 * sources + 1)
    assert len(set(steps.tolist())) > 1
    every = make_planner("abc", dict(params, scouts="all", limit=2)).plan(problem, np.random.default_rng(3))
    steps = np.diff(every.stats.evaluation_history)
    assert np.all(steps <= 3 * sources) and steps.max() > 2 * sources + 1
    assert len(set(steps.tolist())) > 1


def test_pso_spends_one_swarm_an_iteration():
    problem = scenario_problem(load_scenario("restaurant-table-2"))
    path = make_planner("pso", {"population": 12, "iterations": 8, "mode": "robust", "stall_evaluations": 0}).plan(
        problem, np.random.default_rng(3))
    assert np.array_equal(np.diff(path.stats.evaluation_history), np.full(8, 12))


def test_a_via_point_growth_keeps_the_last_search_after_the_failed_ones():
    """Robust mode reran the search with twice the via-points: the histories are the last search's, and its
    evaluation counts start after what the failed search spent, so they still end at the total."""
    problem = scenario_problem(load_scenario("restaurant-table-5"))
    population, iterations = 10, 5
    params = dict(population=population, iterations=iterations, via_points=1, guess_fraction=0.0, polish_rounds=0,
                  repair_rounds=0, mode="robust")
    grown = None
    for seed in range(10):
        try:
            path = make_planner("pso", params).plan(problem, np.random.default_rng(seed))
        except PlanningError:
            continue
        if path.stats.extra["via_point_growths"]:
            grown = path
            break
    assert grown is not None, "no seed needed a second search"
    stats = grown.stats
    assert len(stats.evaluation_history) == len(stats.cost_history) == iterations + 1
    assert stats.evaluation_history[-1] == stats.evaluations
    assert stats.evaluation_history[0] == stats.evaluations - iterations * population > population
