"""The tangent graph (planners/tangent_graph.py) behind ``optimal`` and the robust guess, checked
against references that share none of its code: closed forms, and a brute-force visibility
graph among polygons circumscribed about the discs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from swarmnav.models.geometry import segment_disc_distances
from swarmnav.models.world import Disc, Pose2D, Rect
from swarmnav.planners.optimal import OptimalPlanner
from swarmnav.planners.problem import Problem
from swarmnav.planners.tangent_guess import tangent_route

POLYGON_SIDES = 128


def _polygon_visibility_length(problem: Problem, sides: int = POLYGON_SIDES) -> float:
    """Shortest path through the vertices of ``sides``-gons circumscribed about the inflated
    discs, every segment checked against the discs themselves (a plain O(V^2) Dijkstra).

    Every such path avoids the discs, so its length is at least the optimum; and it is at
    most the optimum among discs grown to the polygons' outer radius, ``r / cos(pi / sides)``.
    """
    centres, radii = problem.disc_centres_m, problem.inflated_radii_m
    angles = 2.0 * math.pi * np.arange(sides) / sides
    outer = radii / math.cos(math.pi / sides)
    directions = np.stack([np.cos(angles), np.sin(angles)], -1)
    vertices = (centres[:, None, :] + outer[:, None, None] * directions).reshape(-1, 2)
    gaps = np.hypot(*(vertices[:, None, :] - centres[None, :, :]).transpose(2, 0, 1)) - radii
    b = problem.bounds
    keep = (np.all(gaps >= 0.0, axis=1) & (vertices[:, 0] >= b.x_min_m) & (vertices[:, 0] <= b.x_max_m)
            & (vertices[:, 1] >= b.y_min_m) & (vertices[:, 1] <= b.y_max_m))
    nodes = np.vstack([problem.start.xy, problem.goal.xy, vertices[keep]])
    i, j = np.triu_indices(nodes.shape[0], 1)
    clear = np.all(segment_disc_distances(nodes[i], nodes[j], centres) >= radii - 1e-9, axis=1)
    weight = np.full((nodes.shape[0],) * 2, np.inf)
    weight[i[clear], j[clear]] = weight[j[clear], i[clear]] = np.hypot(*(nodes[j[clear]] - nodes[i[clear]]).T)
    distance = np.full(nodes.shape[0], np.inf)
    distance[0] = 0.0
    done = np.zeros(nodes.shape[0], dtype=bool)
    while not done[1]:
        u = int(np.argmin(np.where(done, np.inf, distance)))
        if not math.isfinite(distance[u]):
            return math.inf
        done[u] = True
        distance = np.minimum(distance, distance[u] + weight[u])
    return float(distance[1])


def _well_separated_instances(count: int) -> list[Problem]:
    """Random small instances (1-4 discs, some overlapping) with no near-tangency that a
    small growth of the discs could close: every pair of circles, endpoint and disc, and
    disc and bound is 2 cm clear of touching."""
    rng = np.random.default_rng(20261122)
    bounds = Rect(0.0, 0.0, 6.0, 4.0)
    out = []
    while len(out) < count:
        n = int(rng.integers(1, 5))
        discs = tuple(Disc(float(rng.uniform(1.0, 5.0)), float(rng.uniform(0.8, 3.2)), float(rng.uniform(0.2, 0.6)))
                      for _ in range(n))
        start, goal = rng.uniform([0.0, 0.0], [1.0, 4.0]), rng.uniform([5.0, 0.0], [6.0, 4.0])
        problem = Problem(Pose2D(*start), Pose2D(*goal), bounds, discs, robot_radius_m=0.1)
        c, r = problem.disc_centres_m, problem.inflated_radii_m
        pair_d = np.hypot(*(c[:, None, :] - c[None, :, :]).transpose(2, 0, 1))
        near = [abs(pair_d[a, k] - (r[a] + r[k])) < 0.02 or abs(pair_d[a, k] - abs(r[a] - r[k])) < 0.02
                for a in range(n) for k in range(a + 1, n)]
        ends = np.hypot(*(np.vstack([start, goal])[:, None, :] - c[None]).transpose(2, 0, 1)) - r
        walls = np.min(np.column_stack([c[:, 0] - r, 6.0 - c[:, 0] - r, c[:, 1] - r, 4.0 - c[:, 1] - r]), axis=1)
        if any(near) or np.any(ends < 0.02) or np.any(np.abs(walls) < 0.02):
            continue
        out.append(problem)
    return out


@pytest.mark.parametrize("problem", _well_separated_instances(12))
def test_optimum_agrees_with_a_brute_force_polygon_visibility_graph(problem):
    brute_m = _polygon_visibility_length(problem)
    path = OptimalPlanner().plan(problem, np.random.default_rng(0))
    optimum_m = path.stats.extra["optimum_length_m"]
    # the brute force's path avoids the discs: never shorter than the optimum ...
    assert optimum_m <= brute_m + 1e-9
    # ... and it is no longer than the optimum among discs grown by the polygons' bulge, which
    # adds at most (growth x total turning <= 2 pi per disc) to the optimum
    growth_m = float(np.max(problem.inflated_radii_m)) * (1.0 / math.cos(math.pi / POLYGON_SIDES) - 1.0)
    assert brute_m <= optimum_m + 2.0 * math.pi * len(problem.obstacles) * growth_m
    straight_m = float(np.hypot(*(problem.goal.xy - problem.start.xy)))
    assert optimum_m >= straight_m - 1e-12
    assert problem.is_collision_free(path.waypoints)
    # the circumscribed polyline is a hair longer than the exact length it follows
    assert optimum_m - 1e-9 <= path.stats.length_m <= optimum_m * (1.0 + 1e-4)


@pytest.mark.parametrize("y_min_m", [-0.7, -0.75])
def test_bounds_send_the_route_round_the_long_side(y_min_m):
    """The short way round the disc sweeps down to y = -0.8, below the bound; its tangent points
    (y = -0.71) lie outside the bound at -0.7 and inside it at -0.75, where only the arc leaves.
    So the optimum is the long way over the top, as the brute force (which drops vertices
    outside) finds."""
    disc = (Disc(2.0, 0.2, 0.9),)
    free = Problem(Pose2D(0.0, 0.0), Pose2D(4.0, 0.0), Rect(-1.0, -2.0, 5.0, 2.0), disc, robot_radius_m=0.1)
    walled = Problem(Pose2D(0.0, 0.0), Pose2D(4.0, 0.0), Rect(-1.0, y_min_m, 5.0, 2.0), disc, robot_radius_m=0.1)
    short_m = OptimalPlanner().plan(free, np.random.default_rng(0)).stats.extra["optimum_length_m"]
    path = OptimalPlanner().plan(walled, np.random.default_rng(0))
    long_m = path.stats.extra["optimum_length_m"]
    assert long_m > short_m + 0.1
    assert long_m == pytest.approx(_polygon_visibility_length(walled), abs=2e-3)
    assert short_m == pytest.approx(_polygon_visibility_length(free), abs=2e-3)
    assert walled.is_collision_free(path.waypoints)


def test_arcs_go_round_the_discs_that_overlap_them():
    """Small discs overlapping the top and the bottom of a big one: the route must wrap them
    too, not follow the big circle through them (the brute force agrees)."""
    discs = (Disc(3.0, 0.0, 0.9), Disc(3.0, 1.1, 0.2), Disc(3.0, -1.1, 0.2))
    problem = Problem(Pose2D(0.0, 0.0), Pose2D(6.0, 0.0), Rect(-1.0, -3.0, 7.0, 3.0), discs, robot_radius_m=0.1)
    path = OptimalPlanner().plan(problem, np.random.default_rng(0))
    one_disc_m = 2.0 * math.sqrt(9.0 - 1.0) + math.pi - 2.0 * math.acos(1.0 / 3.0)   # round the big disc alone
    assert path.stats.extra["optimum_length_m"] > one_disc_m + 0.01
    assert path.stats.extra["optimum_length_m"] == pytest.approx(_polygon_visibility_length(problem), abs=2e-3)
    assert problem.is_collision_free(path.waypoints)


def test_two_discs_in_a_row_closed_form():
    """Unit discs at (2, 0) and (5, 0), start (0, 0), goal (7, 0): a tangent of length sqrt(3)
    reaching the first disc at 120 degrees, an arc of 30 degrees to its top, the outer
    bitangent y = 1 of length 3, and the mirror image."""
    problem = Problem(Pose2D(0.0, 0.0), Pose2D(7.0, 0.0), Rect(-1.0, -3.0, 8.0, 3.0),
                      (Disc(2.0, 0.0, 0.9), Disc(5.0, 0.0, 0.9)), robot_radius_m=0.1)
    closed_m = 2.0 * math.sqrt(3.0) + 2.0 * (math.pi / 6.0) + 3.0
    path = OptimalPlanner().plan(problem, np.random.default_rng(0))
    assert path.stats.extra["optimum_length_m"] == pytest.approx(closed_m, abs=1e-12)
    route = tangent_route(problem.start.xy, problem.goal.xy, problem.disc_centres_m, problem.inflated_radii_m,
                          problem.bounds)
    assert route.length_m == pytest.approx(closed_m, abs=1e-12)
    assert route.turns == 2
