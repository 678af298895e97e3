"""The bucketed segment test against the problem's exact one, and the move masks against the
neighbour table, on seeded random inputs with the edge cases: segments exactly at the
inflated radius, degenerate segments (points), segments far outside every bucket."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from swarmnav.models.geometry import segment_box_distances, segment_disc_distances
from swarmnav.models.world import Box, Disc, Pose2D, Rect
from swarmnav.planners.grid_graph import move_masks, neighbour_table
from swarmnav.planners.grid_shortcut import clearance_buckets, exact_shortcut
from swarmnav.planners.obstacle_buckets import ClearanceBuckets, pair_box_distances, pair_disc_distances
from swarmnav.planners.problem import Problem


def random_problem(rng: np.random.Generator, discs: int, boxes: int, radii_m=(0.05, 0.2, 1.5)) -> Problem:
    centres = rng.uniform(0.0, 50.0, (discs, 2))
    radii = rng.choice(radii_m, discs)
    corners = rng.uniform(0.0, 48.0, (boxes, 2))
    sizes = rng.uniform(0.1, 3.0, (boxes, 2))
    return Problem(start=Pose2D(0.5, 0.5), goal=Pose2D(49.5, 49.5), bounds=Rect(0.0, 0.0, 50.0, 50.0),
                   obstacles=tuple(Disc(x, y, r) for (x, y), r in zip(centres, radii)),
                   boxes=tuple(Box(x, y, x + w, y + h) for (x, y), (w, h) in zip(corners, sizes)),
                   robot_radius_m=0.15, cell_m=0.5)


@pytest.mark.parametrize("seed", range(5))
def test_bucketed_segment_test_decides_as_the_exact_one(seed):
    rng = np.random.default_rng(seed)
    problem = random_problem(rng, discs=int(rng.integers(0, 400)), boxes=int(rng.integers(0, 60)))
    buckets = ClearanceBuckets.of(problem.disc_centres_m, problem.inflated_radii_m, problem.box_array_m,
                                  problem.inflation_m)
    a = rng.uniform(-5.0, 55.0, (600, 2))
    b = a + rng.normal(0.0, rng.choice([0.3, 5.0, 40.0]), (600, 2))
    b[:20] = a[:20]                                                   # points
    b[20:40] = a[20:40] + [200.0, 0.0]                                # leaving every bucket
    if problem.obstacles:                                             # tangent to a disc at its inflated radius
        k = rng.integers(0, len(problem.obstacles), 40)
        c, r = problem.disc_centres_m[k], problem.inflated_radii_m[k]
        a[40:80] = c + np.column_stack([-np.ones(40), r])
        b[40:80] = c + np.column_stack([np.ones(40), r])
    if problem.boxes:                                                 # along a box edge at the inflation
        k = rng.integers(0, len(problem.boxes), 40)
        box = problem.box_array_m[k]
        a[80:120] = np.column_stack([box[:, 0] - 1.0, box[:, 3] + problem.inflation_m])
        b[80:120] = np.column_stack([box[:, 2] + 1.0, box[:, 3] + problem.inflation_m])
    exact = problem.segment_clearances_m(a, b) >= -1e-9
    if buckets.discs is None and buckets.boxes is None:
        assert exact.all()
    np.testing.assert_array_equal(buckets.segments_clear(a, b, 1e-9), exact)


def test_pair_distances_equal_the_outer_ones():
    rng = np.random.default_rng(3)
    a, b = rng.uniform(0, 10, (300, 2)), rng.uniform(0, 10, (300, 2))
    b[:10] = a[:10]
    c = rng.uniform(0, 10, (300, 2))
    boxes = np.sort(rng.uniform(0, 10, (300, 2, 2)), axis=1).transpose(0, 2, 1).reshape(300, 4)[:, [0, 2, 1, 3]]
    outer_discs = segment_disc_distances(a, b, c)[np.arange(300), np.arange(300)]
    outer_boxes = segment_box_distances(a, b, boxes)[np.arange(300), np.arange(300)]
    np.testing.assert_allclose(pair_disc_distances(*a.T, *b.T, *c.T), outer_discs, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(pair_box_distances(*a.T, *b.T, boxes), outer_boxes, rtol=1e-12, atol=1e-12)


def test_the_shortcut_with_buckets_keeps_the_same_vertices():
    rng = np.random.default_rng(11)
    problem = replace(random_problem(rng, discs=400, boxes=0, radii_m=(0.1, 0.2)), cell_m=0.2)
    assert clearance_buckets(problem) is not None
    from swarmnav.planners.registry import make_planner
    path = make_planner("astar", {"shortcut": False}).plan(problem, rng)
    fast = exact_shortcut(problem, path.waypoints)
    assert problem.is_collision_free(fast)
    import swarmnav.planners.grid_shortcut as shortcut_module
    threshold = shortcut_module.BUCKETS_FROM_OBSTACLES
    try:
        shortcut_module.BUCKETS_FROM_OBSTACLES = 10**9
        slow = exact_shortcut(problem, path.waypoints)
    finally:
        shortcut_module.BUCKETS_FROM_OBSTACLES = threshold
    np.testing.assert_array_equal(fast, slow)
    assert len(fast) < len(path.waypoints)


@pytest.mark.parametrize("seed", range(10))
def test_move_masks_equal_the_neighbour_table(seed):
    rng = np.random.default_rng(seed)
    occupied = rng.random((int(rng.integers(1, 40)), int(rng.integers(1, 40)))) < rng.uniform(0.0, 0.6)
    table = neighbour_table(occupied)
    expected = ((table >= 0) * (1 << np.arange(8))).sum(axis=1)
    np.testing.assert_array_equal(move_masks(occupied), expected)
