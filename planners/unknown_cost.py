"""Unknown cells made costly for the grid searches (``knowledge = { unknown_cost = ... }``, map unknown).

A sensed map's never-seen cells are free by default (Nav2's ``allow_unknown``).  With a positive
``Problem.unknown_cost`` the grid searches ``astar`` and ``dijkstra`` price a move by its length times the mean
of its two cells' weights, ``1 + unknown_cost`` on an unknown cell (``Problem.unknown_cells``) and 1 on a known
one, so they route through space the laser has seen free unless the detour costs more (Nav2's costmap gives
unknown cells a cost likewise; its planners weigh cost against length).  The search is SciPy's Dijkstra
(``scipy.sparse.csgraph``) over the grid graph of :mod:`planners.grid_graph` (8-connected, no corner cutting),
since the compiled searches take uniform costs; the path is then shortcut between its own vertices only
where the straight segment is clear (the exact test of :mod:`planners.grid_shortcut`) and costs no more than
the cells it replaces.  No other planner reads the cost.
"""

from __future__ import annotations

import math

import numpy as np

from swarmnav.models.world import OccupancyGrid
from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.grid_graph import DIRECTIONS, STEP_COSTS, Cell
from swarmnav.planners.grid_shortcut import segments_clear
from swarmnav.planners.problem import Problem


def cell_weights(problem: Problem, grid: OccupancyGrid) -> np.ndarray:
    """(rows, cols) weights of the planner's grid cells: 1, or ``1 + unknown_cost`` where the cell's centre lies
    in an unknown cell of ``problem.unknown_cells``."""
    weights = np.ones(grid.shape)
    unknown = problem.unknown_cells
    if unknown is None or problem.unknown_cost <= 0.0:
        return weights
    rows, cols = grid.shape
    xs = grid.origin_m[0] + (np.arange(cols) + 0.5) * grid.cell_m
    ys = grid.origin_m[1] + (np.arange(rows) + 0.5) * grid.cell_m
    uc = np.clip(np.floor((xs - unknown.origin_m[0]) / unknown.cell_m).astype(int), 0, unknown.shape[1] - 1)
    ur = np.clip(np.floor((ys - unknown.origin_m[1]) / unknown.cell_m).astype(int), 0, unknown.shape[0] - 1)
    weights[unknown.occupied[np.ix_(ur, uc)]] += problem.unknown_cost
    return weights


def weighted_cells(occupied: np.ndarray, weights: np.ndarray, start: Cell, goal: Cell
                   ) -> tuple[list[Cell], float, int]:
    """The cheapest cell path (cells, cost in cell lengths, cells settled) from ``start`` to ``goal``.

    Raises:
        NoPathFound: the goal cannot be reached.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra
    rows, cols = occupied.shape
    free = ~np.asarray(occupied, dtype=bool)
    index = np.arange(rows * cols).reshape(rows, cols)
    heads, tails, costs = [], [], []
    for (dr, dc), step in zip(DIRECTIONS, STEP_COSTS):
        r0, r1 = max(0, -dr), rows - max(0, dr)
        c0, c1 = max(0, -dc), cols - max(0, dc)
        ok = free[r0:r1, c0:c1] & free[r0 + dr:r1 + dr, c0 + dc:c1 + dc]
        if dr and dc:  # no corner cutting: both orthogonal cells passed must be free
            ok &= free[r0 + dr:r1 + dr, c0:c1] & free[r0:r1, c0 + dc:c1 + dc]
        heads.append(index[r0:r1, c0:c1][ok])
        tails.append(index[r0 + dr:r1 + dr, c0 + dc:c1 + dc][ok])
        costs.append(step * 0.5 * (weights[r0:r1, c0:c1][ok] + weights[r0 + dr:r1 + dr, c0 + dc:c1 + dc][ok]))
    n = rows * cols
    graph = coo_matrix((np.concatenate(costs), (np.concatenate(heads), np.concatenate(tails))), shape=(n, n)).tocsr()
    s, g = start[0] * cols + start[1], goal[0] * cols + goal[1]
    dist, pred = dijkstra(graph, indices=s, return_predecessors=True)
    if not math.isfinite(dist[g]):
        raise NoPathFound(f"goal cell {goal} is unreachable from start cell {start}")
    path = [g]
    while path[-1] != s:
        path.append(int(pred[path[-1]]))
    return [divmod(v, cols) for v in reversed(path)], float(dist[g]), int(np.isfinite(dist).sum())


def _segment_cost(a: np.ndarray, b: np.ndarray, grid: OccupancyGrid, weights: np.ndarray) -> float:
    """The weighted length of the segment a-b (in metres), sampled every half cell."""
    length = float(np.hypot(*(b - a)))
    n = max(1, int(math.ceil(length / (0.5 * grid.cell_m))))
    mids = a + np.outer((np.arange(n) + 0.5) / n, b - a)
    c = np.clip(np.floor((mids[:, 0] - grid.origin_m[0]) / grid.cell_m).astype(int), 0, grid.shape[1] - 1)
    r = np.clip(np.floor((mids[:, 1] - grid.origin_m[1]) / grid.cell_m).astype(int), 0, grid.shape[0] - 1)
    return length * float(weights[r, c].mean())


def cost_shortcut(problem: Problem, grid: OccupancyGrid, weights: np.ndarray, waypoints: np.ndarray) -> np.ndarray:
    """Greedy shortcutting of a weighted path: from each kept vertex, the farthest later vertex whose straight
    segment is clear and costs no more than the path between them."""
    pts = np.asarray(waypoints, dtype=float)
    along = np.array([0.0] + [_segment_cost(pts[k], pts[k + 1], grid, weights) for k in range(len(pts) - 1)])
    cumulative = np.cumsum(along)
    kept, i = [pts[0]], 0
    while i < len(pts) - 1:
        clear = segments_clear(problem, pts[i], pts[i + 1:])
        j = i + 1
        for k in range(len(pts) - 1, i + 1, -1):
            if clear[k - i - 1] and _segment_cost(pts[i], pts[k], grid, weights) <= \
                    cumulative[k] - cumulative[i] + 1e-9:
                j = k
                break
        kept.append(pts[j])
        i = j
    return np.array(kept)
