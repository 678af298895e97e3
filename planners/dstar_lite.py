"""D* Lite (Koenig & Likhachev 2002), the incremental grid search, and its planner ``dstar_lite``.

It searches the shared grid graph (:mod:`planners.grid_graph`) backwards from the
goal, so that after cells change or the robot moves only the affected part of the
cost-to-goal field is repaired (:class:`DStarLite`).  The search runs compiled
(``planners/_dstar_lite.c``), the Python one of :mod:`planners.dstar_lite_reference` step for step.
``dstar_lite`` plans once from scratch through the common grid plumbing (:class:`planners.grid_search.GridPlanner`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.planners._dstar_lite import Search
from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.grid_graph import SQRT2, STEP_COSTS, Cell, check_cells, octile_cells
from swarmnav.planners.grid_search import GridPlanner

_MOVE_COSTS = np.array(STEP_COSTS, dtype=float)


class DStarLite:
    """D* Lite (Koenig & Likhachev 2002, optimised version) on an 8-connected grid, no corner cutting.

    The search runs backwards from the goal, so when cells change or the robot
    moves only the affected part of the cost-to-goal field is repaired:

    >>> planner = DStarLite(occupied, start, goal)      # doctest: +SKIP
    >>> cells = planner.plan()                          # doctest: +SKIP
    >>> planner.move_start(cells[3])                    # doctest: +SKIP
    >>> planner.update_cells({(10, 12): True})          # doctest: +SKIP
    >>> cells = planner.plan()                          # doctest: +SKIP

    Its loops are compiled (``planners/_dstar_lite.c``): the keys, expansions, g, rhs and paths of
    :class:`~planners.dstar_lite_reference.DStarLiteReference`, the same search in Python (~90 % of
    ``dstar_replan``'s time before, profiled).

    Optional cell penalties (a costmap): a move between cells u and v costs w (1 + (p_u + p_v) / 2), w its
    length in cells; symmetric, so the graph stays undirected, and >= w, so the octile heuristic stays
    admissible.  None: every move costs its length (the paper's grid).

    """

    def __init__(self, occupied: np.ndarray, start: Cell, goal: Cell, penalty: np.ndarray | None = None):
        occ = np.asarray(occupied, dtype=bool)
        check_cells(occ, start, goal)
        self.rows, self.cols = occ.shape
        self._occupied = occ.copy()
        self._free: list[list[bool]] | None = None  # see free
        pen = None if penalty is None else self._checked_penalty(penalty)
        self.start = start
        self.goal = goal
        self._last = start
        self.km = 0.0
        self._search = Search(np.ascontiguousarray(occ, dtype=np.uint8), self.rows, self.cols, self._index(start),
                              self._index(goal), SQRT2 - 1.0, _MOVE_COSTS, pen)

    def _index(self, cell: Cell) -> int:
        return cell[0] * self.cols + cell[1]

    @property
    def free(self) -> list[list[bool]]:
        """Per row, per column, whether the cell is free (as last set); rebuilt after a change, when read."""
        if self._free is None:
            self._free = (~self._occupied).tolist()
        return self._free

    @property
    def expansions(self) -> int:
        """Vertices expanded so far, over every (re)plan."""
        return self._search.expansions

    @property
    def g(self) -> list[float]:
        """Each vertex's g (flat index), a copy."""
        return self._search.values()[0]

    @property
    def rhs(self) -> list[float]:
        """Each vertex's rhs (flat index), a copy."""
        return self._search.values()[1]

    @property
    def masks(self) -> list[int]:
        """The legal-move mask of each cell (:func:`~planners.grid_graph.move_masks`), as kept by the search."""
        return list(self._search.masks())

    def compute_shortest_path(self) -> None:
        """Expand until the start is locally consistent (Fig. 4 of Koenig & Likhachev, optimised)."""
        self._search.compute(self._index(self.start), self.km)

    def path(self) -> list[Cell]:
        """Cells from the current start to the goal, following the smallest c + g."""
        s = self._index(self.start)
        if self._search.rhs_at(s) == np.inf:
            raise NoPathFound(f"goal cell {self.goal} is unreachable from start cell {self.start}")
        cells = self._search.path(s)
        if cells is None:
            raise NoPathFound("D* Lite could not follow its cost field to the goal")
        cols = self.cols
        return [divmod(v, cols) for v in cells]

    def plan(self) -> list[Cell]:
        """(Re)compute and return the path from the current start."""
        self.compute_shortest_path()
        return self.path()

    @property
    def cost_cells(self) -> float:
        """Cost-to-goal of the current start, in cells (inf when unreachable)."""
        return self._search.rhs_at(self._index(self.start))

    def move_start(self, cell: Cell) -> None:
        """The robot moved: shift the key modifier (the search tree is kept)."""
        self.km += octile_cells(cell[0] - self._last[0], cell[1] - self._last[1])
        self._last = cell
        self.start = cell

    def update_cells(self, changes: dict[Cell, bool]) -> None:
        """Set cells occupied (True) or free (False) and repair the affected vertices.

        A changed cell alters the moves into and out of it and the diagonal
        moves that pass beside it, all within its 3 x 3 block, so those
        vertices get their rhs recomputed.
        """
        occupied = self._occupied.copy()
        for (r, c), blocked in changes.items():
            if not (0 <= r < self.rows and 0 <= c < self.cols):
                raise ValueError(f"cell {(r, c)} is outside the grid")
            occupied[r, c] = bool(blocked)
        self.set_occupied(occupied)

    def set_occupied(self, occupied: np.ndarray) -> None:
        """:meth:`update_cells` with the whole grid: the cells that differ from the current ones are changed."""
        occ = np.asarray(occupied, dtype=bool)
        if occ.shape != (self.rows, self.cols):
            raise ValueError(f"occupied must be a {self.rows} x {self.cols} array")
        flipped = np.flatnonzero(occ != self._occupied)
        if not len(flipped):
            return
        self._occupied = occ.copy()
        self._free = None
        self._search.update_cells(flipped.astype(np.int64), occ.reshape(-1)[flipped].astype(np.uint8),
                                  self._index(self.start), self.km)

    def update_penalty(self, penalty: np.ndarray) -> int:
        """Replace the cell penalties (see the class docstring) and repair the vertices whose moves changed cost
        (each changed cell and its 8 neighbours); returns the number of changed cells."""
        return self._search.update_penalty(self._checked_penalty(penalty), self._index(self.start), self.km)

    def _checked_penalty(self, penalty: np.ndarray) -> np.ndarray:
        pen = np.asarray(penalty, dtype=float)
        if pen.shape != (self.rows, self.cols) or not np.all(np.isfinite(pen)) or np.any(pen < 0):
            raise ValueError(f"penalty must be a finite, non-negative {self.rows} x {self.cols} array")
        return np.ascontiguousarray(pen, dtype=np.float64).reshape(-1)


@dataclass
class DStarLitePlanner(GridPlanner):
    """D* Lite planned once from scratch (its incremental API is :class:`DStarLite`)."""

    name: ClassVar[str] = "dstar_lite"

    def search(self, problem, grid, start, goal):
        planner = DStarLite(grid.occupied, start, goal)
        cells = planner.plan()
        return cells, planner.cost_cells, planner.expansions, {}
