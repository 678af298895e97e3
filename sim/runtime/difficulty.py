"""How hard a scenario is, before any navigator drives it: `swarmnav scenarios info SCENARIO`.

Static (BARN, Perille, Truong, Xiao & Stone 2020; our reading of two of their metrics):

* ``static_density``: the share of the plane covered by static obstacles (discs, map boxes) within
  ``DENSITY_RADIUS_M`` of the static shortest path, averaged over points every 0.1 m along it (BARN counts
  occupied cells around each cell of the path; we sample the same thing on a 0.05 m raster).
* ``dispersion``: from each of those points, ``DISPERSION_RAYS`` rays of ``DISPERSION_RANGE_M``; the number
  of free-to-occupied alternations along each, averaged (BARN: alternations between obstacle and free
  space along rays, how fragmented the surroundings are).

Dynamic (Shi, Chen, Serra Gomez, Wu & Alonso-Mora 2024; the paper defines them over recorded obstacle
trajectories; our reading):

* ``survival_time_s``: a robot standing still at sampled free positions (a 0.5 m lattice, clear of the
  static obstacles) survives until a moving obstacle's footprint first touches its disc; the mean of those
  times, capped at the scene's time limit.  ``survivability`` = 1 - survival_time_s / time limit, so that, as
  the paper reports for its survivability, a *lower* value goes with a *higher* success rate.
* ``dynamic_traversability``: at the same positions, every 2 s, the share of the robot's velocity set (speeds
  up to its top speed, 16 directions, and standing still) outside the velocity obstacles of the moving
  obstacles, truncated at ``VO_HORIZON_S`` (Fiorini & Shiller 1998 via
  :func:`~controllers.prediction.time_to_collision_s`; velocities from the true motion over one control
  period); averaged.  1: every velocity is free everywhere; lower is harder.

Against the oracle: ``oracle_t_star_s`` (:mod:`controllers.oracle_search`, clairvoyant) and
``t_star_ratio``: T* over the same lattice's earliest arrival with the moving obstacles left out (the static
shortest path at the lattice's resolution and speed; 1: the moving obstacles cost nothing; None when
unsolvable).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from swarmnav.controllers.oracle_search import OracleSettings, search
from swarmnav.controllers.prediction import time_to_collision_s
from swarmnav.models.scenario import Scenario

DENSITY_RADIUS_M = 1.0
DISPERSION_RAYS = 16
DISPERSION_RANGE_M = 2.0
SAMPLE_SPACING_M = 0.5
VO_HORIZON_S = 2.0
VO_SAMPLE_PERIOD_S = 2.0


def _static_distance(scenario: Scenario, points: np.ndarray) -> np.ndarray:
    """(P,) distance from each point to the nearest static obstacle's footprint (inf with none)."""
    d = np.full(len(points), np.inf)
    for ob in scenario.obstacles:
        if not ob.moving:
            d = np.minimum(d, np.hypot(points[:, 0] - ob.x_m, points[:, 1] - ob.y_m) - ob.radius_m)
    for b in scenario.boxes:
        gx = np.maximum(np.maximum(b.x_min_m - points[:, 0], points[:, 0] - b.x_max_m), 0.0)
        gy = np.maximum(np.maximum(b.y_min_m - points[:, 1], points[:, 1] - b.y_max_m), 0.0)
        d = np.minimum(d, np.hypot(gx, gy))
    return d


def _reference_path(scenario: Scenario) -> tuple[np.ndarray, float | None]:
    """The static shortest path's points every 0.1 m and its length (straight with no path found)."""
    from swarmnav.planners.errors import PlanningError
    from swarmnav.planners.theta_star import ThetaStarPlanner
    from swarmnav.planners.optimal import OptimalPlanner
    from swarmnav.sim.episode import static_problem
    problem = static_problem(scenario)
    planner = ThetaStarPlanner() if problem.boxes or problem.grid_override is not None else OptimalPlanner()
    found = True
    try:
        waypoints = np.asarray(planner.plan(problem, np.random.default_rng(0)).waypoints, dtype=float)
    except PlanningError:
        waypoints = np.array([[scenario.start.x_m, scenario.start.y_m], [scenario.goal.x_m, scenario.goal.y_m]])
        found = False
    seg = np.linalg.norm(np.diff(waypoints, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    s = np.append(np.arange(0.0, cum[-1], 0.1), cum[-1])
    points = np.column_stack([np.interp(s, cum, waypoints[:, 0]), np.interp(s, cum, waypoints[:, 1])])
    return points, (float(cum[-1]) if found else None)


def static_metrics(scenario: Scenario, path_points: np.ndarray) -> dict[str, float]:
    """``static_density`` and ``dispersion`` (module docstring)."""
    step = 0.05
    offsets = np.arange(-DENSITY_RADIUS_M, DENSITY_RADIUS_M + 1e-9, step)
    ox, oy = np.meshgrid(offsets, offsets)
    disc = np.hypot(ox, oy) <= DENSITY_RADIUS_M
    around = np.column_stack([ox[disc], oy[disc]])                                    # (Q, 2)
    pts = (path_points[:, None, :] + around[None, :, :]).reshape(-1, 2)
    occupied = (_static_distance(scenario, pts) <= 0.0).reshape(len(path_points), -1)
    angles = np.arange(DISPERSION_RAYS) * (2 * math.pi / DISPERSION_RAYS)
    radii = np.arange(step, DISPERSION_RANGE_M + 1e-9, step)
    rays = np.stack([np.cos(angles)[:, None] * radii, np.sin(angles)[:, None] * radii], axis=2)  # (R, S, 2)
    ray_pts = (path_points[:, None, None, :] + rays[None]).reshape(-1, 2)
    hit = (_static_distance(scenario, ray_pts) <= 0.0).reshape(len(path_points), DISPERSION_RAYS, -1)
    alternations = np.count_nonzero(hit[:, :, 1:] & ~hit[:, :, :-1], axis=2) + hit[:, :, 0]
    return {"static_density": float(occupied.mean()), "dispersion": float(alternations.mean())}


def dynamic_metrics(scenario: Scenario) -> dict[str, float | None]:
    """``survival_time_s``, ``survivability`` and ``dynamic_traversability`` (module docstring)."""
    moving = [ob for ob in scenario.obstacles if ob.moving]
    bounds = scenario.planning_bounds(scenario.robot_radius_m)
    xs = np.arange(bounds.x_min_m + SAMPLE_SPACING_M / 2, bounds.x_max_m, SAMPLE_SPACING_M)
    ys = np.arange(bounds.y_min_m + SAMPLE_SPACING_M / 2, bounds.y_max_m, SAMPLE_SPACING_M)
    gx, gy = np.meshgrid(xs, ys)
    points = np.column_stack([gx.ravel(), gy.ravel()])
    points = points[_static_distance(scenario, points) > scenario.robot_radius_m]
    limit = scenario.time_limit_s
    if not moving or not len(points):
        return {"survival_time_s": limit, "survivability": 0.0, "dynamic_traversability": 1.0}
    dt = 1.0 / scenario.sim.control_hz
    times = np.arange(0.0, limit + dt / 2, 0.1)
    radii = np.array([ob.radius_m for ob in moving])
    track = np.stack([ob.trajectory().positions_at(times) for ob in moving], axis=1)     # (T, M, 2)
    survive = np.full(len(points), limit)
    for i in range(0, len(times), 200):                                                # chunks bound memory
        chunk = track[i:i + 200]
        d = np.hypot(chunk[:, None, :, 0] - points[None, :, None, 0], chunk[:, None, :, 1] - points[None, :, None, 1])
        touched = np.any(d <= radii[None, None, :] + scenario.robot_radius_m, axis=2)   # (t, P)
        first = np.where(touched.any(axis=0), times[i + np.argmax(touched, axis=0)], np.inf)
        survive = np.minimum(survive, first)
    survival = float(survive.mean())
    angles = np.arange(16) * (2 * math.pi / 16)
    speeds = scenario.max_speed_m_s * np.array([0.5, 1.0])
    velocities = np.vstack([np.zeros((1, 2)), (speeds[:, None, None] * np.stack([np.cos(angles), np.sin(angles)],
                                                                               axis=1)[None]).reshape(-1, 2)])
    sample_times = np.arange(0.0, limit, VO_SAMPLE_PERIOD_S)
    now = np.stack([ob.trajectory().positions_at(sample_times) for ob in moving], axis=1)
    later = np.stack([ob.trajectory().positions_at(sample_times + dt) for ob in moving], axis=1)
    free_shares = []
    grown = np.tile(radii + scenario.robot_radius_m, len(points))
    for k in range(len(sample_times)):
        velocity = np.tile((later[k] - now[k]) / dt, (len(points), 1))
        relative = (now[k][None, :, :] - points[:, None, :]).reshape(-1, 2)           # (P*M, 2)
        ttc = time_to_collision_s(np.zeros(2), velocities, relative, velocity, grown)  # (V, P*M)
        free = ttc.reshape(len(velocities), len(points), len(moving)).min(axis=2) >= VO_HORIZON_S
        free_shares.append(float(free.mean()))
    return {"survival_time_s": round(survival, 3), "survivability": round(1.0 - survival / limit, 4),
            "dynamic_traversability": round(float(np.mean(free_shares)), 4)}


def scene_metrics(scenario: Scenario) -> dict[str, Any]:
    """The static and dynamic metrics of the module docstring (no oracle), with ``static_path_m``."""
    path_points, length = _reference_path(scenario)
    out: dict[str, Any] = {"static_path_m": None if length is None else round(length, 4)}
    out.update({k: round(v, 4) for k, v in static_metrics(scenario, path_points).items()})
    out.update(dynamic_metrics(scenario))
    return out


def oracle_metrics(scenario: Scenario, settings: OracleSettings | None = None,
                   time_limit_s: float | None = None) -> dict[str, Any]:
    """The oracle's verdict (``oracle``), ``oracle_t_star_s`` and ``t_star_ratio`` (module docstring), searched
    up to ``time_limit_s`` (None: the scenario's)."""
    plan = search(scenario, settings, time_limit_s)
    out: dict[str, Any] = {"oracle": plan.verdict()}
    out["oracle_t_star_s"] = out["oracle"]["arrival_s"]
    ratio = None
    if plan.solvable:
        static = search(replace(scenario, obstacles=tuple(ob for ob in scenario.obstacles if not ob.moving)),
                        settings, time_limit_s)
        ratio = round(plan.arrival_s / static.arrival_s, 4) if static.solvable and static.arrival_s else None
    out["t_star_ratio"] = ratio
    return out


def difficulty(scenario: Scenario, settings: OracleSettings | None = None) -> dict[str, Any]:
    """Every metric of the module docstring for one scenario (its world seed), with the oracle's verdict."""
    out: dict[str, Any] = {"scenario": scenario.name, "world_seed": scenario.world_seed}
    out.update(scene_metrics(scenario))
    out.update(oracle_metrics(scenario, settings))
    return out
