"""D* Lite (Koenig & Likhachev 2002), the incremental grid search, and its planner ``dstar_lite``.

It searches the shared grid graph (:mod:`planners.grid_graph`) backwards from the
goal, so that after cells change or the robot moves only the affected part of the
cost-to-goal field is repaired (:class:`DStarLite`).  ``dstar_lite`` plans once
from scratch through the common grid plumbing (:class:`planners.grid_search.GridPlanner`).
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass
from typing import ClassVar, Iterable

import numpy as np

from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.grid_graph import DIRECTIONS, INF, STEP_COSTS, Cell, check_cells, octile_cells
from swarmnav.planners.grid_search import GridPlanner


class DStarLite:
    """D* Lite (Koenig & Likhachev 2002, optimised version) on an 8-connected grid, no corner cutting.

    The search runs backwards from the goal, so when cells change or the robot
    moves only the affected part of the cost-to-goal field is repaired:

    >>> planner = DStarLite(occupied, start, goal)      # doctest: +SKIP
    >>> cells = planner.plan()                          # doctest: +SKIP
    >>> planner.move_start(cells[3])                    # doctest: +SKIP
    >>> planner.update_cells({(10, 12): True})          # doctest: +SKIP
    >>> cells = planner.plan()                          # doctest: +SKIP

    Attributes:
        expansions: vertices expanded so far, over every (re)plan.
    """

    def __init__(self, occupied: np.ndarray, start: Cell, goal: Cell, penalty: np.ndarray | None = None):
        occ = np.asarray(occupied, dtype=bool)
        check_cells(occ, start, goal)
        self.rows, self.cols = occ.shape
        self.free = (~occ).tolist()
        # Optional cell penalties (a costmap): a move between cells u and v costs w (1 + (p_u + p_v) / 2),
        # w its length in cells; symmetric, so the graph stays undirected, and >= w, so the octile
        # heuristic stays admissible.  None: every move costs its length (the paper's grid).
        self.penalty: list[float] | None = None
        if penalty is not None:
            self.penalty = self._checked_penalty(penalty)
        n = self.rows * self.cols
        self.g = [INF] * n
        self.rhs = [INF] * n
        self.start = start
        self.goal = goal
        self._last = start
        self.km = 0.0
        self.heap: list[tuple[float, float, int]] = []
        self.open: dict[int, tuple[float, float]] = {}
        self.expansions = 0
        t = self._index(goal)
        self.rhs[t] = 0.0
        self._insert(t, self._key(t))

    # -- graph ---------------------------------------------------------------
    def _index(self, cell: Cell) -> int:
        return cell[0] * self.cols + cell[1]

    def _h(self, v: int) -> float:
        vr, vc = divmod(v, self.cols)
        return octile_cells(vr - self.start[0], vc - self.start[1])

    def neighbours(self, v: int) -> Iterable[tuple[int, float]]:
        """Legal moves out of (and, the graph being undirected, into) ``v`` with their costs."""
        r, c = divmod(v, self.cols)
        free = self.free
        if not free[r][c]:
            return
        rows, cols = self.rows, self.cols
        pen = self.penalty
        for (dr, dc), w in zip(DIRECTIONS, STEP_COSTS):
            nr, nc = r + dr, c + dc
            if 0 <= nr < rows and 0 <= nc < cols and free[nr][nc]:
                if dr and dc and not (free[r][nc] and free[nr][c]):
                    continue
                if pen is None:
                    yield nr * cols + nc, w
                else:
                    yield nr * cols + nc, w * (1.0 + 0.5 * (pen[v] + pen[nr * cols + nc]))

    # -- queue ---------------------------------------------------------------
    def _key(self, v: int) -> tuple[float, float]:
        m = min(self.g[v], self.rhs[v])
        return (m + self._h(v) + self.km, m)

    def _insert(self, v: int, key: tuple[float, float]) -> None:
        self.open[v] = key
        heapq.heappush(self.heap, (key[0], key[1], v))

    def _top(self) -> tuple[tuple[float, float], int]:
        while self.heap:
            k1, k2, v = self.heap[0]
            if self.open.get(v) == (k1, k2):
                return (k1, k2), v
            heapq.heappop(self.heap)
        return (INF, INF), -1

    def _update_vertex(self, v: int) -> None:
        inconsistent = self.g[v] != self.rhs[v]
        if inconsistent:
            self._insert(v, self._key(v))
        elif v in self.open:
            del self.open[v]

    def _recompute_rhs(self, v: int) -> None:
        if v == self._index(self.goal):
            return
        best = INF
        g = self.g
        for s, w in self.neighbours(v):
            if w + g[s] < best:
                best = w + g[s]
        self.rhs[v] = best

    def compute_shortest_path(self) -> None:
        """Expand until the start is locally consistent (Fig. 4 of Koenig & Likhachev, optimised)."""
        s = self._index(self.start)
        g, rhs = self.g, self.rhs
        while True:
            k_old, u = self._top()
            if u < 0:
                break
            # Ties (common on grids with the octile heuristic) are expanded too: a vertex whose
            # key equals the start's may still lie on the start's path with a stale g.
            ks = self._key(s)
            if not (k_old < (ks[0] + 1e-9, ks[1] + 1e-9) or rhs[s] != g[s]):
                break
            k_new = self._key(u)
            self.expansions += 1
            if k_old < k_new:
                self._insert(u, k_new)
            elif g[u] > rhs[u]:
                g[u] = rhs[u]
                del self.open[u]
                heapq.heappop(self.heap)
                for p, w in self.neighbours(u):
                    if p != self._index(self.goal) and rhs[p] > w + g[u]:
                        rhs[p] = w + g[u]
                    self._update_vertex(p)
            else:
                g_old = g[u]
                g[u] = INF
                goal = self._index(self.goal)
                for p, w in list(self.neighbours(u)) + [(u, 0.0)]:
                    if p != goal and (p == u or rhs[p] == w + g_old):
                        self._recompute_rhs(p)
                    self._update_vertex(p)

    def path(self) -> list[Cell]:
        """Cells from the current start to the goal, following the smallest c + g."""
        s = self._index(self.start)
        t = self._index(self.goal)
        if self.rhs[s] == INF:
            raise NoPathFound(f"goal cell {self.goal} is unreachable from start cell {self.start}")
        cells = [self.start]
        cur = s
        limit = self.rows * self.cols
        while cur != t:
            best, nxt = INF, -1
            for v, w in self.neighbours(cur):
                if w + self.g[v] < best:
                    best, nxt = w + self.g[v], v
            if nxt < 0 or len(cells) > limit:
                raise NoPathFound("D* Lite could not follow its cost field to the goal")
            cur = nxt
            cells.append(divmod(cur, self.cols))
        return cells

    def plan(self) -> list[Cell]:
        """(Re)compute and return the path from the current start."""
        self.compute_shortest_path()
        return self.path()

    @property
    def cost_cells(self) -> float:
        """Cost-to-goal of the current start, in cells (inf when unreachable)."""
        return self.rhs[self._index(self.start)]

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
        touched: set[int] = set()
        for (r, c), occupied in changes.items():
            if not (0 <= r < self.rows and 0 <= c < self.cols):
                raise ValueError(f"cell {(r, c)} is outside the grid")
            if self.free[r][c] == (not occupied):
                continue
            self.free[r][c] = not occupied
            self._add_block(touched, r, c)
        self._repair(touched)

    def update_penalty(self, penalty: np.ndarray) -> int:
        """Replace the cell penalties (see ``__init__``) and repair the vertices whose moves changed cost
        (each changed cell and its 8 neighbours); returns the number of changed cells."""
        new = self._checked_penalty(penalty)
        old = self.penalty if self.penalty is not None else [0.0] * len(new)
        self.penalty = new
        changed = np.flatnonzero(np.asarray(new) != np.asarray(old))
        touched: set[int] = set()
        for v in changed.tolist():
            self._add_block(touched, *divmod(v, self.cols))
        self._repair(touched)
        return len(changed)

    def _add_block(self, touched: set[int], r: int, c: int) -> None:
        """Cell (r, c) and its in-grid 8 neighbours into ``touched``: the vertices whose moves it changes."""
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                nr, nc = r + dr, c + dc
                if 0 <= nr < self.rows and 0 <= nc < self.cols:
                    touched.add(nr * self.cols + nc)

    def _checked_penalty(self, penalty: np.ndarray) -> list[float]:
        pen = np.asarray(penalty, dtype=float)
        if pen.shape != (self.rows, self.cols) or not np.all(np.isfinite(pen)) or np.any(pen < 0):
            raise ValueError(f"penalty must be a finite, non-negative {self.rows} x {self.cols} array")
        return pen.reshape(-1).tolist()

    def _repair(self, touched: set[int]) -> None:
        for v in sorted(touched):
            if not self.free[v // self.cols][v % self.cols]:
                self.g[v] = INF
            self._recompute_rhs(v)
            self._update_vertex(v)



@dataclass
class DStarLitePlanner(GridPlanner):
    """D* Lite planned once from scratch (its incremental API is :class:`DStarLite`)."""

    name: ClassVar[str] = "dstar_lite"

    def search(self, problem, grid, start, goal):
        planner = DStarLite(grid.occupied, start, goal)
        cells = planner.plan()
        return cells, planner.cost_cells, planner.expansions, {}
