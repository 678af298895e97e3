"""The one map seam: what a navigator plans on, known in advance or built from the laser as it drives.

Every navigator reads the static world through ``NavigationSetup.map_problem`` (a
:class:`~planners.problem.Problem`).  With the map known (the default) that is the scenario's static
obstacles, fixed for the run.  With ``knowledge = { map = "unknown" }`` the setup carries a
:class:`SensedMap` instead, Nav2's costmap in small: the runner (``sim.runner``) feeds it every
observation before the navigator's step (the obstacle layer: a log-odds grid from the laser,
:mod:`models.occupancy`), and at ``publish_hz`` it publishes the occupied cells as the map problem:
each cell a disc about its centre that covers it (radius half its diagonal), the one obstacle kind every
planner handles, the swarm planners included (several support no boxes): grid planners rasterise them grown
by the robot radius and the clearance (``Problem.grid``, the inflation layer), the continuous ones measure
segments against them.  ``revision`` grows with every publication that changed the occupied cells:
a navigator that cached something of the map checks it.  Unknown cells are free (Nav2's ``allow_unknown``).

The oracle and the SPL's L* keep the true map.  No MuJoCo here.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from swarmnav.models.occupancy import LogOddsGrid, SensorModel
from swarmnav.models.world import Disc, OccupancyGrid, Pose2D, Rect
from swarmnav.planners.problem import Problem

PUBLISH_HZ = 5.0  # Nav2's local costmap update_frequency (5 Hz)


class SensedMap:
    """The map built from the laser (see the module docstring).

    Args:
        empty: the scenario's problem with no static obstacle (bounds, robot radius, clearance, goal).
        arena: the arena the grid covers.
        cell_m: the grid's resolution (``knowledge.map_cell_m``).
        publish_hz: how often the planning map is republished (the grid integrates every scan).
    """

    def __init__(self, empty: Problem, arena: Rect, cell_m: float, publish_hz: float = PUBLISH_HZ,
                 model: SensorModel = SensorModel()):
        self.empty = replace(empty, obstacles=(), boxes=(), grid_override=None)
        self.grid = LogOddsGrid(arena, cell_m, model)
        self.period_s = 1.0 / publish_hz
        self.revision = 0
        self._next_publish_s = 0.0
        self._occupied = np.zeros((self.grid.rows, self.grid.cols), dtype=bool)
        self._problem = self._build(self._occupied)
        self._inflated_revision = -1

    def update(self, time_s: float, pose, ranges_m: np.ndarray, angles_rad: np.ndarray, offset_m: float,
               range_m: float) -> bool:
        """Integrate one scan taken at ``pose``; True when the planning map was republished with a change."""
        self.grid.integrate(pose.x_m, pose.y_m, pose.heading_rad, ranges_m, angles_rad, offset_m, range_m)
        if time_s < self._next_publish_s - 1e-9:
            return False
        self._next_publish_s = time_s + self.period_s
        occupied = self.grid.occupied
        if np.array_equal(occupied, self._occupied):
            return False
        self._occupied = occupied
        self._problem = None  # built on demand (most publications are not read)
        self.revision += 1
        return True

    def observe(self, observation) -> bool:
        """:meth:`update` from an :class:`~controllers.navigator.Observation`."""
        return self.update(observation.time_s, observation.pose, observation.ranges_m,
                           observation.range_angles_rad, observation.range_offset_m, observation.range_cutoff_m)

    def problem(self) -> Problem:
        """The published map as a planning problem (the scenario's start and goal)."""
        if self._problem is None:
            self._problem = self._build(self._occupied)
        return self._problem

    def _build(self, occupied: np.ndarray) -> Problem:
        cell = self.grid.cell_m
        centres = (np.argwhere(occupied)[:, ::-1] + 0.5) * cell + np.array(self.grid.origin_m)
        radius = cell * math.sqrt(0.5)
        return replace(self.empty, obstacles=tuple(Disc(float(x), float(y), radius) for x, y in centres.tolist()),
                       cell_m=cell)

    def inflated(self) -> OccupancyGrid:
        """The published cells grown by the robot radius and the clearance (the inflation layer): cells whose
        centre lies within the inflation of a published cell's disc (a Euclidean distance transform)."""
        if self._inflated_revision != self.revision:
            from scipy.ndimage import distance_transform_edt
            cell = self.grid.cell_m
            reach = self.empty.inflation_m + cell * math.sqrt(0.5)
            near = distance_transform_edt(~self._occupied) * cell < reach if self._occupied.any() \
                else np.zeros_like(self._occupied)
            self._inflated = OccupancyGrid(near, cell, self.grid.origin_m)
            self._inflated_revision = self.revision
        return self._inflated

    def blocks(self, waypoints_m: np.ndarray) -> bool:
        """Whether a polyline (from the robot on), sampled every half cell, enters :meth:`inflated`; the part
        within the inflation plus a cell of its first point (the robot) is not judged, so a robot that passes
        close by an obstacle is not sent to replan by its own position."""
        problem = self.empty
        pts = np.asarray(waypoints_m, dtype=float).reshape(-1, 2)
        if len(pts) < 2 or not self._occupied.any():
            return False
        seg = np.diff(pts, axis=0)
        lengths = np.hypot(seg[:, 0], seg[:, 1])
        step_m = self.grid.cell_m / 2.0
        samples = [pts[:1]]
        for a, d, length in zip(pts[:-1], seg, lengths):
            n = max(1, int(math.ceil(length / step_m)))
            samples.append(a + np.outer(np.arange(1, n + 1) / n, d))
        points = np.vstack(samples)
        away = np.hypot(points[:, 0] - pts[0, 0], points[:, 1] - pts[0, 1]) > problem.inflation_m + self.grid.cell_m
        return bool(grid_hits(self.inflated(), points[away]).any())


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
