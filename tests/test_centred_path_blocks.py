"""CentredPlanner.blocks on a new map rasterises only the discs that can reach the path: the same answer as the
whole grid (the version it replaced, kept here as the reference), on sensed-map-like discs around paths."""

from __future__ import annotations

import math

import numpy as np

from swarmnav.controllers.centred_path import CentredPlanner
from swarmnav.models.world import Box, Disc, Rect, rasterise
from swarmnav.planners.problem import Problem
from swarmnav.models.world import Pose2D


def blocks_reference(planner: CentredPlanner, problem: Problem, waypoints_m, skip_m: float) -> bool:
    """blocks() as it was: the whole map rasterised (cells()), then the polyline's cells read."""
    grid = rasterise(problem.bounds, problem.obstacles, problem.boxes, planner.block_m, problem.cell_m)
    pts = np.asarray(waypoints_m, dtype=float).reshape(-1, 2)
    if len(pts) < 2:
        return False
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


def problem_with(discs, boxes=()) -> Problem:
    return Problem(bounds=Rect(0.0, 0.0, 7.0, 16.0), start=Pose2D(1.0, 1.0, 0.0), goal=(6.0, 15.0),
                   obstacles=tuple(discs), boxes=tuple(boxes), robot_radius_m=0.215, clearance_m=0.05, cell_m=0.05)


def test_blocks_is_the_whole_grid_answer():
    rng = np.random.default_rng(81)
    planner = CentredPlanner(0.265, 10.0, 0.3)
    blocked = 0
    for trial in range(150):
        # a polyline across the arena; sensed cells (half-diagonal discs on the 5 cm lattice) near it
        pts = np.column_stack([rng.uniform(0.5, 6.5, 6), np.sort(rng.uniform(0.5, 15.5, 6))])
        t = rng.uniform(0, 1, int(rng.integers(1, 5)))
        seg = rng.integers(0, len(pts) - 1, len(t))
        on = pts[seg] + t[:, None] * (pts[seg + 1] - pts[seg])
        off = on + rng.normal(0.0, 0.6, on.shape)
        cells = np.floor(off / 0.05)
        centres = (cells + 0.5) * 0.05
        radii = np.full(len(centres), 0.05 * math.sqrt(0.5)) if rng.random() < 0.7 else rng.uniform(0, 0.1, len(t))
        discs = [Disc(float(x), float(y), float(r)) for (x, y), r in zip(centres.tolist(), radii.tolist())]
        boxes = [Box(3.0, 7.0, 3.5, 7.2)] if rng.random() < 0.2 else []
        problem = problem_with(discs, boxes)
        skip = float(rng.choice([0.0, 0.3]))
        want = blocks_reference(planner, problem, pts, skip)
        blocked += want
        assert CentredPlanner(0.265, 10.0, 0.3).blocks(problem, pts, skip) == want, trial
    assert 20 < blocked < 140


def test_blocks_with_discs_at_the_edge_of_the_path_reach():
    """Discs just within and beyond the grown radius of the cell of a point on the path, on either side: a
    bound without the point's half cell diagonal drops some that mark the path's cells."""
    rng = np.random.default_rng(82)
    planner = CentredPlanner(0.265, 10.0, 0.3)
    half_diagonal = 0.05 / math.sqrt(2.0)
    r = 0.05 * math.sqrt(0.5)
    differ = 0
    for trial in range(300):
        pts = np.array([[rng.uniform(1, 6), 0.6], [rng.uniform(1, 6), 15.0]])
        k = rng.uniform(0.1, 0.9)
        p = pts[0] + k * (pts[1] - pts[0])
        normal = np.array([-(pts[1] - pts[0])[1], (pts[1] - pts[0])[0]])
        normal /= np.hypot(*normal)
        # the disc centre off the line by about the grown radius plus up to two half diagonals
        d = r + 0.265 + half_diagonal + rng.uniform(0.0, 2.0) * half_diagonal
        centre = p + rng.choice([-1.0, 1.0]) * d * normal
        problem = problem_with([Disc(float(centre[0]), float(centre[1]), r)])
        want = blocks_reference(planner, problem, pts, 0.0)
        differ += want
        assert CentredPlanner(0.265, 10.0, 0.3).blocks(problem, pts, 0.0) == want, trial
    assert differ > 10
