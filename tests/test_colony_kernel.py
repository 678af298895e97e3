"""The compiled colony walk gives the NumPy reference's tours, lengths and draws, bit for bit.

Random occupancy grids (open, cluttered, walled-in starts), random cell and turn
weights, with and without backtracking, with and without a length cap; the
generator must be left in the same state (the same number of uniforms drawn).
"""

import numpy as np
import pytest

from swarmnav.models.world import OccupancyGrid
from swarmnav.planners.colony_walk import GridGraph, cosine_table, walk_colony, walk_colony_reference


def _graph(rng: np.random.Generator, rows: int, cols: int, density: float) -> GridGraph:
    occupied = rng.random((rows, cols)) < density
    return GridGraph.of(OccupancyGrid(occupied=occupied, cell_m=1.0, origin_m=(0.0, 0.0)))


def _assert_same(graph, start, goal, ants, cell_weights, turn_weights, max_steps, backtrack, max_length, seed):
    rng_ref, rng_fast = np.random.default_rng(seed), np.random.default_rng(seed)
    ref = walk_colony_reference(graph, start, goal, ants, cell_weights, turn_weights, rng_ref, max_steps,
                                backtrack=backtrack, max_length=max_length)
    fast = walk_colony(graph, start, goal, ants, cell_weights, turn_weights, rng_fast, max_steps,
                       backtrack=backtrack, max_length=max_length)
    np.testing.assert_array_equal(fast.reached, ref.reached)
    np.testing.assert_array_equal(fast.steps, ref.steps)
    np.testing.assert_array_equal(fast.length_cells, ref.length_cells)   # exact, not approximate
    np.testing.assert_array_equal(fast.turns, ref.turns)
    for a in range(ants):  # the valid part of each tour (the reference keeps a stuck ant's last garbage key)
        np.testing.assert_array_equal(fast.tour(a), ref.tour(a))
    assert rng_fast.random() == rng_ref.random()                       # the same draws were consumed
    return ref


@pytest.mark.parametrize("seed", range(12))
def test_compiled_walk_equals_the_reference_on_random_grids(seed):
    rng = np.random.default_rng(1000 + seed)
    rows, cols = int(rng.integers(3, 25)), int(rng.integers(3, 25))
    graph = _graph(rng, rows, cols, density=float(rng.choice([0.0, 0.15, 0.3, 0.45])))
    free = np.flatnonzero(~graph.grid.occupied.ravel())
    if free.size < 1:
        pytest.skip("no free cell")
    start, goal = (int(v) for v in rng.choice(free, 2))
    cell_weights = np.where(graph.table >= 0, rng.random((graph.size, 8)) ** 3, 0.0)
    turn_weights = None if seed % 3 == 0 else np.power(cosine_table() + 1.0, rng.uniform(0.5, 3.0))
    max_length = np.inf if seed % 2 else float(rng.uniform(1.0, rows + cols))
    _assert_same(graph, start, goal, int(rng.integers(1, 60)), cell_weights, turn_weights,
                 int(rng.integers(1, 200)), backtrack=seed % 4 != 1, max_length=max_length, seed=seed)


def test_compiled_walk_equals_the_reference_at_the_edges():
    rng = np.random.default_rng(7)
    graph = _graph(rng, 8, 8, 0.0)
    weights = np.where(graph.table >= 0, 1.0, 0.0)
    # Start at the goal: nobody walks, nothing is drawn.
    walk = _assert_same(graph, 5, 5, 10, weights, None, 50, True, np.inf, 0)
    assert walk.reached.all() and (walk.steps == 0).all()
    # A start walled in on every side: every ant is stuck at once, with and without backtracking.
    occupied = np.zeros((5, 5), dtype=bool)
    occupied[1:4, 1:4] = True
    occupied[2, 2] = False
    boxed = GridGraph.of(OccupancyGrid(occupied=occupied, cell_m=1.0, origin_m=(0.0, 0.0)))
    boxed_weights = np.where(boxed.table >= 0, 1.0, 0.0)
    for backtrack in (True, False):
        walk = _assert_same(boxed, boxed.index((2, 2)), 0, 6, boxed_weights, None, 40, backtrack, np.inf, 1)
        assert not walk.reached.any()
    # A step budget that ends mid-block, and a length cap every ant exceeds.
    _assert_same(graph, 0, 63, 30, weights, np.power(cosine_table() + 1.0, 2.0), 45, True, np.inf, 2)
    _assert_same(graph, 0, 63, 30, weights, None, 200, True, 3.0, 3)


def test_the_kernel_refuses_inputs_that_would_reach_outside_its_buffers():
    from swarmnav.planners._colony_walk import walk_block

    n, ants, width = 4, 2, 5

    def args(cell_weights=None, end_step=width - 1, keys_size=ants * width):
        return [np.zeros(n * 8) if cell_weights is None else cell_weights, np.ones(8),
                np.full(n * 8, -1, dtype=np.int64), np.ones(9), np.zeros((32, ants)),
                32, 0, end_step, n, 3, width, True, np.inf, np.zeros(keys_size, dtype=np.int64),
                np.ones(ants * (n + 1), dtype=bool), np.ones(ants, dtype=bool), np.zeros(ants, dtype=np.int64),
                np.zeros(ants, dtype=np.int64), np.zeros(ants), np.zeros(ants, dtype=np.int64), np.zeros(ants),
                np.zeros(ants, dtype=bool)]

    assert walk_block(*args()) == 0                    # every move illegal: both ants stuck at the start
    with pytest.raises(ValueError, match="keys"):
        walk_block(*args(keys_size=ants * width - 1))
    with pytest.raises(ValueError, match="no cell"):   # weight on moves to no cell: refused, not a crash
        walk_block(*args(cell_weights=np.ones(n * 8)))
    with pytest.raises(ValueError, match="width"):     # more steps than a tour stack holds
        walk_block(*args(end_step=width))
