"""The continuous planners' robust mode and its options (planners/continuous.py, run_settings.py,
path_guess.py, polish.py); the paper mode's independence of the scene's file is in test_fair_comparison.py."""

from __future__ import annotations

import numpy as np
import pytest

from swarmnav.models.scenario import load_scenario
from swarmnav.planners.registry import make_planner
from swarmnav.planners.optimal import OptimalPlanner
from swarmnav.planners.path_guess import fit_via_points, pushed_fit_via_points, resample_by_length, tangent_route_for
from swarmnav.planners.polish import compass_polish
from swarmnav.planners.problem import scenario_problem
from swarmnav.planners.random_fields import random_disc_field
from swarmnav.planners.via_points import ViaPointCurve

CONTINUOUS = ("abc", "adl_abc", "gwo", "pso")
SMALL = {"population": 30, "iterations": 40}


def _optimum(problem) -> float:
    return OptimalPlanner().plan(problem, np.random.default_rng(0)).stats.extra["optimum_length_m"]


@pytest.mark.parametrize("planner", CONTINUOUS)
@pytest.mark.parametrize("field", [(15, 3), (30, 5), (40, 9)])
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
    assert first.same_as(again)
    # The seeded fit may win whatever the seed; without seeds the draws show.
    unseeded = dict(SMALL, mode="robust", guess_fraction=0.0, via_points=5)
    first = make_planner(planner, unseeded).plan(problem, np.random.default_rng(4))
    other = make_planner(planner, unseeded).plan(problem, np.random.default_rng(5))
    assert not first.same_as(other)


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


@pytest.mark.parametrize("field", [(13, 1), (26, 5), (40, 9), (36, 8)])
def test_tangent_route_is_the_exact_optimum(field):
    """The whole-array tangent graph finds the same shortest length as the yardstick's."""
    problem = random_disc_field(*field)
    route = tangent_route_for(problem, 0.0)
    assert route.turns >= 1
    assert abs(route.length_m - _optimum(problem)) < 1e-6
    polyline_m = float(np.sum(np.hypot(*np.diff(route.waypoints, axis=0).T)))
    assert abs(polyline_m - route.length_m) < 2e-3 * route.length_m      # arcs sampled as chords
    np.testing.assert_allclose(route.waypoints[[0, -1]], [problem.start.xy, problem.goal.xy])


def test_tangent_route_around_one_disc_and_none_through_a_wall():
    from swarmnav.models.world import Rect
    from swarmnav.planners.tangent_guess import tangent_route

    bounds = Rect(0.0, 0.0, 4.0, 2.0)
    route = tangent_route(np.array([0.0, 1.0]), np.array([4.0, 1.0]), np.array([[2.0, 1.0]]), np.array([1.0]),
                          bounds)
    # two tangents of length sqrt(3) and an arc of 60 degrees on the unit circle
    assert route.length_m == pytest.approx(2.0 * np.sqrt(3.0) + np.pi / 3.0)
    assert route.turns == 1
    wall = np.array([[2.0, y] for y in np.arange(0.0, 2.01, 0.25)])
    assert tangent_route(np.array([0.5, 1.0]), np.array([3.5, 1.0]), wall, np.full(len(wall), 0.2), bounds) is None


def test_pushed_fit_clears_the_discs_the_plain_fit_cuts():
    problem = random_disc_field(40, 9)
    route = tangent_route_for(problem, 0.02)
    curve = ViaPointCurve("spline", 2 * route.turns + 3, problem.start.xy, problem.goal.xy, 100)
    radii = problem.inflated_radii_m + 0.02

    def deepest_cut_m(solution):
        xs, ys = curve.sample(solution[None, :])
        gaps = np.hypot(xs[0][:, None] - problem.disc_centres_m[:, 0], ys[0][:, None] - problem.disc_centres_m[:, 1])
        return float(np.max(radii - gaps))

    plain = fit_via_points(curve, route.waypoints)
    pushed = pushed_fit_via_points(curve, route.waypoints, problem.disc_centres_m, radii, 10)
    assert deepest_cut_m(plain) > 0.01
    assert deepest_cut_m(pushed) < 0.25 * deepest_cut_m(plain)
    np.testing.assert_allclose(pushed_fit_via_points(curve, route.waypoints, problem.disc_centres_m, radii, 0),
                               plain, atol=1e-9)


@pytest.mark.parametrize("planner", CONTINUOUS)
def test_the_robust_search_stops_on_stall_and_the_paper_runs_every_iteration(planner):
    problem = random_disc_field(20, 1)
    stalled = make_planner(planner, {"mode": "robust", "iterations": 100}).plan(problem, np.random.default_rng(3))
    full = make_planner(planner, {"mode": "robust", "iterations": 100, "stall_evaluations": 0}).plan(
        problem, np.random.default_rng(3))
    assert stalled.stats.extra["stopped_on_stall"] and not full.stats.extra["stopped_on_stall"]
    assert stalled.stats.iterations < full.stats.iterations == 100
    assert stalled.stats.evaluations < full.stats.evaluations
    # the last improvement of the best by more than the tolerance is at least 10 populations back
    history = np.asarray(stalled.stats.cost_history)
    assert history[-1] >= history[-2] * (1.0 - 1e-4)
    paper = make_planner(planner, dict(SMALL, mode="paper", penalty_weight=1000.0, penalty_margin_m=0.02,
                                       population_fallback=True)).plan(
        scenario_problem(load_scenario("gwo-scenario-1"), clearance_m=0.0), np.random.default_rng(3))
    assert paper.stats.iterations == SMALL["iterations"] and not paper.stats.extra["stopped_on_stall"]


def test_gap_margins_keep_a_narrow_gap_open_and_the_robust_mode_threads_it():
    """Field (25, 142): the optimum passes a gap narrower than twice the penalty's 2 cm
    margin; a uniform margin closed it (1.16 x the optimum), the gap margins keep it."""
    from swarmnav.planners.path_guess import gap_margins_m

    problem = random_disc_field(25, 142)
    margins = gap_margins_m(problem, 0.02)
    centres, radii = problem.disc_centres_m, problem.inflated_radii_m
    gaps = np.hypot(*(centres[:, None, :] - centres[None, :, :]).transpose(2, 0, 1)) - radii[:, None] - radii
    np.fill_diagonal(gaps, np.inf)
    open_pairs = gaps > 0
    assert np.any(open_pairs & (gaps < 0.04))
    assert np.all((margins[:, None] + margins[None, :] < gaps) | ~open_pairs)
    assert np.all(margins <= 0.02) and np.any(margins == 0.02)
    optimum = _optimum(problem)
    lengths = [make_planner("gwo", {"mode": "robust"}).plan(problem, np.random.default_rng(seed)).stats.length_m
               for seed in range(3)]
    uniform = make_planner("gwo", {"mode": "robust", "gap_margins": False}).plan(problem, np.random.default_rng(0))
    assert np.median(lengths) <= 1.03 * optimum < uniform.stats.length_m


def test_fast_gap_matches_the_exact_clearance():
    from swarmnav.planners.segment_gaps import polyline_gap_m

    problem = random_disc_field(30, 5)
    rng = np.random.default_rng(0)
    cuts = 0
    for _ in range(200):
        start = rng.uniform(0.0, 10.0, 2)
        points = start + np.cumsum(rng.normal(0.0, 0.3, (rng.integers(1, 200), 2)), axis=0)
        exact = problem.path_clearance_m(points)
        fast = polyline_gap_m(points, problem.disc_centres_m, problem.inflated_radii_m, chunk=8)
        assert fast >= exact - 1e-9
        if exact < 0:
            cuts += 1
            assert abs(fast - exact) < 1e-9
    assert 20 < cuts < 190
    # all discs measured (one chunk whose box covers the arena): the same gap
    corners = np.array([[0.0, 0.0], [10.0, 10.0], [0.0, 10.0], [10.0, 0.0]])
    assert abs(polyline_gap_m(corners, problem.disc_centres_m, problem.inflated_radii_m)
               - problem.path_clearance_m(corners)) < 1e-9
    # a segment of zero length, and one ending exactly on an inflated edge
    centre, radius = problem.disc_centres_m[0], problem.inflated_radii_m[0]
    on_edge = np.array([centre + [radius, 0.0], centre + [radius + 1.0, 0.0]])
    assert abs(polyline_gap_m(on_edge, problem.disc_centres_m[:1], problem.inflated_radii_m[:1])) < 1e-12
    point = np.array([[5.0, 5.0]])
    assert abs(polyline_gap_m(point, problem.disc_centres_m, problem.inflated_radii_m)
               - problem.path_clearance_m(point)) < 1e-9


def test_robust_guess_is_the_tangent_graph_up_to_its_disc_limit_then_the_grid():
    from swarmnav.models.world import Disc, Pose2D, Rect
    from swarmnav.planners.path_guess import MAX_TANGENT_DISCS
    from swarmnav.planners.problem import Problem

    def lattice(count):
        side = int(np.ceil(np.sqrt(count)))
        discs = tuple(Disc(1.5 + 1.0 * (i % side), 1.5 + 1.0 * (i // side), 0.15) for i in range(count))
        arena = 2.0 + side
        return Problem(Pose2D(0.5, 0.5, 0.0), Pose2D(arena - 0.5, arena - 0.5, 0.0), Rect(0.0, 0.0, arena, arena),
                       discs, robot_radius_m=0.15, clearance_m=0.05)

    small = make_planner("gwo", dict(SMALL, mode="robust")).plan(lattice(16), np.random.default_rng(0))
    large = make_planner("gwo", dict(SMALL, mode="robust")).plan(lattice(MAX_TANGENT_DISCS + 1),
                                                                np.random.default_rng(0))
    assert small.stats.extra["guess"] == "tangent" and large.stats.extra["guess"] == "grid"
    assert make_planner("gwo", dict(SMALL, mode="paper")).settings_for(lattice(16)).guess == "none"


@pytest.mark.parametrize("scenario", ["adl-abc-path-1", "adl-abc-path-2"])
def test_robust_mode_fails_at_once_where_the_exact_planner_proves_no_path(scenario):
    from swarmnav.planners.errors import NoPathFound

    problem = scenario_problem(load_scenario(scenario), clearance_m=0.0)
    with pytest.raises(NoPathFound):
        OptimalPlanner().plan(problem, np.random.default_rng(0))
    with pytest.raises(NoPathFound, match="tangent graph"):
        make_planner("gwo", {"mode": "robust"}).plan(problem, np.random.default_rng(0))
    # the paper's algorithm searches (and fails) as written
    with pytest.raises(NoPathFound) as paper:
        make_planner("gwo", dict(SMALL, mode="paper")).plan(problem, np.random.default_rng(0))
    assert "tangent graph" not in str(paper.value)
