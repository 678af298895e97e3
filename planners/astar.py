"""A* on the inflated occupancy grid: the foundation's grid baseline.

The search itself now lives in :mod:`planners.grid_search` beside Dijkstra,
Theta* and D* Lite (one neighbour table, one set of conventions: 8-connected,
no corner cutting, octile heuristic).  This module keeps the foundation's names.
"""

from planners.grid_search import (MOVES_8, SQRT2, AStarPlanner, astar_cells, grid_endpoints,
                                  octile_cells)

__all__ = ["AStarPlanner", "astar_cells", "grid_endpoints", "octile_cells", "MOVES_8", "SQRT2"]
