"""Walking a grid map cell by cell, as the two papers' robots do (Hasan et al. 2023; Gong et al. 2022, §2.1).

The papers' robot occupies one cell and moves one cell per step.  Here a
:class:`CellWalker` hands the controller the centres of the cells still to
visit and reports each cell the robot reaches; the navigators decide at those
moments.  :func:`static_grid` is the known static world on the problem's cells.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from swarmnav.controllers.controller import ControlCommand, Controller, Twist
from swarmnav.models.grid_map import inflated_map_grid
from swarmnav.models.world import OccupancyGrid, Pose2D, rasterise
from swarmnav.planners.grid_graph import grid_line_of_sight
from swarmnav.planners.problem import Path, Problem

Cell = tuple[int, int]  # (row, col); rows grow with y
MOVES = ((-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (-1, 1), (1, -1), (1, 1))


def static_grid(problem: Problem) -> OccupancyGrid:
    """The known static world on the problem's cells: its boxes (the map) and its discs, inflated by the robot.

    Pass the robot's known map, ``NavigationSetup.map_problem`` (static obstacles
    only): both papers plan on the static map and sense the moving obstacles.  Map
    cells are taken as the map has them (:func:`~models.grid_map.inflated_map_grid`,
    so one-cell corridors stay open for a robot up to one cell wide); static discs
    are rasterised with :func:`~models.world.rasterise`'s margin.
    """
    bounds = problem.bounds
    cell_m = problem.cell_m
    cols = max(1, int(math.ceil(bounds.width_m / cell_m - 1e-9)))
    rows = max(1, int(math.ceil(bounds.height_m / cell_m - 1e-9)))
    xs = bounds.x_min_m + (np.arange(cols) + 0.5) * cell_m
    ys = bounds.y_min_m + (np.arange(rows) + 0.5) * cell_m
    occupied = np.zeros((rows, cols), dtype=bool)
    for box in problem.boxes:
        inside_x = (xs > box.x_min_m) & (xs < box.x_max_m)
        inside_y = (ys > box.y_min_m) & (ys < box.y_max_m)
        occupied |= inside_y[:, None] & inside_x[None, :]
    grid = inflated_map_grid(occupied, cell_m, problem.inflation_m, problem.boxes or None,
                             origin_m=(bounds.x_min_m, bounds.y_min_m))
    if problem.obstacles:
        discs = rasterise(bounds, problem.obstacles, (), problem.inflation_m, cell_m)
        grid = OccupancyGrid(grid.occupied | discs.occupied, grid.cell_m, grid.origin_m)
    return grid


def occupied_cells(grid: OccupancyGrid, centres_m: np.ndarray, reach_m: np.ndarray) -> np.ndarray:
    """(rows, cols) cells whose centres lie within ``reach_m[i]`` of obstacle centre ``i`` ("Dobstacle")."""
    rows, cols = grid.shape
    out = np.zeros((rows, cols), dtype=bool)
    xs = grid.origin_m[0] + (np.arange(cols) + 0.5) * grid.cell_m
    ys = grid.origin_m[1] + (np.arange(rows) + 0.5) * grid.cell_m
    for (x, y), r in zip(np.asarray(centres_m, dtype=float).reshape(-1, 2), np.asarray(reach_m, dtype=float)):
        out |= (ys[:, None] - y) ** 2 + (xs[None, :] - x) ** 2 < r * r
    return out


def grid_problem(problem: Problem, grid: OccupancyGrid, start_cell: Cell) -> Problem:
    """The problem from a cell's centre to the goal on ``grid`` (its discs are in the grid), for replanning."""
    x, y = grid.centres_m(np.array([start_cell]))[0]
    return replace(problem, start=Pose2D(float(x), float(y), problem.start.heading_rad), obstacles=(),
                   grid_override=grid)


def cells_of_path(path: Path, grid: OccupancyGrid) -> list[Cell]:
    """A planner's cells (its ``raw_cells``), else its waypoints' cells joined by 8-neighbour steps."""
    raw = path.stats.extra.get("raw_cells")
    if raw:
        return [(int(r), int(c)) for r, c in raw]
    cells: list[Cell] = []
    for x, y in np.asarray(path.waypoints, dtype=float):
        cell = grid.cell_of(float(x), float(y))
        cells.extend(step_line(cells[-1], cell)[1:] if cells else [cell])
    return cells


def pulled_corners(occupied: np.ndarray, cells: list[Cell]) -> list[Cell]:
    """The cells where a cell path must turn: greedy line of sight over the free cells (first and last kept).

    A cell of the path that is blocked (the map changed under it) keeps the path as it is there: a line of
    sight from a blocked cell is never taken."""
    if len(cells) <= 2:
        return list(cells)
    free = (~np.asarray(occupied, dtype=bool)).tolist()
    out = [cells[0]]
    anchor = 0
    while anchor < len(cells) - 1:
        nxt = anchor + 1
        while nxt + 1 < len(cells) and grid_line_of_sight(free, cells[anchor], cells[nxt + 1]):
            nxt += 1
        out.append(cells[nxt])
        anchor = nxt
    return out


def step_line(a: Cell, b: Cell) -> list[Cell]:
    """Cells from ``a`` to ``b`` by 8-neighbour steps, diagonal first then straight (both included)."""
    out = [a]
    r, c = a
    while (r, c) != b:
        r += int(np.sign(b[0] - r))
        c += int(np.sign(b[1] - c))
        out.append((r, c))
    return out


def heading_of(cells: list[Cell], index: int) -> Cell:
    """The 8-neighbour step from ``cells[index]`` to the next cell ((0, 0) at the end)."""
    if index + 1 >= len(cells):
        return (0, 0)
    (r0, c0), (r1, c1) = cells[index], cells[index + 1]
    return (int(np.sign(r1 - r0)), int(np.sign(c1 - c0)))


@dataclass
class CellWalker:
    """Drives a controller through a list of cells and counts the cells reached.

    ``index`` is the last cell of ``cells`` the robot has reached (within
    ``reach_m`` of its centre); :meth:`command` returns whether a new cell was
    reached this step.

    ``pulled`` (ours, off by default: the papers' robot visits every cell centre): the controller is handed
    the cells' corners (:func:`pulled_corners` on the grid) instead of every centre, and a cell counts as
    reached when it is the furthest of the next ``PULLED_WINDOW`` cells within ``reach_m`` of the robot (the
    robot cuts the staircase of an 8-neighbour path, so it passes beside some centres, not over them).
    """

    controller: Controller
    grid: OccupancyGrid
    reach_m: float
    pulled: bool = False

    PULLED_WINDOW = 12

    def start(self, cells: list[Cell], index: int = 0) -> Path:
        self.cells = list(cells)
        self.index = index
        return self._hand_over()

    def _hand_over(self) -> Path:
        rest = self.cells[self.index:]
        if self.pulled:
            rest = pulled_corners(self.grid.occupied, rest)
        waypoints = self.grid.centres_m(np.array(rest)).reshape(-1, 2)
        self.waypoints = [(float(x), float(y)) for x, y in waypoints]
        path = Path.from_waypoints(waypoints, 0.0)
        self.controller.reset(path)
        return path

    def centre(self, cell: Cell) -> np.ndarray:
        return self.grid.centres_m(np.array([cell]))[0]

    def command(self, pose: Pose2D, twist: Twist) -> tuple[ControlCommand, bool]:
        reached = False
        if self.pulled:
            ahead = self.cells[self.index + 1:self.index + 1 + self.PULLED_WINDOW]
            if ahead:
                centres = self.grid.centres_m(np.array(ahead)).reshape(-1, 2)
                near = np.flatnonzero(np.hypot(centres[:, 0] - pose.x_m, centres[:, 1] - pose.y_m) <= self.reach_m)
                if near.size:
                    self.index += int(near[-1]) + 1
                    reached = True
            return self.controller.command(pose, twist), reached
        while self.index + 1 < len(self.cells):
            x, y = self.centre(self.cells[self.index + 1])
            if math.hypot(x - pose.x_m, y - pose.y_m) > self.reach_m:
                break
            self.index += 1
            reached = True
        return self.controller.command(pose, twist), reached

    @property
    def cell(self) -> Cell:
        return self.cells[self.index]

    @property
    def at_end(self) -> bool:
        return self.index + 1 >= len(self.cells)
