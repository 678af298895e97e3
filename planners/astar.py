"""A* on the inflated occupancy grid: the foundation's grid baseline.

8-connected, no corner cutting (a diagonal move needs both orthogonal
neighbours free, the Moving AI convention), octile heuristic, heapq.  The cell
path is then shortcut by line of sight so the robot is not asked to zig-zag.
"""

from __future__ import annotations

import heapq
import math
import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from planners.errors import NoPathFound
from planners.problem import OccupancyGrid, Path, Problem, check_endpoints
from planners.shortcut import shortcut

SQRT2 = math.sqrt(2.0)
# (d_row, d_col, cost in cells)
MOVES_8 = ((-1, 0, 1.0), (1, 0, 1.0), (0, -1, 1.0), (0, 1, 1.0),
           (-1, -1, SQRT2), (-1, 1, SQRT2), (1, -1, SQRT2), (1, 1, SQRT2))


def octile_cells(dr: int, dc: int) -> float:
    """Octile distance in cells between two cells ``dr`` rows and ``dc`` columns apart."""
    dr, dc = abs(dr), abs(dc)
    return (SQRT2 - 1.0) * min(dr, dc) + max(dr, dc)


def astar_cells(occupied: np.ndarray, start: tuple[int, int], goal: tuple[int, int],
                heuristic_weight: float = 1.0) -> tuple[list[tuple[int, int]], float, int]:
    """A* over an 8-connected grid without corner cutting.

    Args:
        occupied: (rows, cols) bool, True where blocked.
        start, goal: (row, col) cells; both must be free.
        heuristic_weight: 1.0 for optimal A*, 0.0 for Dijkstra.

    Returns:
        (cells from start to goal, cost in cells, number of expansions).

    Raises:
        NoPathFound: the goal is unreachable.
    """
    rows, cols = occupied.shape
    free = ~occupied
    g = np.full(rows * cols, np.inf)
    parent = np.full(rows * cols, -1, dtype=np.int64)
    closed = np.zeros(rows * cols, dtype=bool)
    gr, gc = goal
    s = start[0] * cols + start[1]
    goal_idx = gr * cols + gc
    g[s] = 0.0
    heap = [(heuristic_weight * octile_cells(start[0] - gr, start[1] - gc), 0.0, s)]
    expansions = 0
    free_list = free.tolist()
    while heap:
        _, gcur, cur = heapq.heappop(heap)
        if closed[cur]:
            continue
        closed[cur] = True
        expansions += 1
        if cur == goal_idx:
            break
        r, c = divmod(cur, cols)
        for dr, dc, cost in MOVES_8:
            nr, nc = r + dr, c + dc
            if not (0 <= nr < rows and 0 <= nc < cols) or not free_list[nr][nc]:
                continue
            if dr and dc and not (free_list[r][nc] and free_list[nr][c]):
                continue
            nxt = nr * cols + nc
            ng = gcur + cost
            if ng < g[nxt]:
                g[nxt] = ng
                parent[nxt] = cur
                h = heuristic_weight * octile_cells(nr - gr, nc - gc)
                heapq.heappush(heap, (ng + h, ng, nxt))
    if not closed[goal_idx]:
        raise NoPathFound(f"goal cell {goal} is unreachable from start cell {start}")
    cells = []
    cur = goal_idx
    while cur != -1:
        cells.append(divmod(int(cur), cols))
        cur = parent[cur]
    cells.reverse()
    return cells, float(g[goal_idx]), expansions


def grid_endpoints(problem: Problem, grid: OccupancyGrid) -> tuple[tuple[int, int], tuple[int, int]]:
    """Start and goal cells, checked free on the inflated grid."""
    from planners.errors import GoalBlocked, StartBlocked

    start = grid.cell_of(problem.start.x_m, problem.start.y_m)
    goal = grid.cell_of(problem.goal.x_m, problem.goal.y_m)
    if grid.occupied[start]:
        raise StartBlocked(f"start cell {start} is occupied on the inflated grid")
    if grid.occupied[goal]:
        raise GoalBlocked(f"goal cell {goal} is occupied on the inflated grid")
    return start, goal


@dataclass
class AStarPlanner:
    """Grid A* followed by line-of-sight shortcutting.

    Args:
        cell_m: grid resolution; ``None`` keeps the problem's.
        shortcut: apply line-of-sight shortcutting (on by default for execution).
    """

    name: ClassVar[str] = "astar"
    cell_m: float | None = None
    shortcut: bool = True

    def plan(self, problem: Problem, rng: np.random.Generator) -> Path:
        t0 = time.perf_counter()
        check_endpoints(problem)
        if self.cell_m is not None and self.cell_m != problem.cell_m:
            from dataclasses import replace
            problem = replace(problem, cell_m=self.cell_m)
        grid = problem.grid
        start, goal = grid_endpoints(problem, grid)
        cells, cost_cells, expansions = astar_cells(grid.occupied, start, goal)
        centres = grid.centres_m(np.array(cells))
        # The exact start and goal replace the centres of their cells.
        raw = np.vstack([problem.start.xy, centres[1:-1], problem.goal.xy]) if len(cells) > 1 \
            else np.vstack([problem.start.xy, problem.goal.xy])
        waypoints = shortcut(problem, raw) if self.shortcut else raw
        return Path.from_waypoints(
            waypoints, time.perf_counter() - t0, iterations=expansions, evaluations=expansions,
            extra={"raw_cells": [list(c) for c in cells], "raw_length_m": cost_cells * grid.cell_m})
