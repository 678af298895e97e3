"""Line-of-sight shortcutting of a polyline, shared by every grid planner."""

from __future__ import annotations

import numpy as np

from planners.problem import Problem


def segment_is_clear(problem: Problem, a: np.ndarray, b: np.ndarray) -> bool:
    """True when the segment a-b keeps the problem's inflation from every obstacle.

    Discs are tested exactly (segment-disc distance).  Box obstacles and grids
    given directly (maps) are tested on the inflated grid, sampled every quarter cell.
    """
    pts = np.vstack([a, b])
    if problem.obstacles and problem.path_clearance_m(pts) < 0.0:
        return False
    if problem.boxes or problem.grid_override is not None:
        grid = problem.grid
        length = float(np.hypot(*(b - a)))
        n = max(2, int(np.ceil(length / (grid.cell_m * 0.25))) + 1)
        t = np.linspace(0.0, 1.0, n)[:, None]
        samples = a[None, :] * (1.0 - t) + b[None, :] * t
        cols = np.floor((samples[:, 0] - grid.origin_m[0]) / grid.cell_m).astype(int)
        rows = np.floor((samples[:, 1] - grid.origin_m[1]) / grid.cell_m).astype(int)
        h, w = grid.occupied.shape
        if np.any((rows < 0) | (rows >= h) | (cols < 0) | (cols >= w)):
            return False
        if np.any(grid.occupied[rows, cols]):
            return False
    return True


def shortcut(problem: Problem, waypoints: np.ndarray) -> np.ndarray:
    """Greedy line-of-sight shortcut: from each kept vertex jump to the farthest visible one.

    The first and last vertices are kept.  Consecutive vertices are assumed
    mutually visible (as grid moves between free cells are), so this never fails.
    """
    pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    if len(pts) <= 2:
        return pts.copy()
    kept = [0]
    i = 0
    last = len(pts) - 1
    while i < last:
        j = last
        while j > i + 1 and not segment_is_clear(problem, pts[i], pts[j]):
            j -= 1
        kept.append(j)
        i = j
    return pts[kept]
