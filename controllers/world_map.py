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

from swarmnav.controllers.guided import GuidedCarrot, SensedLocalObstacles, grid_hits
from swarmnav.models.occupancy import LogOddsGrid, SensorModel
from swarmnav.models.world import Disc, OccupancyGrid, Rect
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
        centre lies within the inflation of a published cell's centre (a Euclidean distance transform).  Not
        of its covering disc: a point is judged by its cell's centre, up to half a cell diagonal (the disc's
        radius) off, and a path planned at exactly the inflation from the discs must not read as blocked."""
        if self._inflated_revision != self.revision:
            from scipy.ndimage import distance_transform_edt
            cell = self.grid.cell_m
            reach = self.empty.inflation_m
            near = distance_transform_edt(~self._occupied) * cell < reach if self._occupied.any() \
                else np.zeros_like(self._occupied)
            self._inflated = OccupancyGrid(near, cell, self.grid.origin_m)
            self._inflated_revision = self.revision
        return self._inflated

    def local_guidance(self, setup, lookahead_m: float):
        """What :func:`controllers.guidance.local_setup` gives the local navigators on this map: (a carrot on a
        guidance path replanned on it, its obstacles near the robot) (:mod:`controllers.guided`)."""
        return GuidedCarrot(setup, lookahead_m), SensedLocalObstacles(setup)

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
