"""The compiled A* (planners/_grid_search.c) expands the same cells as the Python reference.

Cells, cost (exactly) and expansion counts are compared on random grids and on
the Moving AI maps when they are present, for A*, Dijkstra and a weighted A*;
an unreachable goal is NoPathFound in both.
"""

import numpy as np
import pytest

from swarmnav.models.grid_map import benchmark_sets, read_map, read_scenarios
from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.grid_search import astar_cells, astar_cells_reference


def _same(occupied, start, goal, weight=1.0):
    fast = astar_cells(occupied, start, goal, heuristic_weight=weight)
    ref = astar_cells_reference(occupied, start, goal, heuristic_weight=weight)
    assert fast[0] == ref[0] and fast[1] == ref[1] and fast[2] == ref[2]
    return fast


@pytest.mark.parametrize("seed", range(10))
def test_compiled_astar_equals_the_reference_on_random_grids(seed):
    rng = np.random.default_rng(seed)
    rows, cols = int(rng.integers(2, 60)), int(rng.integers(2, 60))
    occupied = rng.random((rows, cols)) < [0.0, 0.1, 0.25, 0.35, 0.45][seed % 5]
    free = np.argwhere(~occupied)
    if len(free) < 2:
        pytest.skip("no two free cells")
    for _ in range(5):
        start, goal = (tuple(int(v) for v in free[i]) for i in rng.choice(len(free), 2))
        for weight in (1.0, 0.0, 1.7):
            try:
                _same(occupied, start, goal, weight)
            except NoPathFound:
                with pytest.raises(NoPathFound):
                    astar_cells_reference(occupied, start, goal, heuristic_weight=weight)


def test_compiled_astar_equals_the_reference_on_the_moving_ai_maps():
    sets = benchmark_sets()
    if not sets:
        pytest.skip("no Moving AI maps (../shared/benchmarks/movingai or SWARMNAV_MOVINGAI_DIR)")
    for map_path, scen_path in sets:
        occupied = read_map(map_path)
        scenarios = [s for s in read_scenarios(scen_path) if s.map_name.endswith(map_path.name)]
        for s in scenarios[:: max(1, len(scenarios) // 25)]:
            cells, cost, _ = _same(occupied, s.start_cell(), s.goal_cell())
            assert cost == pytest.approx(s.optimal_length, abs=1e-4)


def test_an_unreachable_goal_and_the_start_at_the_goal():
    occupied = np.zeros((5, 5), dtype=bool)
    occupied[:, 2] = True
    with pytest.raises(NoPathFound):
        astar_cells(occupied, (0, 0), (4, 4))
    assert _same(occupied, (1, 1), (1, 1)) == ([(1, 1)], 0.0, 1)


def test_the_kernel_refuses_masks_that_leave_the_grid():
    from swarmnav.planners._grid_search import astar

    offsets = np.array([-3, 3, -1, 1, -4, -2, 2, 4], dtype=np.int64)
    masks = np.full(9, 255, dtype=np.uint8)                       # every move legal, even off the edge
    with pytest.raises(ValueError, match="leaves the grid"):
        astar(masks, offsets, np.ones(8), 3, 0.4, 1.0, 0, 8)
    with pytest.raises(ValueError):
        astar(masks, offsets, np.ones(8), 4, 0.4, 1.0, 4, 8)       # 9 masks are no 4-wide grid


@pytest.mark.parametrize("snap", [False, True])
def test_pairwise_segment_box_distances_are_the_cross_tables_entries_bit_for_bit(snap):
    from swarmnav.models.geometry import segment_box_distances, segment_box_pair_distances

    rng = np.random.default_rng(5 + snap)
    for _ in range(200):
        s, b = int(rng.integers(1, 20)), int(rng.integers(1, 40))
        a, z = rng.uniform(0, 10, (s, 2)), rng.uniform(0, 10, (s, 2))
        lo = rng.uniform(0, 9, (b, 2))
        boxes = np.hstack([lo, lo + rng.uniform(0, 2, (b, 2))])
        if snap:  # grid-like: ends and edges on half metres, points, axis-parallel segments
            a, z, boxes = np.round(a * 2) / 2, np.round(z * 2) / 2, np.round(boxes * 2) / 2
            z[::3] = a[::3]
            z[1::4, 0] = a[1::4, 0]
        si, bi = np.nonzero(np.ones((s, b), dtype=bool))
        np.testing.assert_array_equal(segment_box_pair_distances(a[si], z[si], boxes[bi]),
                                      segment_box_distances(a, z, boxes)[si, bi])


@pytest.mark.parametrize("scenario_name", ["immas-env6-rows", "iaco-baffle", "restaurant-table-5"])
def test_the_shortcut_fan_test_decides_as_the_problems_segment_test(scenario_name):
    from swarmnav.models.scenario import load_scenario
    from swarmnav.planners.grid_shortcut import segments_clear
    from swarmnav.planners.problem import scenario_problem

    problem = scenario_problem(load_scenario(scenario_name))
    rng = np.random.default_rng(3)
    b = problem.bounds
    for _ in range(60):
        # Cell centres and cell corners: segments that graze box edges exactly at the inflation.
        pts = rng.uniform((b.x_min_m, b.y_min_m), (b.x_max_m, b.y_max_m), (33, 2))
        pts = np.round(pts / (problem.grid.cell_m / 2)) * (problem.grid.cell_m / 2)
        a, bs = pts[0], pts[1:]
        expected = problem.in_bounds(bs, 1e-9) & (problem.segment_clearances_m(a, bs, cull_beyond_m=0.0) >= -1e-9)
        np.testing.assert_array_equal(segments_clear(problem, a, bs), expected)
