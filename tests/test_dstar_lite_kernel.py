"""The compiled D* Lite (planners/_dstar_lite.c) is the Python reference step for step.

Random grids, with and without cell penalties, go through the same sequence of plans, robot moves, cell
changes and penalty changes in both; after every step g, rhs, the expansion count, the key modifier and the
path (or NoPathFound) must be equal exactly, not approximately.
"""

import numpy as np
import pytest

from swarmnav.planners.dstar_lite import DStarLite
from swarmnav.planners.dstar_lite_reference import DStarLiteReference
from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.grid_graph import move_masks


def _trace(cls, seed: int, penalised: bool, size: int = 30, steps: int = 20) -> list:
    rng = np.random.default_rng(seed)
    occ = rng.random((size, size)) < [0.1, 0.2, 0.3][seed % 3]
    start, goal = (0, 0), (size - 1, size - 1)
    occ[start] = occ[goal] = False
    penalty = rng.random(occ.shape) * 3 if penalised else None
    planner = cls(occ, start, goal, penalty=penalty)
    out = []
    for step in range(steps):
        try:
            cells = planner.plan()
        except NoPathFound as error:
            cells = str(error)
        out.append((cells, list(planner.g), list(planner.rhs), planner.expansions, planner.km, planner.cost_cells))
        if isinstance(cells, list) and len(cells) > 2:
            planner.move_start(cells[int(rng.integers(1, 4)) if len(cells) > 4 else 1])
        changes = {}
        for _ in range(int(rng.integers(1, [4, 60][step % 2]))):
            cell = (int(rng.integers(0, size)), int(rng.integers(0, size)))
            if cell not in (planner.start, goal):
                changes[cell] = bool(rng.random() < 0.5)
        planner.update_cells(changes)
        if penalised and step % 3 == 0:
            penalty = penalty.copy()
            penalty[int(rng.integers(0, size))] = np.round(rng.random(size) * 3, 1)  # ties among costs
            out.append(planner.update_penalty(penalty))
    return out


@pytest.mark.parametrize("penalised", [False, True])
@pytest.mark.parametrize("seed", range(6))
def test_compiled_dstar_lite_equals_the_reference(seed, penalised):
    assert _trace(DStarLite, seed, penalised) == _trace(DStarLiteReference, seed, penalised)


def test_the_masks_follow_the_changed_cells_and_a_bad_cell_or_penalty_is_refused():
    occ = np.zeros((6, 7), dtype=bool)
    planner = DStarLite(occ, (0, 0), (5, 6))
    occ[2, 3] = occ[4, 0] = True
    planner.update_cells({(2, 3): True, (4, 0): True, (0, 1): False})
    assert planner.masks == move_masks(occ).tolist()
    with pytest.raises(ValueError, match="outside"):
        planner.update_cells({(6, 0): True})
    with pytest.raises(ValueError, match="penalty"):
        planner.update_penalty(np.full((6, 7), np.nan))
    with pytest.raises(ValueError, match="penalty"):
        planner.update_penalty(np.zeros((7, 6)))


def test_the_repair_benchmark_compares_the_two_searches_on_the_same_sequence():
    from swarmnav.benchmarks.grid import bench_dstar_repairs

    result = bench_dstar_repairs(replans=6, size=30)
    assert result["replans"] == 6 and result["disagreements"] == 0
    assert result["ours_mean_s"] > 0 and result["reference_mean_s"] > 0
