"""A path kept to the middle of passages, for a box chassis on a sensed map: what the ``footprint = "box"``
options of ``replan``, ``dwa``, ``velocity_obstacle`` and ``mppi`` plan their paths with (BARN's configurations,
docs/barn.md), as ``dstar_replan``'s ``footprint = "box"`` and ``cost_weight`` do with D* Lite.

:class:`CentredPlanner`: the map problem's obstacles rasterised on its cells grown by ``block_m`` (the chassis'
inscribed circle plus the clearance: :func:`controllers.footprint.block_radius_m`; planning for the Jackal's
circumscribed circle closes BARN's 0.75 m passages), each free cell priced 1 + :func:`controllers.footprint.
cell_penalty` (``weight`` x (1 - d / ``reach_m``)^2 near blocked cells, Nav2's inflation cost in small), the
cheapest 8-connected cell path (:func:`planners.unknown_cost.weighted_cells`: a move costs its length times the
mean of its two cells' prices, as D* Lite's penalties), then greedy string pulling by line of sight on the
free cells, a shortcut taken only where it runs no nearer the obstacles than the cells it replaces
(:func:`controllers.footprint.no_costlier`).  :meth:`CentredPlanner.blocks` tells whether a path still fits.

No MuJoCo here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from swarmnav.controllers.footprint import cell_penalty, no_costlier
from swarmnav.models.geometry import segment_disc_distances
from swarmnav.models.world import Disc, OccupancyGrid, rasterise
from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.grid_graph import Cell, grid_line_of_sight
from swarmnav.planners.problem import Problem
from swarmnav.planners.unknown_cost import weighted_cells

START_SEARCH_CELLS = 4  # a blocked start cell is replaced by the nearest free cell within this many cells
PATH_SLACK_M = 1e-6  # CentredPlanner._path_grid: discs this much farther from the polyline are rasterised too


@dataclass
class CentredPlanner:
    """Cheapest cell paths on a problem's obstacles grown by ``block_m``, priced near them (module docstring).

    Args:
        block_m: cells whose centre lies within this (plus half a cell diagonal) of an obstacle are blocked.
        weight: the penalty's weight (0: shortest paths on the blocked cells).
        reach_m: how far from a blocked cell the penalty reaches.
        pockets: discs planned around as obstacles besides the problem's (none at first): where a navigator that
            uses it stood stuck (``mppi``'s ``recovery_block_m``); :meth:`plan` forgets them when no path
            passes them.
    """

    block_m: float
    weight: float
    reach_m: float
    pockets: tuple[Disc, ...] = ()
    _cache: tuple = field(default=(), init=False, repr=False)
    _with_pockets: tuple = field(default=(), init=False, repr=False)

    def _problem(self, problem: Problem) -> Problem:
        """``problem`` with :attr:`pockets` among its obstacles (itself when there are none); the same object
        while neither changes, so that :meth:`cells`' cache holds."""
        if not self.pockets:
            return problem
        if not self._with_pockets or self._with_pockets[0] is not problem or self._with_pockets[1] != self.pockets:
            self._with_pockets = (problem, self.pockets,
                                  replace(problem, obstacles=tuple(problem.obstacles) + self.pockets))
        return self._with_pockets[2]

    def cells(self, problem: Problem) -> tuple[OccupancyGrid, np.ndarray | None]:
        """(the blocked cells, their penalty or None) of ``problem``'s obstacles; kept while the problem is."""
        problem = self._problem(problem)
        if not self._cache or self._cache[0] is not problem:
            grid = rasterise(problem.bounds, problem.obstacles, problem.boxes, self.block_m, problem.cell_m)
            occupied = np.asarray(grid.occupied, dtype=bool)
            self._cache = (problem, grid, cell_penalty(occupied, grid.cell_m, self.weight, self.reach_m))
        return self._cache[1], self._cache[2]

    def _path_grid(self, problem: Problem, pts: np.ndarray) -> OccupancyGrid:
        """:meth:`cells`' blocked grid as far as :meth:`blocks` reads it (the cells of points on the polyline
        ``pts``): only the discs whose grown radius (``block_m`` and half a cell diagonal, as
        :func:`models.world.rasterise` grows them) plus another half diagonal (a point lies within that of its
        cell's centre) and :data:`PATH_SLACK_M` reaches the polyline are rasterised; a disc marks its cells
        whatever the others, so every cell of the polyline reads as in the whole grid.  Why (speed): the whole
        sensed map was rasterised at each of its changes only to ask this (a replan, rare, still rasterises it
        all): ~7 % of a BARN run's CPU for ``dwa``."""
        discs = problem.obstacles
        if discs:
            half_diagonal = problem.cell_m / math.sqrt(2.0)
            reach = problem.disc_radii_m + self.block_m + 2.0 * half_diagonal + PATH_SLACK_M
            near = (segment_disc_distances(pts[:-1], pts[1:], problem.disc_centres_m) <= reach[None, :]).any(axis=0)
            discs = tuple(discs[i] for i in np.flatnonzero(near).tolist())
        return rasterise(problem.bounds, discs, problem.boxes, self.block_m, problem.cell_m)

    def plan(self, problem: Problem, start_xy: tuple[float, float]) -> np.ndarray:
        """(n, 2) waypoints from ``start_xy`` to ``problem``'s goal.

        Raises:
            NoPathFound: no free cell near the start, or none of its paths reaches the goal's cell (with
                :attr:`pockets`, first planned with them, then, forgetting them, without).
        """
        if self.pockets:
            try:
                return self._plan(problem, start_xy)
            except NoPathFound:
                self.pockets = ()
        return self._plan(problem, start_xy)

    def _plan(self, problem: Problem, start_xy: tuple[float, float]) -> np.ndarray:
        grid, penalty = self.cells(problem)
        occupied = np.asarray(grid.occupied, dtype=bool)
        start = _free_cell_near(occupied, grid, start_xy)
        goal_xy = (problem.goal.x_m, problem.goal.y_m)
        goal = _free_cell_near(occupied, grid, goal_xy)
        if start is None or goal is None:
            raise NoPathFound(f"no free cell within {START_SEARCH_CELLS} cells of the "
                              f"{'start' if start is None else 'goal'}")
        weights = np.ones(occupied.shape) if penalty is None else 1.0 + penalty
        path, _, _ = weighted_cells(occupied, weights, start, goal)
        corners = _string_pull(path, occupied, grid, penalty)
        middle = grid.centres_m(np.array(corners[1:-1])).reshape(-1, 2)
        return np.vstack([[start_xy], middle, [goal_xy]])

    def blocks(self, problem: Problem, waypoints_m: np.ndarray, skip_m: float) -> bool:
        """Whether the polyline (from the robot on), sampled every half cell, enters a blocked cell farther
        than ``skip_m`` from its first point (the robot's own surroundings are not judged)."""
        pts = np.asarray(waypoints_m, dtype=float).reshape(-1, 2)
        if len(pts) < 2:
            return False
        problem = self._problem(problem)
        grid = self._cache[1] if self._cache and self._cache[0] is problem else self._path_grid(problem, pts)
        samples = [pts[:1]]
        for a, b in zip(pts[:-1], pts[1:]):
            n = max(1, int(math.ceil(float(np.hypot(*(b - a))) / (0.5 * grid.cell_m))))
            samples.append(a + np.outer(np.arange(1, n + 1) / n, b - a))
        points = np.vstack(samples)
        points = points[np.hypot(points[:, 0] - pts[0, 0], points[:, 1] - pts[0, 1]) > skip_m]
        rows, cols = grid.occupied.shape
        col = np.floor((points[:, 0] - grid.origin_m[0]) / grid.cell_m).astype(np.int64)
        row = np.floor((points[:, 1] - grid.origin_m[1]) / grid.cell_m).astype(np.int64)
        inside = (col >= 0) & (col < cols) & (row >= 0) & (row < rows)
        return bool(np.asarray(grid.occupied, dtype=bool)[row[inside], col[inside]].any())


def _free_cell_near(occupied: np.ndarray, grid: OccupancyGrid, xy: tuple[float, float]) -> Cell | None:
    """The cell of ``xy``, or the free cell nearest it within :data:`START_SEARCH_CELLS` (None if none)."""
    r0, c0 = grid.cell_of(*xy)
    if not occupied[r0, c0]:
        return (r0, c0)
    k = START_SEARCH_CELLS
    rows, cols = occupied.shape
    lo_r, hi_r, lo_c, hi_c = max(0, r0 - k), min(rows, r0 + k + 1), max(0, c0 - k), min(cols, c0 + k + 1)
    free = np.argwhere(~occupied[lo_r:hi_r, lo_c:hi_c]) + (lo_r, lo_c)
    if not len(free):
        return None
    d = np.hypot(*(grid.centres_m(free) - np.asarray(xy)).T)
    r, c = free[int(np.argmin(d))]
    return (int(r), int(c))


def _string_pull(cells: list[Cell], occupied: np.ndarray, grid: OccupancyGrid,
                 penalty: np.ndarray | None) -> list[Cell]:
    """The cells where the path must turn: greedy line of sight on the free cells, no nearer the obstacles."""
    free = (~occupied).tolist()
    centres = grid.centres_m(np.array(cells)).reshape(-1, 2)
    out, anchor = [cells[0]], 0
    while anchor < len(cells) - 1:
        nxt = anchor + 1
        while nxt + 1 < len(cells) and grid_line_of_sight(free, cells[anchor], cells[nxt + 1]) \
                and no_costlier(penalty, grid, centres[anchor], centres[nxt + 1], cells[anchor:nxt + 2]):
            nxt += 1
        out.append(cells[nxt])
        anchor = nxt
    return out
