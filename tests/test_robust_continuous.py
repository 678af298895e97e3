"""The continuous planners' modes: the paper's algorithm on the papers' instances, the robust
options elsewhere (planners/continuous.py, path_guess.py, polish.py, paper_instances.py)."""

from __future__ import annotations

import numpy as np
import pytest

from swarmnav.models.scenario import load_scenario
from swarmnav.planners.registry import make_planner
from swarmnav.planners.optimal import OptimalPlanner
from swarmnav.planners.path_guess import fit_via_points, resample_by_length
from swarmnav.planners.polish import compass_polish
from swarmnav.planners.problem import scenario_problem
from swarmnav.planners.random_fields import random_disc_field
from swarmnav.planners.via_points import ViaPointCurve

CONTINUOUS = ("abc", "adl_abc", "gwo", "pso")
SMALL = {"population": 30, "iterations": 40}


def _optimum(problem) -> float:
    return OptimalPlanner().plan(problem, np.random.default_rng(0)).stats.extra["optimum_length_m"]


@pytest.mark.parametrize("planner", CONTINUOUS)
def test_auto_is_the_paper_on_the_papers_instances_and_robust_elsewhere(planner):
    paper_scene = scenario_problem(load_scenario("gwo-scenario-1"), clearance_m=0.0)
    auto = make_planner(planner, SMALL).plan(paper_scene, np.random.default_rng(2))
    paper = make_planner(planner, dict(SMALL, mode="paper")).plan(paper_scene, np.random.default_rng(2))
    assert auto.stats.extra["mode"] == "paper" and auto.stats.extra["paper_instance"] == "gwo-scenario-1"
    assert auto.same_as(paper)
    assert auto.stats.extra["via_point_count"] == 3
    other = scenario_problem(load_scenario("restaurant-table-5"))
    assert make_planner(planner, SMALL).plan(other, np.random.default_rng(2)).stats.extra["mode"] == "robust"


@pytest.mark.parametrize("planner", CONTINUOUS)
@pytest.mark.parametrize("field", [(15, 3), (30, 5)])
def test_robust_on_random_fields_is_feasible_and_near_the_optimum(planner, field):
    problem = random_disc_field(*field)
    optimum = _optimum(problem)
    lengths = []
    for seed in range(3):
        path = make_planner(planner, {"mode": "robust"}).plan(problem, np.random.default_rng(seed))
        assert problem.is_collision_free(path.waypoints)
        assert path.stats.length_m >= optimum - 1e-6
        lengths.append(path.stats.length_m)
    assert np.median(lengths) <= 1.03 * optimum, (planner, field, np.median(lengths) / optimum)


@pytest.mark.parametrize("planner", CONTINUOUS)
def test_robust_same_seed_same_path(planner):
    problem = random_disc_field(20, 1)
    first = make_planner(planner, dict(SMALL, mode="robust")).plan(problem, np.random.default_rng(4))
    again = make_planner(planner, dict(SMALL, mode="robust")).plan(problem, np.random.default_rng(4))
    other = make_planner(planner, dict(SMALL, mode="robust")).plan(problem, np.random.default_rng(5))
    assert first.same_as(again) and not first.same_as(other)


def test_robust_beats_the_paper_on_dense_field_30():
    problem = scenario_problem(load_scenario("dense-field-30"))
    optimum = _optimum(problem)
    robust = make_planner("gwo", {"mode": "robust"}).plan(problem, np.random.default_rng(0))
    assert robust.stats.length_m <= 1.03 * optimum
    assert robust.stats.extra["via_point_count"] > 3


def test_fit_recovers_via_points_of_a_curve_it_can_draw():
    """A polyline drawn by the encoding itself is fitted back to its own via-points (the
    curve samples are at equal parameter steps, so the polyline's length fractions are
    those of the parameter only for the polyline encoding with equal-length legs)."""
    curve = ViaPointCurve("polyline", 3, np.array([0.0, 0.0]), np.array([4.0, 0.0]), 101)
    truth = np.array([1.0, 2.0, 3.0, 1.0, 0.0, -1.0])       # x then y, legs of equal length
    legs = np.hypot(*np.diff(curve.knots(truth), axis=0).T)
    assert np.allclose(legs, legs[0])
    np.testing.assert_allclose(fit_via_points(curve, curve.knots(truth)), truth, atol=1e-9)
    pts = resample_by_length(np.array([[0.0, 0.0], [2.0, 0.0]]), np.array([0.0, 0.25, 1.0]))
    np.testing.assert_allclose(pts, [[0.0, 0.0], [0.5, 0.0], [2.0, 0.0]])


def test_compass_polish_finds_a_quadratic_minimum_and_falls_back_to_the_last_accepted():
    target = np.array([0.3, -0.2])
    cost = lambda x: np.sum((np.atleast_2d(x) - target) ** 2, axis=1)  # noqa: E731
    lower, upper = np.full(2, -1.0), np.full(2, 1.0)
    best, best_cost, _ = compass_polish(np.zeros(2), float(cost(np.zeros(2))[0]), cost, lambda x: True,
                                        lower, upper, 0.5, 200, 1e-6)
    np.testing.assert_allclose(best, target, atol=1e-5)
    # Nothing with x > 0.1 passes: the result is the newest incumbent that does.
    best, _, _ = compass_polish(np.zeros(2), float(cost(np.zeros(2))[0]), cost, lambda x: x[0] <= 0.1,
                                lower, upper, 0.5, 200, 1e-6)
    assert best[0] <= 0.1
