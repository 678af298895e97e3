"""The total arc cost of a grid tour priced on the map as given, the same field for every planner.

Hasan, Abdullah & Saleh (2023) report each method's "Total Arc Cost" (Table 1): IMMAS sums the route cost
``k`` of every cell its tour enters (Algorithm 3 line 25, ``PathCost = PathCost + X.k``), ``k`` being the
cost to the goal its propagation computes (Algorithm 1) on the map *after* closing gates and tight
tunnels.  ``immas`` reports that sum as ``total_arc_cost``.  A baseline (``mmas``) has no propagation, and
IMMAS's ``k`` is raised where it closed cells, so comparing ``total_arc_cost`` with anything would price two
tours by two fields.  :func:`map_arc_cost` prices any tour by one field, the map's own: ``k`` of an exact
8-connected Dijkstra from the goal over the occupancy grid as given (diagonal moves cost 1.4 as in
Algorithm 1, no corner cutting, as every grid planner here: :mod:`planners.grid_graph`).  The planners
report it as ``map_arc_cost`` (the studies' ``plan_map_arc_cost``); our reading, stated in ``docs/papers.md``.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from swarmnav.planners.grid_graph import DIRECTIONS, Cell

#: Algorithm 1's cost of a diagonal move (Hasan et al. 2023, "multiply by 1.4 or 1").
DIAGONAL_COST = 1.4


def cost_to_goal(occupied: np.ndarray, goal: Cell, diagonal_cost: float = DIAGONAL_COST) -> np.ndarray:
    """``k`` of every cell: the cost of its cheapest 8-connected route to ``goal`` (inf: occupied or cut off).

    Args:
        occupied: (rows, cols) True where blocked.
        goal: the goal cell (row, col).
        diagonal_cost: the cost of a diagonal move (an orthogonal one costs 1).
    """
    occ = np.asarray(occupied, dtype=bool)
    rows, cols = occ.shape
    free = ~occ
    index = np.arange(rows * cols).reshape(rows, cols)
    heads, tails, costs = [], [], []
    for dr, dc in DIRECTIONS:
        # cells (r, c) whose neighbour (r + dr, c + dc) is inside the grid
        r0, r1 = max(0, -dr), rows - max(0, dr)
        c0, c1 = max(0, -dc), cols - max(0, dc)
        ok = free[r0:r1, c0:c1] & free[r0 + dr:r1 + dr, c0 + dc:c1 + dc]
        if dr and dc:   # no corner cutting: both orthogonal cells passed must be free
            ok &= free[r0:r1, c0 + dc:c1 + dc] & free[r0 + dr:r1 + dr, c0:c1]
        heads.append(index[r0:r1, c0:c1][ok])
        tails.append(index[r0 + dr:r1 + dr, c0 + dc:c1 + dc][ok])
        costs.append(np.full(int(ok.sum()), diagonal_cost if dr and dc else 1.0))
    graph = coo_matrix((np.concatenate(costs), (np.concatenate(heads), np.concatenate(tails))),
                       shape=(rows * cols, rows * cols)).tocsr()
    k = dijkstra(graph, directed=True, indices=int(index[goal]))
    k[occ.ravel()] = np.inf
    return k.reshape(rows, cols)


def map_arc_cost(occupied: np.ndarray, goal: Cell, cells: list[Cell] | np.ndarray) -> float:
    """The tour's total arc cost on the map as given: ``sum k(X)`` over every cell it enters (not the start).

    Args:
        occupied: (rows, cols) True where blocked.
        goal: the goal cell.
        cells: the tour, start first, as (row, col) cells.
    """
    idx = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    if idx.shape[0] < 2:
        return 0.0
    k = cost_to_goal(occupied, goal)
    return float(np.sum(k[idx[1:, 0], idx[1:, 1]]))
