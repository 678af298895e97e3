"""The local navigators' guidance on a sensed map (``knowledge = { map = "unknown" }``): what
:func:`controllers.guidance.local_setup` gives ``dwa``, ``velocity_obstacle`` and ``mppi`` instead of the
fixed carrot and map obstacles, so that none of them has map code of its own.

* :class:`SensedLocalObstacles`: the map's occupied cells near the robot, refreshed whenever the sensed
  map publishes a change (``NavigationSetup.map_revision``), each as the point at its centre (Nav2's
  controllers likewise score a costmap cell at its centre): a cell holds a hit anywhere in it, so the disc
  that covers it stands up to a cell out from the surface; its centre is within half a cell diagonal of
  it, inside the local navigators' own ``margin_m`` at the default 0.05 m cells.  Measured: with whole
  cells ``dwa`` froze beside the first obstacle it mapped on gwo-scenario-1 (the map grew under it, and
  every arc, standing still included, then started inside its margin).
* :class:`GuidedCarrot`: the carrot on a guidance path that is replanned, with the run's planner, on the
  sensed map (from the robot, ``free_start`` when its position is blocked; with one map cell more clearance
  than the scenario's, so the local navigators' own margins fit beside it) whenever a publication blocks
  the rest of it, at most once per ``cooldown_s`` of simulated time (a failed replan keeps the old path and
  is retried at the next publication).  The new guidance paths are not logged (the navigators return none).
  With a :class:`~controllers.centred_path.CentredPlanner` (the local navigators' ``footprint = "box"``
  option) the guidance is its path instead (the chassis' inscribed circle, kept to the middle of passages),
  replanned when the rest of the path enters its blocked cells; the run's planner is not asked.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from swarmnav.controllers.centred_path import CentredPlanner
from swarmnav.controllers.footprint import block_radius_m, covering_discs
from swarmnav.controllers.guidance import PathCarrot
from swarmnav.controllers.navigator import NavigationSetup
from swarmnav.controllers.prediction import LocalObstacles
from swarmnav.models.world import Disc, OccupancyGrid, Pose2D
from swarmnav.planners.errors import PlanningError, StartBlocked
from swarmnav.planners.problem import Problem

GUIDANCE_COOLDOWN_S = 0.5  # as the replan navigator's default cooldown_s


class SensedLocalObstacles(LocalObstacles):
    """:class:`~controllers.prediction.LocalObstacles` of the sensed map's latest publication."""

    def __init__(self, setup: NavigationSetup):
        self.setup = setup
        self.revision = -1
        self._refresh()

    def _refresh(self) -> None:
        if self.setup.map_revision != self.revision:
            self.revision = self.setup.map_revision
            known = self.setup.map_problem
            super().__init__(known.disc_centres_m, np.zeros(len(known.obstacles)), known.box_array_m)

    def near(self, x_m: float, y_m: float, reach_m: float, detections):
        self._refresh()
        return super().near(x_m, y_m, reach_m, detections)


class GuidedCarrot(PathCarrot):
    """A :class:`~controllers.guidance.PathCarrot` whose path is replanned on the sensed map (see above)."""

    def __init__(self, setup: NavigationSetup, lookahead_m: float, cooldown_s: float = GUIDANCE_COOLDOWN_S,
                 centred: CentredPlanner | None = None):
        super().__init__(setup.path.waypoints, lookahead_m)
        self.setup, self.cooldown_s, self.centred = setup, cooldown_s, centred
        self.revision = setup.map_revision
        self.next_replan_s = 0.0
        self.time_s = 0.0
        self.replans = 0
        self._sight_radius_m: float | None = None

    def keep_in_sight(self, disc_centres_m, disc_radii_m, boxes_m, radius_m: float, samples: int = 8) -> None:
        # In sight for the robot with the same extra cell of clearance as the guidance path (see _replan).
        self._sight_radius_m = float(radius_m) + (0.0 if self.centred else self.setup.map_problem.cell_m)
        self._sight_samples = samples
        super().keep_in_sight(disc_centres_m, disc_radii_m, boxes_m, self._sight_radius_m, samples)

    def update(self, pose: Pose2D, window_m: float = 2.0) -> np.ndarray:
        revision = self.setup.map_revision
        if revision != self.revision and self.time_s >= self.next_replan_s - 1e-9:
            self.revision = revision
            known = self.setup.map_problem
            if self._sight_radius_m is not None:  # the sight test sees the current map
                self.sight = None
                super().keep_in_sight(known.disc_centres_m, known.disc_radii_m, known.box_array_m,
                                      self._sight_radius_m, self._sight_samples)
            rest = np.vstack([[pose.x_m, pose.y_m], self.points[self._segment(self.progress_m) + 1:]])
            if self.centred is not None:
                blocked = self.centred.blocks(known, rest, self.centred.block_m + known.cell_m)
            else:
                blocked = self.setup.world_map.blocks(rest)
            if blocked:
                self.next_replan_s = self.time_s + self.cooldown_s
                self._replan(known, pose)
        self.time_s += self.setup.control_dt_s
        return super().update(pose, window_m)

    def block_pocket(self, pocket: Disc, pose: Pose2D) -> None:
        """Plan the guidance path from ``pose`` around ``pocket`` as well from now on, at once (with a
        :class:`~controllers.centred_path.CentredPlanner` only, which forgets its pockets when no path passes
        them); ``mppi``'s ``recovery_block_m``."""
        if self.centred is None:
            return
        self.centred.pockets = self.centred.pockets + (pocket,)
        self._replan(self.setup.map_problem, pose)

    def _replan(self, known, pose: Pose2D) -> None:
        if self.centred is not None:
            try:
                waypoints = self.centred.plan(known, (pose.x_m, pose.y_m))
            except PlanningError:
                self.revision = -1
                return
            self._restart(waypoints)
            return
        # A cell more clearance than the map asks for: the local navigators keep their own margin from the
        # cells' edges, and a guidance path that grazes them at exactly that margin leaves them no room.
        problem = replace(known, start=Pose2D(pose.x_m, pose.y_m, pose.heading_rad),
                          clearance_m=known.clearance_m + known.cell_m)
        planner = self.setup.planner
        try:
            try:
                path = planner.plan(problem, self.setup.rng)
            except StartBlocked:
                problem = free_start(problem)
                path = planner.plan(problem, self.setup.rng)
        except PlanningError:
            self.revision = -1  # try again at the next update after the cooldown
            return
        if not problem.is_collision_free(path.waypoints, tolerance_m=1e-6):
            self.revision = -1
            return
        self._restart(np.vstack([[pose.x_m, pose.y_m], path.waypoints]))

    def _restart(self, waypoints: np.ndarray) -> None:
        """Carry on along ``waypoints`` (from the robot), the sight test kept."""
        sight, samples = self.sight, getattr(self, "sight_samples", 8)
        PathCarrot.__init__(self, waypoints, self.lookahead_m)
        self.sight, self.sight_samples = sight, samples
        self.replans += 1


def box_guidance(setup: NavigationSetup, footprint: str, cost_weight: float, cost_reach_m: float):
    """(the :class:`~controllers.centred_path.CentredPlanner` of a local navigator's ``footprint = "box"``, the
    chassis' covering discs in the base frame (:func:`controllers.footprint.covering_discs`), their radius);
    (None, one disc at the origin, the robot radius) for ``footprint = "circle"``."""
    if footprint != "box":
        return None, np.zeros((1, 2)), float(setup.map_problem.robot_radius_m)
    block_m = block_radius_m(setup) + setup.map_problem.clearance_m
    discs, radius = covering_discs(setup)
    return CentredPlanner(block_m, cost_weight, cost_reach_m), discs, radius


def free_start(problem: Problem, search_m: float = 0.4) -> Problem:
    """``problem`` from the nearest start that is not blocked (outside every grown box and disc and in a
    free cell of its grid: a sensed map's cells are coarser than the obstacles, so a robot that kept its
    distance can still stand in a blocked cell): the robot's own position if it is free, else the nearest of
    rings of 16 points 1 cm apart within ``search_m``; first with the problem's clearance, then with none
    (the start unchanged, no clearance, if no point is free).  What a replanning navigator plans from after
    ``StartBlocked`` (Nav2's planners fail there; ``dstar_replan`` takes the nearest free cell likewise)."""
    start = problem.start
    angles = 2.0 * math.pi * np.arange(16) / 16
    rings = np.arange(0.0, search_m + 1e-9, 0.01)
    for clearance_m in dict.fromkeys((problem.clearance_m, 0.0)):
        candidate = replace(problem, clearance_m=clearance_m)
        grid = candidate.grid
        for ring_m in rings:
            pts = start.xy + ring_m * np.column_stack([np.cos(angles), np.sin(angles)])
            ok = (candidate.segment_clearances_m(pts, pts) >= 1e-6) & candidate.in_bounds(pts) & ~grid_hits(grid, pts)
            if ok.any():
                x, y = pts[int(np.argmax(ok))]
                return replace(candidate, start=Pose2D(float(x), float(y), start.heading_rad))
    return replace(problem, clearance_m=0.0)


def grid_hits(grid: OccupancyGrid, points_m: np.ndarray) -> np.ndarray:
    """(N,) whether each point lies in an occupied cell (points off the grid: not occupied)."""
    rows, cols = grid.occupied.shape
    col = np.floor((points_m[:, 0] - grid.origin_m[0]) / grid.cell_m).astype(np.int64)
    row = np.floor((points_m[:, 1] - grid.origin_m[1]) / grid.cell_m).astype(np.int64)
    inside = (col >= 0) & (col < cols) & (row >= 0) & (row < rows)
    out = np.zeros(len(points_m), dtype=bool)
    out[inside] = grid.occupied[row[inside], col[inside]]
    return out
