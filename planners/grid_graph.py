"""The shared grid graph of every grid planner: moves, neighbour tables, and grid <-> metres.

All grid planners search the same graph: 8-connected with **no corner cutting**
(a diagonal move needs both orthogonal cells it passes to be free), the Moving AI
convention, so A* and Dijkstra reproduce the benchmark's optimal octile lengths.

* :data:`DIRECTIONS` and :data:`STEP_COSTS`: the 8 moves and their costs in cells;
* :func:`neighbour_table`: the legal moves of every cell as flat indices (the ant
  colonies'), and :func:`move_masks`: the same as one 8-bit mask per cell, the
  searches' (:data:`ADJACENCY`, cached by the grid's content), read through
  :func:`moves_by_mask`;
* :func:`grid_line_of_sight` and :func:`line_cells`: which cells a segment between
  two cell centres enters;
* :func:`grid_endpoints`, :func:`cells_to_waypoints`: from metres to cells and back.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from dataclasses import replace

import numpy as np

from swarmnav.models.scenario_limits import MAX_GRID_CELLS as MAX_SCENARIO_GRID_CELLS
from swarmnav.models.errors import ConfigError
from swarmnav.models.world import OccupancyGrid
from swarmnav.planners.errors import GoalBlocked, StartBlocked
from swarmnav.planners.problem import Problem

SQRT2 = math.sqrt(2.0)
INF = float("inf")
#: (d_row, d_col) of the 8 moves: 4 orthogonal first, then 4 diagonal.
DIRECTIONS = ((-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (-1, 1), (1, -1), (1, 1))
#: Cost in cells of each move of :data:`DIRECTIONS`.
STEP_COSTS = (1.0, 1.0, 1.0, 1.0, SQRT2, SQRT2, SQRT2, SQRT2)

Cell = tuple[int, int]
#: Most cells a grid planner's grid may have (a 100 x 100 m arena at 0.05 m is 4 M);
#: the neighbour table alone takes 64 bytes a cell.
MAX_GRID_CELLS = 5_000_000  # the cells a grid planner searches (README Limits: planner grid cells)


def grid_problem(problem: Problem, cell_m: float | None, max_cells: int = MAX_GRID_CELLS) -> Problem:
    """``problem`` at a planner's own ``cell_m`` (None: the problem's), its grid size checked up front.

    A problem with a fixed grid (a map) keeps it.

    Raises:
        ConfigError: the grid would have more than ``max_cells`` cells; names the
            planner's ``cell_m`` when it set the resolution, else the scenario's ``sim.cell_m``.
    """
    field = "sim.cell_m"
    if cell_m is not None and cell_m != problem.cell_m and problem.grid_override is None:
        problem = replace(problem, cell_m=cell_m)
        field = "planner.params.cell_m"
    if problem.grid_override is None:
        b = problem.bounds
        cols = max(1, math.ceil(b.width_m / problem.cell_m - 1e-9))
        rows = max(1, math.ceil(b.height_m / problem.cell_m - 1e-9))
        if rows * cols > max_cells:
            raise ConfigError(field, f"a {b.width_m:g} x {b.height_m:g} m workspace at {problem.cell_m:g} m a cell "
                              f"needs {rows * cols:,} grid cells, more than the {max_cells:,} a grid planner searches "
                              f"(a scenario itself may hold up to {MAX_SCENARIO_GRID_CELLS:,}: give a coarser cell_m)")
    return problem


def octile_cells(dr: int, dc: int) -> float:
    """Octile distance in cells between two cells ``dr`` rows and ``dc`` columns apart."""
    dr, dc = abs(dr), abs(dc)
    return (SQRT2 - 1.0) * min(dr, dc) + max(dr, dc)


def neighbour_table(occupied: np.ndarray) -> np.ndarray:
    """Flat index of each cell's 8 neighbours in :data:`DIRECTIONS` order, -1 where a move is illegal.

    A move is legal when both cells are free and, for a diagonal, both
    orthogonal cells it passes are free (no corner cutting).  Occupied cells
    get no neighbours.

    Args:
        occupied: (rows, cols) bool.

    Returns:
        (rows * cols, 8) int64.
    """
    occ = np.asarray(occupied, dtype=bool)
    rows, cols = occ.shape
    free = ~occ
    pad = np.zeros((rows + 2, cols + 2), dtype=bool)
    pad[1:-1, 1:-1] = free
    index = np.arange(rows * cols, dtype=np.int64).reshape(rows, cols)
    table = np.full((rows, cols, 8), -1, dtype=np.int64)
    for k, (dr, dc) in enumerate(DIRECTIONS):
        ok = free & pad[1 + dr:rows + 1 + dr, 1 + dc:cols + 1 + dc]
        if dr and dc:
            ok &= pad[1 + dr:rows + 1 + dr, 1:cols + 1] & pad[1:rows + 1, 1 + dc:cols + 1 + dc]
        table[..., k] = np.where(ok, index + dr * cols + dc, -1)
    return table.reshape(rows * cols, 8)


def moves_by_mask(cols: int) -> tuple[tuple[tuple[int, float], ...], ...]:
    """For each 8-bit mask of legal moves, the (flat index offset, cost) of those moves on a ``cols``-wide grid.

    Bit k of a mask is move k of :data:`DIRECTIONS`; 256 tuples, built once per width.
    """
    hit = _MOVES_BY_MASK.get(cols)
    if hit is None:
        offsets = [dr * cols + dc for dr, dc in DIRECTIONS]
        hit = tuple(tuple((offsets[k], STEP_COSTS[k]) for k in range(8) if mask >> k & 1) for mask in range(256))
        _MOVES_BY_MASK[cols] = hit
    return hit


_MOVES_BY_MASK: dict[int, tuple] = {}


def move_masks(occupied: np.ndarray) -> np.ndarray:
    """(rows * cols,) uint8: bit k set where move k of :data:`DIRECTIONS` is legal from the cell
    (the same rule as :func:`neighbour_table`, without building the (N, 8) table)."""
    occ = np.asarray(occupied, dtype=bool)
    rows, cols = occ.shape
    free = ~occ
    pad = np.zeros((rows + 2, cols + 2), dtype=bool)
    pad[1:-1, 1:-1] = free
    masks = np.zeros((rows, cols), dtype=np.uint8)
    for k, (dr, dc) in enumerate(DIRECTIONS):
        ok = free & pad[1 + dr:rows + 1 + dr, 1 + dc:cols + 1 + dc]
        if dr and dc:
            ok &= pad[1 + dr:rows + 1 + dr, 1:cols + 1] & pad[1:rows + 1, 1 + dc:cols + 1 + dc]
        masks |= ok.view(np.uint8) << k
    return masks.reshape(-1)


class _AdjacencyCache:
    """Legal-move masks of recently seen grids, keyed by content.

    A search reads the moves out of cell ``u`` as ``moves_by_mask(cols)[masks[u]]``,
    offsets to add to ``u``: building that for a new grid is a few vectorised
    boolean operations (:func:`move_masks`) and a list of N small ints, not N
    Python lists.
    """

    def __init__(self, size: int = 16):
        self.size = size
        self.entries: OrderedDict[tuple, list[int]] = OrderedDict()
        self.arrays: OrderedDict[tuple, np.ndarray] = OrderedDict()  # the same masks as uint8, for C

    def clear(self) -> None:
        self.entries.clear()
        self.arrays.clear()

    def get_array(self, occupied: np.ndarray) -> np.ndarray:
        """The legal-move mask of every cell, as a (rows * cols,) uint8 array (read-only)."""
        occ = np.ascontiguousarray(occupied, dtype=bool)
        key = (occ.shape, occ.tobytes())
        hit = self.arrays.get(key)
        if hit is not None:
            self.arrays.move_to_end(key)
            return hit
        masks = move_masks(occ)
        masks.flags.writeable = False
        self.arrays[key] = masks
        if len(self.arrays) > self.size:
            self.arrays.popitem(last=False)
        return masks

    def get(self, occupied: np.ndarray) -> list[int]:
        """The legal-move mask of every cell, as a list."""
        occ = np.ascontiguousarray(occupied, dtype=bool)
        key = (occ.shape, occ.tobytes())
        hit = self.entries.get(key)
        if hit is not None:
            self.entries.move_to_end(key)
            return hit
        masks = move_masks(occ).tolist()
        self.entries[key] = masks
        if len(self.entries) > self.size:
            self.entries.popitem(last=False)
        return masks


ADJACENCY = _AdjacencyCache()

def check_cells(occupied: np.ndarray, start: Cell, goal: Cell) -> None:
    """Raise StartBlocked / GoalBlocked when an endpoint cell is outside the grid or occupied."""
    rows, cols = occupied.shape
    for cell, error, label in ((start, StartBlocked, "start"), (goal, GoalBlocked, "goal")):
        if not (0 <= cell[0] < rows and 0 <= cell[1] < cols):
            raise error(f"{label} cell {cell} is outside the {rows} x {cols} grid")
        if occupied[cell]:
            raise error(f"{label} cell {cell} is occupied")



def grid_line_of_sight(free: list[list[bool]], a: Cell, b: Cell) -> bool:
    """Whether the segment between the centres of cells ``a`` and ``b`` crosses only free cells.

    Every cell the segment enters is tested (a supercover walk in integer
    arithmetic); where it passes exactly through a grid corner both cells
    beside the corner must be free, so it never squeezes between two blocked
    cells that touch diagonally.
    """
    r, c = a
    dr, dc = b[0] - r, b[1] - c
    sr = 1 if dr > 0 else -1
    sc = 1 if dc > 0 else -1
    adr, adc = abs(dr), abs(dc)
    ix = iy = 0
    if not free[r][c]:
        return False
    while ix < adc or iy < adr:
        across = (2 * ix + 1) * adr      # compares the next column crossing t=(ix+.5)/adc
        down = (2 * iy + 1) * adc        # with the next row crossing t=(iy+.5)/adr
        if across < down:
            c += sc
            ix += 1
        elif across > down:
            r += sr
            iy += 1
        else:
            if not (free[r][c + sc] and free[r + sr][c]):
                return False
            r += sr
            c += sc
            ix += 1
            iy += 1
        if not free[r][c]:
            return False
    return True


def line_cells(a: Cell, b: Cell) -> list[Cell]:
    """Cells the segment between the centres of ``a`` and ``b`` enters, in order (a supercover).

    Where the segment passes exactly through a grid corner the two cells beside
    the corner are listed too.  Cells may lie outside the grid if ``a`` or ``b`` do.
    """
    r, c = a
    dr, dc = b[0] - r, b[1] - c
    sr = 1 if dr > 0 else -1
    sc = 1 if dc > 0 else -1
    adr, adc = abs(dr), abs(dc)
    ix = iy = 0
    out = [(r, c)]
    while ix < adc or iy < adr:
        across = (2 * ix + 1) * adr
        down = (2 * iy + 1) * adc
        if across < down:
            c += sc
            ix += 1
        elif across > down:
            r += sr
            iy += 1
        else:
            out.append((r, c + sc))
            out.append((r + sr, c))
            r += sr
            c += sc
            ix += 1
            iy += 1
        out.append((r, c))
    return out


def grid_endpoints(problem: Problem, grid: OccupancyGrid) -> tuple[Cell, Cell]:
    """Start and goal cells, checked free on the inflated grid."""
    start = grid.cell_of(problem.start.x_m, problem.start.y_m)
    goal = grid.cell_of(problem.goal.x_m, problem.goal.y_m)
    if grid.occupied[start]:
        raise StartBlocked(f"start cell {start} is occupied on the inflated grid")
    if grid.occupied[goal]:
        raise GoalBlocked(f"goal cell {goal} is occupied on the inflated grid")
    return start, goal


def cells_to_waypoints(problem: Problem, grid: OccupancyGrid, cells: list[Cell]) -> np.ndarray:
    """Cell centres in metres, with the exact start and goal in place of their cells' centres."""
    if len(cells) <= 1:
        return np.vstack([problem.start.xy, problem.goal.xy])
    centres = grid.centres_m(np.array(cells))
    return np.vstack([problem.start.xy, centres[1:-1], problem.goal.xy])


def count_bends(cells: list[Cell] | np.ndarray) -> int:
    """Number of direction changes along a cell path."""
    arr = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    if len(arr) < 3:
        return 0
    steps = np.diff(arr, axis=0)
    return int(np.count_nonzero(np.any(steps[1:] != steps[:-1], axis=1)))



def cell_clearance_m(grid: OccupancyGrid) -> np.ndarray:
    """(rows, cols) Euclidean distance in metres from each cell centre to the nearest occupied cell centre
    (of the inflated grid): the "wide free space" Hasan et al. (2023) seek, as one number per cell."""
    from scipy import ndimage  # SciPy only where a clearance is asked for
    return ndimage.distance_transform_edt(~grid.occupied) * grid.cell_m
