"""Exact line-of-sight shortcutting of grid paths against the inflated obstacles.

A grid path follows cell moves; :func:`exact_shortcut` replaces it by the fewest
of its own vertices that see each other, where "see" is the problem's one exact
segment test (:meth:`planners.problem.Problem.segment_clearances_m`: segment-disc
and segment-box distances) or, on a bare grid without boxes, the cell walk of
:func:`planners.grid_graph.grid_line_of_sight`.  :func:`box_line_of_sight` is the
same exact test between cell centres, culled per cell, for Theta*.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from swarmnav.models.geometry import segment_box_distance, segment_box_pair_distances, segment_disc_distances
from swarmnav.models.world import OccupancyGrid
from swarmnav.planners.grid_graph import Cell, grid_line_of_sight, line_cells
from swarmnav.planners.obstacle_buckets import ClearanceBuckets
from swarmnav.planners.problem import Problem


def segments_clear(problem: Problem, a: np.ndarray, bs: np.ndarray, tolerance_m: float = 1e-9,
                   buckets: ClearanceBuckets | None = None) -> np.ndarray:
    """For each end point in ``bs`` (K, 2), whether the segment from ``a`` stays in the bounds
    and keeps the inflation (:meth:`~planners.problem.Problem.segment_clearances_m` ``>= -tolerance_m``).

    With ``buckets`` (:func:`clearance_buckets` of the same problem) only the obstacles
    near each segment are measured (the same decision; the tests compare them).
    A grid given directly without boxes (a bare map) is tested cell by cell with
    :func:`grid_line_of_sight`.
    """
    bs = np.asarray(bs, dtype=float).reshape(-1, 2)
    a = np.asarray(a, dtype=float).reshape(1, 2)
    ok = problem.in_bounds(bs, tolerance_m)
    if buckets is not None:
        ok &= buckets.segments_clear(a, bs, tolerance_m)
    elif problem.boxes:
        ok &= _fan_clear(problem, a, bs, tolerance_m)
    else:
        ok &= problem.segment_clearances_m(a, bs, cull_beyond_m=0.0) >= -tolerance_m
    if not problem.boxes and problem.grid_override is not None:
        grid = problem.grid
        free = (~grid.occupied).tolist()
        ca = grid.cell_of(*a[0])
        for k in np.flatnonzero(ok):
            ok[k] = grid_line_of_sight(free, ca, grid.cell_of(*bs[k]))
    return ok


def _fan_clear(problem: Problem, a: np.ndarray, bs: np.ndarray, tolerance_m: float) -> np.ndarray:
    """``problem.segment_clearances_m(a, bs, cull_beyond_m=0.0) >= -tolerance_m``, each box measured
    only against the segments whose bounding box, grown by the inflation, it reaches.

    The same decision: a box beyond that reach of a segment is farther than the inflation from it
    (a positive gap, which cannot make the segment blocked), and the pairs that are measured get
    the distances of :func:`~planners.geometry.segment_box_distances` (computed pair by pair,
    bit for bit the same).  A fan of 32 segments meets a few of a map's boxes each, where the
    segments' joint bounding box meets most of them (profiled: 13 such fans made ~2/3 of an
    ``astar`` plan on a 50 x 50 map).
    """
    a_k, bs = np.broadcast_arrays(a, bs)
    clear = np.ones(len(bs), dtype=bool)
    if problem.obstacles:
        d = segment_disc_distances(a_k, bs, problem.disc_centres_m)
        clear = np.min(d - problem.inflated_radii_m[None, :], axis=1) >= -tolerance_m
    boxes, reach_m = problem.box_array_m, problem.inflation_m
    lo = np.minimum(a_k, bs) - reach_m
    hi = np.maximum(a_k, bs) + reach_m
    near = ((boxes[None, :, 0] <= hi[:, None, 0]) & (boxes[None, :, 2] >= lo[:, None, 0])
            & (boxes[None, :, 1] <= hi[:, None, 1]) & (boxes[None, :, 3] >= lo[:, None, 1]))
    seg, box = np.nonzero(near)
    if seg.size:
        gap = segment_box_pair_distances(a_k[seg], bs[seg], boxes[box]) - reach_m
        clear[seg[gap < -tolerance_m]] = False
    return clear


#: Fewest obstacles for which :func:`exact_shortcut` files them in buckets: below it, measuring
#: every obstacle in one NumPy call is as fast (the buckets' own NumPy calls cost as much).
BUCKETS_FROM_OBSTACLES = 256


def clearance_buckets(problem: Problem) -> ClearanceBuckets | None:
    """The problem's inflated discs and boxes filed in buckets (:mod:`planners.obstacle_buckets`),
    or None with fewer than :data:`BUCKETS_FROM_OBSTACLES` obstacles."""
    if len(problem.obstacles) + len(problem.boxes) < BUCKETS_FROM_OBSTACLES:
        return None
    return ClearanceBuckets.of(problem.disc_centres_m, problem.inflated_radii_m, problem.box_array_m,
                               problem.inflation_m)


def boxes_by_cell(grid: OccupancyGrid, boxes: np.ndarray, reach_m: float) -> list[tuple[int, ...]]:
    """For each cell (row-major index), the boxes that come within ``reach_m`` of it.

    A box is listed when its footprint grown by ``reach_m`` (a square, so a
    superset of the round Minkowski sum) overlaps the closed cell.  So any
    point of a cell that lies within ``reach_m`` of a box has that box in the
    cell's list.

    Args:
        grid: the grid whose cells are indexed.
        boxes: (B, 4) rows of (x_min, y_min, x_max, y_max) in metres.
        reach_m: how far from a box a cell may be and still list it.
    """
    rows, cols = grid.occupied.shape
    boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
    x_edges = grid.origin_m[0] + np.arange(cols + 1) * grid.cell_m
    y_edges = grid.origin_m[1] + np.arange(rows + 1) * grid.cell_m
    col_near = (x_edges[None, :-1] <= boxes[:, 2:3] + reach_m) & (x_edges[None, 1:] >= boxes[:, 0:1] - reach_m)
    row_near = (y_edges[None, :-1] <= boxes[:, 3:4] + reach_m) & (y_edges[None, 1:] >= boxes[:, 1:2] - reach_m)
    near = row_near[:, :, None] & col_near[:, None, :]               # (B, rows, cols)
    box_ids, cell_ids = np.nonzero(near.reshape(len(boxes), -1))
    lists: list[list[int]] = [[] for _ in range(rows * cols)]
    for k, i in zip(box_ids.tolist(), cell_ids.tolist()):
        lists[i].append(k)
    return [tuple(ids) for ids in lists]


def box_line_of_sight(problem: Problem, grid: OccupancyGrid, tolerance_m: float = 1e-9
                      ) -> Callable[[Cell, Cell], bool]:
    """Exact visibility between cell centres: free cells only, and the inflation kept from every box.

    The segment must pass only through free cells (:func:`grid_line_of_sight`)
    and keep at least ``problem.inflation_m`` (less ``tolerance_m``) from every
    box of ``problem.box_array_m``.

    Speed without giving up exactness: every cell lists the boxes within the
    inflation of it (:func:`boxes_by_cell`, once per call of this function), and
    the cells a segment enters (:func:`line_cells`) cover all its points, so
    only the boxes those cells list can be within the inflation of the
    segment; those few are tested with the scalar
    :func:`~planners.geometry.segment_box_distance`.

    Returns:
        ``los(p, q)`` for (row, col) cells of ``grid``.
    """
    free = (~grid.occupied).tolist()
    rows, cols = grid.occupied.shape
    inflation_m = problem.inflation_m
    # The small extra reach only lists more boxes; it guards the cull against rounding.
    near = boxes_by_cell(grid, problem.box_array_m, inflation_m + 1e-6)
    boxes = problem.box_array_m.tolist()
    xs = grid.centres_m(np.column_stack([np.zeros(cols), np.arange(cols)]))[:, 0].tolist()   # by column
    ys = grid.centres_m(np.column_stack([np.arange(rows), np.zeros(rows)]))[:, 1].tolist()   # by row

    def los(p: Cell, q: Cell) -> bool:
        if not grid_line_of_sight(free, p, q):
            return False
        ids: set[int] = set()
        for r, c in line_cells(p, q):
            ids.update(near[r * cols + c])
        if not ids:
            return True
        ax, ay, bx, by = xs[p[1]], ys[p[0]], xs[q[1]], ys[q[0]]
        return all(segment_box_distance(ax, ay, bx, by, *boxes[k]) - inflation_m >= -tolerance_m for k in ids)

    return los


def exact_shortcut(problem: Problem, waypoints: np.ndarray, window: int = 32) -> np.ndarray:
    """Greedy line-of-sight shortcut: from each kept vertex jump to the farthest visible one.

    Visibility is :func:`segments_clear` (through the problem's
    :func:`clearance_buckets`, built once, when it has many obstacles), evaluated ``window`` vertices at a
    time in one NumPy call; while the last vertex of a window is still visible
    the next window is tried too, so a long straight run collapses to one
    segment.  Consecutive vertices are assumed visible (grid moves between free
    cells are), so this never fails.
    """
    pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    if len(pts) <= 2:
        return pts.copy()
    buckets = clearance_buckets(problem)
    kept = [0]
    i = 0
    last = len(pts) - 1
    while i < last:
        j = i + 1
        lo = i + 1
        while lo <= last:
            hi = min(lo + window, last + 1)
            visible = np.flatnonzero(segments_clear(problem, pts[i], pts[lo:hi], buckets=buckets))
            if visible.size:
                j = lo + int(visible[-1])
            if not visible.size or j != hi - 1:
                break
            lo = hi
        kept.append(j)
        i = j
    return pts[kept]

