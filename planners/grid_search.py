"""Grid searches A* and Dijkstra, the planners ``astar`` and ``dijkstra``, and the grid planners' plumbing.

They search the shared grid graph (:mod:`planners.grid_graph`: 8-connected, no
corner cutting) with ``heapq`` over plain Python lists, reading each cell's moves
from the table of the 256 move masks.  :class:`GridPlanner` is the plumbing
every grid planner shares: it turns the cell path into waypoints in metres (the
exact start and goal replace the centres of their cells), keeps the raw cell
path in ``stats.extra["raw_cells"]``, and by default shortcuts it by exact line
of sight (:func:`planners.grid_shortcut.exact_shortcut`).  Theta* lives in
:mod:`planners.theta_star`, D* Lite in :mod:`planners.dstar_lite`.
"""

from __future__ import annotations

import heapq
import time
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from swarmnav.models.parameters import param, within
from swarmnav.models.world import OccupancyGrid
from swarmnav.planners.errors import NoPathFound, check_parameters
from swarmnav.planners._grid_search import astar
from swarmnav.planners.grid_graph import (ADJACENCY, DIRECTIONS, INF, SQRT2, STEP_COSTS, Cell, cells_to_waypoints,
                                          check_cells, count_bends, grid_endpoints, grid_problem, moves_by_mask)
from swarmnav.planners.grid_shortcut import exact_shortcut
from swarmnav.planners.problem import Path, Problem, check_endpoints
from swarmnav.planners.unknown_cost import cell_weights, cost_shortcut, weighted_cells


def _octile_to(goal: Cell, shape: tuple[int, int]) -> list[float]:
    rows, cols = shape
    dr = np.abs(np.arange(rows) - goal[0])[:, None]
    dc = np.abs(np.arange(cols) - goal[1])[None, :]
    return ((SQRT2 - 1.0) * np.minimum(dr, dc) + np.maximum(dr, dc)).ravel().tolist()



def astar_cells(occupied: np.ndarray, start: Cell, goal: Cell,
                heuristic_weight: float = 1.0) -> tuple[list[Cell], float, int]:
    """:func:`astar_cells_reference`, compiled (``planners/_grid_search.c``): the same cells, cost and expansions.

    The heap loop in Python costs ~1-2 ms on a 50 x 50 map (profiled, issue 14); the C search
    orders its open list by the same (f, -g, cell) keys, all distinct, and does the same double
    arithmetic (the octile heuristic computed per cell as the reference's NumPy table does), so it
    expands the same cells in the same order.
    """
    occupied = np.asarray(occupied, dtype=bool)
    check_cells(occupied, start, goal)
    cols = occupied.shape[1]
    path, cost, expansions = astar(ADJACENCY.get_array(occupied), _MOVE_OFFSETS[cols], _MOVE_COSTS, cols,
                                   SQRT2 - 1.0, float(heuristic_weight), start[0] * cols + start[1],
                                   goal[0] * cols + goal[1])
    if path is None:
        raise NoPathFound(f"goal cell {goal} is unreachable from start cell {start}")
    return [divmod(v, cols) for v in path], cost, expansions


class _MoveOffsets(dict):
    """Flat-index offsets of the 8 moves of :data:`planners.grid_graph.DIRECTIONS`, by grid width."""

    def __missing__(self, cols: int) -> np.ndarray:
        self[cols] = offsets = np.array([dr * cols + dc for dr, dc in DIRECTIONS], dtype=np.int64)
        return offsets


_MOVE_OFFSETS = _MoveOffsets()
_MOVE_COSTS = np.array(STEP_COSTS, dtype=float)


def astar_cells_reference(occupied: np.ndarray, start: Cell, goal: Cell,
                          heuristic_weight: float = 1.0) -> tuple[list[Cell], float, int]:
    """A* (or Dijkstra with ``heuristic_weight=0``) over an 8-connected grid without corner cutting.

    Ties on f are broken towards the larger g, which keeps A* expansions low on open maps.

    Args:
        occupied: (rows, cols) bool, True where blocked.
        start, goal: (row, col) cells; both must be free.
        heuristic_weight: 1.0 for optimal A* (octile heuristic), 0.0 for Dijkstra.

    Returns:
        (cells from start to goal, cost in cells, number of expansions).

    Raises:
        StartBlocked, GoalBlocked: an endpoint is outside the grid or occupied.
        NoPathFound: the goal is unreachable.
    """
    occupied = np.asarray(occupied, dtype=bool)
    check_cells(occupied, start, goal)
    rows, cols = occupied.shape
    masks = ADJACENCY.get(occupied)
    moves = moves_by_mask(cols)
    s = start[0] * cols + start[1]
    t = goal[0] * cols + goal[1]
    n = rows * cols
    g = [INF] * n
    parent = [-1] * n
    closed = bytearray(n)
    g[s] = 0.0
    push, pop = heapq.heappush, heapq.heappop
    if heuristic_weight:
        h = _octile_to(goal, occupied.shape)
        if heuristic_weight != 1.0:
            h = [heuristic_weight * v for v in h]
        heap = [(h[s], 0.0, s)]
    else:
        h = None
        heap = [(0.0, 0.0, s)]
    expansions = 0
    while heap:
        _, _, u = pop(heap)
        if closed[u]:
            continue
        closed[u] = 1
        expansions += 1
        if u == t:
            break
        gu = g[u]
        for off, w in moves[masks[u]]:
            v = u + off
            nv = gu + w
            if nv < g[v]:
                g[v] = nv
                parent[v] = u
                push(heap, ((nv + h[v]) if h is not None else nv, -nv, v))
    if not closed[t]:
        raise NoPathFound(f"goal cell {goal} is unreachable from start cell {start}")
    return _walk_back(parent, t, cols), g[t], expansions


def dijkstra_cells(occupied: np.ndarray, start: Cell, goal: Cell) -> tuple[list[Cell], float, int]:
    """Dijkstra over the same graph as :func:`astar_cells` (no heuristic)."""
    return astar_cells(occupied, start, goal, heuristic_weight=0.0)


def _walk_back(parent: list[int], t: int, cols: int) -> list[Cell]:
    cells = []
    cur = t
    while cur != -1:
        cells.append(divmod(cur, cols))
        cur = parent[cur]
    cells.reverse()
    return cells


@dataclass
class GridPlanner:
    """Shared plumbing of the grid planners: endpoints, waypoints, shortcut and stats.

    Subclasses define ``name`` and :meth:`search`.
    """

    name: ClassVar[str] = ""
    honours_unknown_cost: ClassVar[bool] = False  # astar and dijkstra: Problem.unknown_cost (planners.unknown_cost)
    supports: ClassVar[frozenset[str]] = frozenset({"discs", "boxes"})
    cell_m: float | None = param(None, within(1e-6, 100))
    shortcut: bool = True

    def __post_init__(self) -> None:
        check_parameters(self, (("cell_m", self.cell_m is None or self.cell_m > 0, "must be positive"),))

    def search(self, problem: Problem, grid: OccupancyGrid, start: Cell, goal: Cell
               ) -> tuple[list[Cell], float, int, dict[str, Any]]:
        """Return (cells, cost in cells, expansions, extra stats)."""
        raise NotImplementedError

    def plan(self, problem: Problem, rng: np.random.Generator) -> Path:
        t0 = time.perf_counter()
        check_endpoints(problem)
        problem = grid_problem(problem, self.cell_m)
        grid = problem.grid
        start, goal = grid_endpoints(problem, grid)
        weighted = self.honours_unknown_cost and problem.unknown_cells is not None and problem.unknown_cost > 0.0
        if weighted:  # costly unknown cells (planners.unknown_cost): a weighted Dijkstra, a cost-aware shortcut
            weights = cell_weights(problem, grid)
            cells, cost_cells, expansions = weighted_cells(grid.occupied, weights, start, goal)
            extra = {"unknown_cost": problem.unknown_cost}
        else:
            cells, cost_cells, expansions, extra = self.search(problem, grid, start, goal)
        raw = cells_to_waypoints(problem, grid, cells)
        if weighted:
            waypoints = cost_shortcut(problem, grid, weights, raw) if self.shortcut else raw
        else:
            waypoints = exact_shortcut(problem, raw) if self.shortcut else raw
        stats = {"raw_cells": [list(c) for c in cells], "raw_length_m": cost_cells * grid.cell_m,
                 "bends": count_bends(cells)}
        stats.update(extra)
        return Path.from_waypoints(waypoints, time.perf_counter() - t0, iterations=expansions,
                                   evaluations=expansions, extra=stats)


@dataclass
class AStarPlanner(GridPlanner):
    """Grid A* (octile heuristic, no corner cutting), then exact line-of-sight shortcutting.

    Args:
        cell_m: grid resolution; ``None`` keeps the problem's.  The grid may have at most
            :data:`planners.grid_graph.MAX_GRID_CELLS` (5,000,000) cells.
        shortcut: apply line-of-sight shortcutting (on by default for execution).
    """

    name: ClassVar[str] = "astar"
    honours_unknown_cost: ClassVar[bool] = True

    def search(self, problem, grid, start, goal):
        cells, cost, expansions = astar_cells(grid.occupied, start, goal)
        return cells, cost, expansions, {}


@dataclass
class DijkstraPlanner(GridPlanner):
    """Grid Dijkstra over the same 8-connected graph as A* (the uninformed baseline)."""

    name: ClassVar[str] = "dijkstra"
    honours_unknown_cost: ClassVar[bool] = True

    def search(self, problem, grid, start, goal):
        cells, cost, expansions = dijkstra_cells(grid.occupied, start, goal)
        return cells, cost, expansions, {}
