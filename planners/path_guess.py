"""A fast geometric guess for the continuous planners' robust mode, and its via-points.

Three of the robust options of :class:`planners.continuous.ContinuousPlanner` start here:

* the guess, ``guess = "tangent"`` (the robust default, :func:`tangent_guesses`): the
  shortest route of the tangent graph (:mod:`planners.tangent_guess`) around the inflated
  discs grown by the penalty's margin; on the ten random fields of ``bench planners`` it is
  the exact optimum's route (the A* guess below was up to 1.03 x it, in the wrong homotopy
  class on the 40-disc field) in 1-6 ms;
* or ``guess = "grid"`` (:func:`grid_guesses`): a grid A* path, exactly shortcut by line of sight
  (:class:`planners.grid_search.AStarPlanner`), on the problem's own grid of the inflated
  discs (``guess_cell_m`` to choose another cell).  On dense-field-30 it is 1.007 x the
  exact optimum in about 10 ms (the exact tangent graph, :mod:`planners.tangent_graph`, now
  takes about 7 ms there, so it is the default guess up to 100 discs).  A coarser grid is faster but closes narrow gaps: on one random 33-disc
  field the 0.1 m guess is 1.14 x the optimum, the 0.05 m one 1.013 x; starting from both
  let the wrong one win (its fit is clear of the discs, the right one's cuts a little);
* the number of via-points chosen from the scene: for the tangent guess
  :func:`via_points_for_turns` (two per turn plus seven), for the grid guess
  :func:`via_points_for_guess`: one per bend of the guess plus two; either between 3 (the
  papers') and :data:`MAX_AUTO_VIA_POINTS` (with the grid guess on dense-field-30, 5, 8
  and 13 via-points gave the same median length, 1.002-1.003 x the optimum; 3 cannot
  follow its six bends);
* the guess's fit, :func:`fit_via_points`: the via-points whose curve is nearest the guess in
  the least-squares sense (the curve is linear in the via-points, so this is one
  ``lstsq``), moved out of the discs it cuts (:func:`pushed_fit_via_points`), then
  perturbed copies (:func:`population_around`).

Seeding an initial population with a heuristic solution is the standard hybrid
initialisation of population methods (e.g. Kazimipour, Li & Qin 2014, "A review of
population initialization techniques for evolutionary algorithms", CEC 2014, Sect. III-C).
"""

from __future__ import annotations

import numpy as np

from swarmnav.planners.errors import PlanningError
from swarmnav.planners.problem import Problem
from swarmnav.planners.segment_gaps import row_blocks
from swarmnav.planners.tangent_guess import TangentRoute, tangent_route
from swarmnav.planners.via_points import ViaPointCurve

#: Most via-points :func:`via_points_for_guess` chooses.
MAX_AUTO_VIA_POINTS = 16
#: Most discs the robust mode's default guess builds a tangent graph for (its work grows as
#: the cube of the discs: about 10 ms for 40, 0.1-0.2 s for 100, 2.4 s for 400); above, the
#: default is the grid guess, whose work grows with the grid's cells.
MAX_TANGENT_DISCS = 100
#: Most via-points :func:`via_points_for_turns` chooses.
MAX_TURN_VIA_POINTS = 24
#: Via-points beyond two per turn of a tangent route (:func:`via_points_for_turns`).
TURN_EXTRA_VIA_POINTS = 7
#: Share of an open gap between two footprints a penalty margin may take (:func:`gap_margins_m`).
GAP_SHARE = 0.4
#: How far :func:`pushed_fit_via_points` moves a target per unit depth of its sample.
PUSH_GAIN = 2.0


def grid_guesses(problem: Problem, cell_m: float | None = None) -> tuple[np.ndarray, ...]:
    """The (N, 2) waypoints of the shortcut A* path at ``cell_m`` (None: the problem's cell),
    as a tuple of one, or of none when the grid has no path."""
    from swarmnav.planners.grid_search import AStarPlanner

    try:
        return (AStarPlanner(cell_m=cell_m).plan(problem, np.random.default_rng(0)).waypoints,)
    except PlanningError:
        return ()


def gap_margins_m(problem: Problem, margin_m: float, share: float = GAP_SHARE) -> np.ndarray:
    """(n,) each disc's penalty margin: ``margin_m``, but at most ``share`` of every open gap
    between its inflated footprint and another's, and ``2 share`` of the gap to each
    arena wall, so that a margin never closes a gap the robot fits through (gaps already
    closed, overlapping footprints, are left alone).

    The penalty's margin keeps a curve sampled at ``samples`` points from cutting a disc
    between two samples; a uniform 2 cm margin also closes every gap narrower than 4 cm, and
    on 4 of 60 further random fields the optimum threads such a gap (the robust mode's
    result was then 1.03-1.16 x the optimum in the next homotopy class)."""
    centres, radii = problem.disc_centres_m, problem.inflated_radii_m
    n = radii.size
    margins = np.full(n, float(margin_m))
    if n == 0:
        return margins
    nearest = np.empty(n)
    for block in row_blocks(n, n):
        gaps = (np.hypot(centres[block, None, 0] - centres[None, :, 0], centres[block, None, 1] - centres[None, :, 1])
                - radii[block, None] - radii[None, :])
        gaps[np.arange(gaps.shape[0]), np.arange(n)[block]] = np.inf
        gaps[gaps <= 0.0] = np.inf
        nearest[block] = gaps.min(axis=1)
    b = problem.bounds
    walls = np.column_stack([centres[:, 0] - b.x_min_m, b.x_max_m - centres[:, 0],
                             centres[:, 1] - b.y_min_m, b.y_max_m - centres[:, 1]]) - radii[:, None]
    walls[walls <= 0.0] = np.inf
    return np.minimum(margins, np.minimum(share * nearest, 2.0 * share * walls.min(axis=1)))


def tangent_guesses(problem: Problem, margin_m: float | np.ndarray = 0.0) -> tuple[np.ndarray, ...]:
    """The (N, 2) waypoints of the shortest route of the tangent graph
    (:func:`planners.tangent_guess.tangent_route`) around the inflated discs grown by
    ``margin_m`` (never so far that a grown disc would reach the start or the goal), as a
    tuple of one, or of none when the grown discs separate start from goal."""
    route = tangent_route_for(problem, margin_m)
    return () if route is None else (route.waypoints,)


def tangent_route_for(problem: Problem, margin_m: float | np.ndarray = 0.0) -> TangentRoute | None:
    """:func:`planners.tangent_guess.tangent_route` of ``problem``'s inflated discs grown by
    ``margin_m`` (one for all, or one per disc; capped a micrometre short of the start and
    the goal)."""
    centres, radii = problem.disc_centres_m, problem.inflated_radii_m
    reach = np.minimum(np.hypot(*(centres - problem.start.xy).T), np.hypot(*(centres - problem.goal.xy).T))
    grown = np.maximum(np.minimum(radii + margin_m, reach - 1e-6), radii)
    return tangent_route(problem.start.xy, problem.goal.xy, centres, grown, problem.bounds)


def scene_guesses(problem: Problem, kind: str, cell_m: float | None = None,
                  margin_m: float | np.ndarray = 0.0) -> tuple[tuple[np.ndarray, ...], int]:
    """The guesses of ``kind`` ("grid": :func:`grid_guesses`, "tangent": the route of
    :func:`tangent_route_for` with ``margin_m``, or without margins when they close every
    way) and the via-points a curve needs to follow them (:func:`via_points_for_guess`,
    :func:`via_points_for_turns`; the papers' 3 when there is no guess).  No tangent guess
    means that no collision-free path exists (the tangent graph without margins is exact)."""
    if kind == "tangent":
        route = tangent_route_for(problem, margin_m)
        if route is None and np.any(np.asarray(margin_m) > 0):
            route = tangent_route_for(problem, 0.0)   # the margins closed the only way through
        if route is None:
            return (), 3                              # the exact graph has no route: no path exists
        return (route.waypoints,), via_points_for_turns(route.turns)
    guesses = grid_guesses(problem, cell_m)
    return guesses, max((via_points_for_guess(g) for g in guesses), default=3)


def via_points_for_turns(turns: int) -> int:
    """Via-points for a curve that follows a tangent route of ``turns`` arcs: ``2 turns +``
    :data:`TURN_EXTRA_VIA_POINTS`, clamped to [3, :data:`MAX_TURN_VIA_POINTS`], and 3 for a
    straight route (on the ten random fields of ``bench planners``, the pushed fit with one
    via-point per turn plus one to three still cuts discs by up to 5 cm, with two per turn
    plus three it is clear of them, at most 1.01 x the optimum; on fields whose route makes 7-9 turns a cap of 16
    left the fit cutting by up to 3 mm, where 17-21 via-points clear it; and a short route
    with one turn, restaurant-table-5's, needs more: 5 via-points end at 1.0094 x the
    optimum, 7 at 1.0054, 9 at 1.0037, its grown route's own 1.0031, hence plus seven)."""
    if turns == 0:
        return 3                  # a straight route: the papers' count draws it exactly
    return int(min(max(2 * turns + TURN_EXTRA_VIA_POINTS, 3), MAX_TURN_VIA_POINTS))


def via_points_for_guess(waypoints: np.ndarray) -> int:
    """Via-points for a curve that follows ``waypoints``: ``bends + 2``, clamped to
    [3, :data:`MAX_AUTO_VIA_POINTS`] (3 is the papers' count)."""
    bends = max(np.asarray(waypoints).reshape(-1, 2).shape[0] - 2, 0)
    return int(min(max(bends + 2, 3), MAX_AUTO_VIA_POINTS))


def resample_by_length(waypoints: np.ndarray, fractions: np.ndarray) -> np.ndarray:
    """(len(fractions), 2) points at the given fractions of the polyline's length."""
    pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
    if along[-1] <= 0.0:
        return np.repeat(pts[:1], fractions.size, axis=0)
    at = np.asarray(fractions, dtype=float) * along[-1]
    return np.column_stack([np.interp(at, along, pts[:, 0]), np.interp(at, along, pts[:, 1])])


def fit_via_points(curve: ViaPointCurve, waypoints: np.ndarray) -> np.ndarray:
    """(2k,) the decision vector whose sampled curve is nearest ``waypoints`` (least squares,
    sample ``s`` of the curve against the point at the same fraction of the guess's length)."""
    fractions = np.linspace(0.0, 1.0, curve.samples)
    target = resample_by_length(waypoints, fractions)                 # (S, 2)
    basis = curve._via_basis.T                                         # (S, k)
    rhs = target - curve._end_offset.T                                 # (S, 2)
    via, *_ = np.linalg.lstsq(basis, rhs, rcond=None)                  # (k, 2)
    return np.concatenate([via[:, 0], via[:, 1]])


def pushed_fit_via_points(curve: ViaPointCurve, waypoints: np.ndarray, centres_m: np.ndarray,
                          radii_m: np.ndarray, rounds: int, gain: float = PUSH_GAIN) -> np.ndarray:
    """(2k,) :func:`fit_via_points`, then ``rounds`` times: every curve sample inside a disc
    ``(centres_m, radii_m)`` moves its target point out along that disc's normal by ``gain``
    times its depth (the deepest disc per sample), and the curve is fitted again.

    A least-squares fit of a smooth curve to a route that hugs the discs cuts their corners
    (on the random fields by 2-20 cm); moving the targets out until the curve clears them is
    a fixed-point iteration of the alternating-projection kind (fit onto the curves the
    encoding can draw, then project the samples out of the discs; Bauschke & Borwein 1996,
    "On projection algorithms for solving convex feasibility problems", SIAM Review 38(3)),
    our choice for this step; the targets only ever move out, so the fit gets no shorter
    than it must.  It stops early once no sample is inside a disc."""
    target = resample_by_length(waypoints, np.linspace(0.0, 1.0, curve.samples))   # (S, 2)
    basis = curve._via_basis.T                                                        # (S, k)
    offset = curve._end_offset.T                                                      # (S, 2)
    inverse = np.linalg.pinv(basis)                                                   # (k, S)
    centres = np.asarray(centres_m, dtype=float).reshape(-1, 2)
    radii = np.asarray(radii_m, dtype=float).reshape(-1)
    via = inverse @ (target - offset)
    rows = np.arange(curve.samples)
    for _ in range(rounds if centres.size else 0):
        points = basis @ via + offset
        away = points[:, None, :] - centres[None, :, :]                               # (S, n, 2)
        distance = np.hypot(away[..., 0], away[..., 1])
        depth = radii[None, :] - distance
        deepest = np.argmax(depth, axis=1)
        worst = depth[rows, deepest]
        inside = worst > 0.0
        if not inside.any():
            break
        normal = away[rows, deepest] / np.maximum(distance[rows, deepest], 1e-12)[:, None]
        target[inside] += gain * worst[inside, None] * normal[inside]
        via = inverse @ (target - offset)
    return np.concatenate([via[:, 0], via[:, 1]])


def population_around(fit: np.ndarray, count: int, spread_m: float, lower: np.ndarray,
                      upper: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """``count`` copies of ``fit``: the first exact, the others with Gaussian noise whose
    standard deviation grows linearly up to ``spread_m``; clipped to the search box."""
    scale = np.linspace(0.0, spread_m, max(count, 1))[:count, None]
    noise = rng.normal(0.0, 1.0, (count, fit.size)) * scale
    return np.clip(fit[None, :] + noise, lower, upper)
