"""The one map seam: what a navigator plans on, known in advance or built from the laser as it drives.

Every navigator reads the static world through ``NavigationSetup.map_problem`` (a
:class:`~planners.problem.Problem`).  With the map known (the default) that is the scenario's static
obstacles, fixed for the run.  With ``knowledge = { map = "unknown" }`` the setup carries a
:class:`SensedMap` instead, Nav2's costmap in small: the runner (``sim.simulation``) feeds it every
observation before the navigator's step (the obstacle layer: a log-odds grid from the laser,
:mod:`models.occupancy`), and at ``publish_hz`` it publishes the occupied cells as the map problem:
each cell a disc about its centre that covers it (radius half its diagonal), the one obstacle kind every
planner handles, the swarm planners included (several support no boxes): grid planners rasterise them grown
by the robot radius and the clearance (``Problem.grid``, the inflation layer), the continuous ones measure
segments against them.  ``revision`` grows with every publication that changed the occupied cells:
a navigator that cached something of the map checks it.  Unknown cells are free (Nav2's ``allow_unknown``).

Planners read :meth:`SensedMap.planning_problem` (``NavigationSetup.plan_problem``): the same cells, each
presented as the largest disc, up to :data:`GROWN_MAX_M` in radius, that covers it and reaches into the
cells *not seen free* behind it (the hit's far side: the laser cannot see past it) but holds the centre of
no cell seen free or driven over; a cell with no such room keeps its covering disc.  Why: the swarm
planners' obstacle penalty (Kamil et al. 2020, Eqs. (3)-(5)) is measured at ``samples`` points of the
curve, and a cell's own disc (3.5 cm at 0.05 m cells; 0.255 m with the inflation and the penalty margin)
is narrower than the spacing of those points on a long spline (0.5-0.7 m measured): on ``gwo-scenario-1``
``abc``'s best candidate crossed a row of ten rim cells with no sample inside any (penalty 0, clearance
-0.23 m), and every replan failed.  Space seen free stays free, so no gap the robot has seen is narrowed;
the local obstacles, the safety layer and ``dstar_replan`` keep the cells' own discs (:meth:`problem`).

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
GROWN_MAX_M = 0.25  # the largest disc a sensed cell is presented as to the planners (planning_problem)
GROWN_STEPS = 4  # radii tried per cell: GROWN_MAX_M, then 3/4, 1/2 and 1/4 of it


class SensedMap:
    """The map built from the laser (see the module docstring).

    Args:
        empty: the scenario's problem with no static obstacle (bounds, robot radius, clearance, goal).
        arena: the arena the grid covers.
        cell_m: the grid's resolution (``knowledge.map_cell_m``).
        publish_hz: how often the planning map is republished (the grid integrates every scan).
        unknown_cost: with a positive value, :meth:`planning_problem` carries the never-seen cells and this
            weight (``knowledge.unknown_cost``; the grid searches read them: :mod:`planners.unknown_cost`).
    """

    def __init__(self, empty: Problem, arena: Rect, cell_m: float, publish_hz: float = PUBLISH_HZ,
                 model: SensorModel = SensorModel(), unknown_cost: float = 0.0):
        self.empty = replace(empty, obstacles=(), boxes=(), grid_override=None)
        self.unknown_cost = float(unknown_cost)
        self.grid = LogOddsGrid(arena, cell_m, model)
        self.period_s = 1.0 / publish_hz
        self.revision = 0
        self._next_publish_s = 0.0
        self._occupied = np.zeros((self.grid.rows, self.grid.cols), dtype=bool)
        self._driven = np.zeros_like(self._occupied)  # cells under the robot's disc at some scan (seen free)
        self._problem = self._build(self._occupied)
        self._planning: tuple[int, Problem] | None = None
        self._inflated_revision = -1

    def update(self, time_s: float, pose, ranges_m: np.ndarray, angles_rad: np.ndarray, offset_m: float,
               range_m: float) -> bool:
        """Integrate one scan taken at ``pose``; True when the planning map was republished with a change."""
        self.grid.integrate(pose.x_m, pose.y_m, pose.heading_rad, ranges_m, angles_rad, offset_m, range_m)
        self._drive_over(pose.x_m, pose.y_m)
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

    def planning_problem(self) -> Problem:
        """The published map as the planners see it: each cell as its grown disc (module docstring)."""
        if self._planning is None or self._planning[0] != self.revision:
            cell = self.grid.cell_m
            centres, radii = grown_discs(self._occupied, self.grid.log_odds < 0.0, self._driven, cell,
                                         self.grid.origin_m)
            discs = tuple(Disc(x, y, r) for (x, y), r in zip(centres.tolist(), radii.tolist()))
            problem = replace(self.empty, obstacles=discs, cell_m=cell)
            if self.unknown_cost > 0.0:
                unknown = OccupancyGrid(~self.grid.known & ~self._driven, cell, self.grid.origin_m)
                problem = replace(problem, unknown_cells=unknown, unknown_cost=self.unknown_cost)
            self._planning = (self.revision, problem)
        return self._planning[1]

    def _drive_over(self, x_m: float, y_m: float) -> None:
        """Mark the cells whose centres lie under the robot's disc: it stood there, so they are free."""
        cell, (x0, y0) = self.grid.cell_m, self.grid.origin_m
        r = self.empty.robot_radius_m
        c0, c1 = max(0, int((x_m - r - x0) / cell)), min(self.grid.cols, int((x_m + r - x0) / cell) + 1)
        r0, r1 = max(0, int((y_m - r - y0) / cell)), min(self.grid.rows, int((y_m + r - y0) / cell) + 1)
        if c0 >= c1 or r0 >= r1:
            return
        xs = (np.arange(c0, c1) + 0.5) * cell + x0 - x_m
        ys = (np.arange(r0, r1) + 0.5) * cell + y0 - y_m
        self._driven[r0:r1, c0:c1] |= xs[None, :] ** 2 + ys[:, None] ** 2 <= r * r

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


def grown_discs(occupied: np.ndarray, seen_free: np.ndarray, driven: np.ndarray, cell_m: float,
                origin_m: tuple[float, float], max_m: float = GROWN_MAX_M,
                steps: int = GROWN_STEPS) -> tuple[np.ndarray, np.ndarray]:
    """Each occupied cell's grown disc (see the module docstring): (n, 2) centres and (n,) radii.

    ``D`` is the distance from each cell's centre to the nearest centre of a free cell (seen free or driven
    over; a Euclidean distance transform).  A cell's disc is pushed from its centre along the gradient of
    ``D`` (away from the free space), by ``rho`` less the cell's half diagonal so that it still covers the
    cell; the largest ``rho`` of ``max_m x (steps, ..., 1) / steps`` such that no free cell's centre lies
    inside the disc (``D`` at the moved centre's cell, less the centre's offset from that cell's centre, is
    at least ``rho``) is taken; a cell with none (or a flat ``D``) keeps its covering disc (radius: half its
    diagonal)."""
    from scipy.ndimage import distance_transform_edt
    cells = np.argwhere(occupied)
    half_diagonal = cell_m * math.sqrt(0.5)
    centres = (cells[:, ::-1] + 0.5) * cell_m + np.asarray(origin_m, dtype=float)
    radii = np.full(len(cells), half_diagonal)
    free = (seen_free | driven) & ~occupied
    if not len(cells):
        return centres, radii
    far = 2.0 * max_m + 2.0 * cell_m
    distance = np.minimum(distance_transform_edt(~free) * cell_m, far) if free.any() \
        else np.full(occupied.shape, far)
    grad_y, grad_x = np.gradient(distance)
    normal = np.column_stack([grad_x[cells[:, 0], cells[:, 1]], grad_y[cells[:, 0], cells[:, 1]]])
    length = np.hypot(normal[:, 0], normal[:, 1])
    open_ = length > 1e-9
    normal[open_] /= length[open_, None]
    rows, cols = occupied.shape
    out = centres.copy()
    for rho in max_m * np.arange(steps, 0, -1) / steps:
        if rho <= half_diagonal:
            break
        moved = centres + (rho - half_diagonal) * normal
        c = np.clip(np.floor((moved[:, 0] - origin_m[0]) / cell_m).astype(np.int64), 0, cols - 1)
        r = np.clip(np.floor((moved[:, 1] - origin_m[1]) / cell_m).astype(np.int64), 0, rows - 1)
        # The distance from the moved centre to the nearest free centre is at least its cell's less the offset.
        off = np.hypot(moved[:, 0] - ((c + 0.5) * cell_m + origin_m[0]),
                       moved[:, 1] - ((r + 0.5) * cell_m + origin_m[1]))
        take = open_ & (radii == half_diagonal) & (distance[r, c] - off >= rho)
        out[take], radii[take] = moved[take], rho
    return out, radii
