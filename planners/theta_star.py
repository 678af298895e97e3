"""Theta* (Nash, Daniel, Koenig & Felner 2007), the planner ``theta_star``: any-angle A* on the grid.

It searches the shared grid graph (:mod:`planners.grid_graph`: 8-connected, no corner cutting) as
A* does (:mod:`planners.grid_search`), except that a cell's parent may be any visible ancestor, and
runs through the grid planners' plumbing (:class:`planners.grid_search.GridPlanner`).
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass
from typing import Callable, ClassVar

import numpy as np

from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.grid_graph import ADJACENCY, INF, Cell, check_cells, grid_line_of_sight, moves_by_mask
from swarmnav.planners.grid_search import GridPlanner
from swarmnav.planners.grid_shortcut import box_line_of_sight


def theta_star_cells(occupied: np.ndarray, start: Cell, goal: Cell,
                     line_of_sight: Callable[[Cell, Cell], bool] | None = None
                     ) -> tuple[list[Cell], float, int]:
    """Theta* (Nash, Daniel, Koenig & Felner 2007): A* whose parent may be any visible ancestor.

    Args:
        occupied: (rows, cols) bool.
        start, goal: (row, col) free cells.
        line_of_sight: visibility test between two cells; by default
            :func:`grid_line_of_sight` on ``occupied``.  Each pair is asked
            at most once (answers are kept for the search).

    Returns:
        (corner cells from start to goal, Euclidean length in cells, expansions).
    """
    occupied = np.asarray(occupied, dtype=bool)
    check_cells(occupied, start, goal)
    rows, cols = occupied.shape
    masks = ADJACENCY.get(occupied)
    moves = moves_by_mask(cols)
    free = (~occupied).tolist()
    los = line_of_sight or (lambda p, q: grid_line_of_sight(free, p, q))
    s = start[0] * cols + start[1]
    t = goal[0] * cols + goal[1]
    n = rows * cols
    g = [INF] * n
    parent = [-1] * n
    closed = bytearray(n)
    seen: dict[int, bool] = {}      # line of sight by (parent, cell): Theta* asks most pairs several times
    g[s] = 0.0
    parent[s] = s
    gr, gc = goal

    def h(v: int) -> float:
        vr, vc = divmod(v, cols)
        return math.hypot(vr - gr, vc - gc)

    heap = [(h(s), 0.0, s)]
    expansions = 0
    while heap:
        _, _, u = heapq.heappop(heap)
        if closed[u]:
            continue
        closed[u] = 1
        expansions += 1
        if u == t:
            break
        pu = parent[u]
        pr, pc = divmod(pu, cols)
        ur, uc = divmod(u, cols)
        for off, w in moves[masks[u]]:
            v = u + off
            if closed[v]:
                continue
            vr, vc = divmod(v, cols)
            if pu != u:
                key = pu * n + v
                visible = seen.get(key)
                if visible is None:
                    visible = seen[key] = los((pr, pc), (vr, vc))
            else:
                visible = False
            if visible:
                cand, par = g[pu] + math.hypot(vr - pr, vc - pc), pu
            else:
                cand, par = g[u] + w, u
            if cand < g[v] - 1e-12:
                g[v] = cand
                parent[v] = par
                heapq.heappush(heap, (cand + h(v), -cand, v))
    if not closed[t]:
        raise NoPathFound(f"goal cell {goal} is unreachable from start cell {start}")
    return _corners(parent, s, t, cols), g[t], expansions


def _corners(parent: list[int], s: int, t: int, cols: int) -> list[Cell]:
    """Theta*'s cells from ``s`` to ``t`` along ``parent`` (the start is its own parent)."""
    cells = []
    cur = t
    while True:
        cells.append(divmod(cur, cols))
        if cur == s:
            break
        cur = parent[cur]
    cells.reverse()
    return cells



@dataclass
class ThetaStarPlanner(GridPlanner):
    """Theta*, any-angle: the grid yardstick for the length of a path that need not follow moves.

    Line of sight is checked cell by cell on the inflated grid and, where the
    problem has box obstacles (maps), also exactly against the inflated boxes
    (:func:`box_line_of_sight`).
    """

    name: ClassVar[str] = "theta_star"

    def search(self, problem, grid, start, goal):
        los = box_line_of_sight(problem, grid) if problem.boxes else None
        cells, cost, expansions = theta_star_cells(grid.occupied, start, goal, los)
        return cells, cost, expansions, {}
