"""D* Lite (Koenig & Likhachev 2002) in Python: the reference the compiled search of :mod:`planners.dstar_lite`
(``planners/_dstar_lite.c``) is checked against, step for step (tests/test_dstar_lite_kernel.py).

The compiled :class:`~planners.dstar_lite.DStarLite` keeps the same g, rhs, keys, heap order and lazy deletion, and
does the same double operations in the same order, so its expansions, costs and paths are this class's.
"""

from __future__ import annotations

import heapq

import numpy as np

from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.grid_graph import INF, Cell, check_cells, move_masks, moves_by_mask, octile_cells


_BLOCK_ROWS = np.repeat(np.arange(-1, 2), 3)  # the 3 x 3 block's row and column offsets
_BLOCK_COLS = np.tile(np.arange(-1, 2), 3)


class DStarLiteReference:
    """D* Lite (Koenig & Likhachev 2002, optimised version) on an 8-connected grid, no corner cutting.

    The search runs backwards from the goal, so when cells change or the robot
    moves only the affected part of the cost-to-goal field is repaired:

    >>> planner = DStarLiteReference(occupied, start, goal)      # doctest: +SKIP
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
        self._occupied = occ.copy()
        # Legal moves out of each cell as a bit mask (planners.grid_graph.move_masks: the same rule as the
        # paper's grid, no corner cutting), read through moves_by_mask; refreshed when cells change.
        self._masks: list[int] = move_masks(occ).tolist()
        self._by_mask = moves_by_mask(self.cols)
        # Optional cell penalties (a costmap): a move between cells u and v costs w (1 + (p_u + p_v) / 2),
        # w its length in cells; symmetric, so the graph stays undirected, and >= w, so the octile
        # heuristic stays admissible.  None: every move costs its length (the paper's grid).
        self.penalty: list[float] | None = None
        if penalty is not None:
            self.penalty = self._checked_penalty(penalty)
        n = self.rows * self.cols
        self.g = [INF] * n
        self._moves: list[list[tuple[int, float]] | None] = [None] * n  # see neighbours
        self._h_start: Cell | None = None  # the start self._h_all is for (see _heuristic)
        self._h_all = _OctileFrom(start, self.cols)
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

    def neighbours(self, v: int) -> list[tuple[int, float]]:
        """Legal moves out of (and, the graph being undirected, into) ``v`` with their costs, in
        :data:`DIRECTIONS` order.  They depend on the cells of ``v``'s 3 x 3 block (and their penalties) only,
        so each vertex's list is kept until a change in that block (:meth:`_repair`) drops it."""
        moves = self._moves[v]
        if moves is None:
            moves = self._moves[v] = self._legal_moves(v)
        return moves

    def _legal_moves(self, v: int) -> list[tuple[int, float]]:
        pen, moves = self.penalty, self._by_mask[self._masks[v]]
        if pen is None:
            return [(v + offset, w) for offset, w in moves]
        return [(v + offset, w * (1.0 + 0.5 * (pen[v] + pen[v + offset]))) for offset, w in moves]

    # -- queue ---------------------------------------------------------------
    def _key(self, v: int) -> tuple[float, float]:
        m = min(self.g[v], self.rhs[v])
        return (m + self._h(v) + self.km, m)

    def _insert(self, v: int, key: tuple[float, float]) -> None:
        self.open[v] = key
        heapq.heappush(self.heap, (key[0], key[1], v))

    def compute_shortest_path(self) -> None:
        """Expand until the start is locally consistent (Fig. 4 of Koenig & Likhachev, optimised).

        The paper's CalculateKey, TopKey (lazy deletion: a heap entry counts while it is the vertex's key in
        ``open``), UpdateVertex and the rhs minimum are written out inline, with the heuristic kept per
        start (this loop is nearly all of ``dstar_replan``'s time; inline, 1.5-2x faster than as methods,
        measured): the same double operations in the same order, so the same keys, expansions and paths."""
        s = self._index(self.start)
        goal = self._index(self.goal)
        g, rhs, heap, open_, km = self.g, self.rhs, self.heap, self.open, self.km
        h = self._heuristic()
        moves = self._moves
        push, pop = heapq.heappush, heapq.heappop
        while True:
            while heap:  # TopKey
                k1, k2, u = heap[0]
                if open_.get(u) == (k1, k2):
                    break
                pop(heap)
            else:
                break
            k_old = (k1, k2)
            # Ties (common on grids with the octile heuristic) are expanded too: a vertex whose
            # key equals the start's may still lie on the start's path with a stale g.
            m = g[s] if g[s] < rhs[s] else rhs[s]
            if not (k_old < (m + h[s] + km + 1e-9, m + 1e-9) or rhs[s] != g[s]):
                break
            m = g[u] if g[u] < rhs[u] else rhs[u]
            k_new = (m + h[u] + km, m)  # CalculateKey
            self.expansions += 1
            if k_old < k_new:
                open_[u] = k_new
                push(heap, (k_new[0], m, u))
            elif g[u] > rhs[u]:
                g_u = g[u] = rhs[u]
                del open_[u]
                pop(heap)
                for p, w in (moves[u] if moves[u] is not None else self.neighbours(u)):
                    if p != goal and rhs[p] > w + g_u:
                        rhs[p] = w + g_u
                    if g[p] != rhs[p]:  # UpdateVertex
                        m = g[p] if g[p] < rhs[p] else rhs[p]
                        k1 = m + h[p] + km
                        open_[p] = (k1, m)
                        push(heap, (k1, m, p))
                    elif p in open_:
                        del open_[p]
            else:
                g_old = g[u]
                g[u] = INF
                for p, w in (moves[u] if moves[u] is not None else self.neighbours(u)) + [(u, 0.0)]:
                    if p != goal and (p == u or rhs[p] == w + g_old):
                        best = INF  # rhs = min over the moves of c + g
                        for q, wq in (moves[p] if moves[p] is not None else self.neighbours(p)):
                            if wq + g[q] < best:
                                best = wq + g[q]
                        rhs[p] = best
                    if g[p] != rhs[p]:  # UpdateVertex
                        m = g[p] if g[p] < rhs[p] else rhs[p]
                        k1 = m + h[p] + km
                        open_[p] = (k1, m)
                        push(heap, (k1, m, p))
                    elif p in open_:
                        del open_[p]

    def _heuristic(self) -> "_OctileFrom":
        """:meth:`_h` of the vertices for the current start, each computed on first use and kept while the start
        stays (a vertex's key is computed many times per plan)."""
        if self._h_start != self.start:
            self._h_all = _OctileFrom(self.start, self.cols)
            self._h_start = self.start
        return self._h_all

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
        flipped: list[int] = []
        for (r, c), occupied in changes.items():
            if not (0 <= r < self.rows and 0 <= c < self.cols):
                raise ValueError(f"cell {(r, c)} is outside the grid")
            if self.free[r][c] == (not occupied):
                continue
            self.free[r][c] = not occupied
            self._occupied[r, c] = occupied
            flipped.append(r * self.cols + c)
        if flipped:
            self._refresh_masks(flipped)
        self._repair(self._blocks(flipped))

    def _refresh_masks(self, flipped: list[int]) -> None:
        """Recompute the move masks of the cells within one of a flipped cell (a mask depends on its cell's 3 x 3
        block), over the flipped cells' bounding box grown by two cells."""
        r, c = np.divmod(np.asarray(flipped, dtype=np.int64), self.cols)
        r0, r1 = max(int(r.min()) - 2, 0), min(int(r.max()) + 3, self.rows)
        c0, c1 = max(int(c.min()) - 2, 0), min(int(c.max()) + 3, self.cols)
        window = move_masks(self._occupied[r0:r1, c0:c1]).reshape(r1 - r0, c1 - c0)
        # The window's outer ring sees "blocked" beyond it; only cells within one of a flipped cell are written.
        w0, w1 = max(int(r.min()) - 1, 0), min(int(r.max()) + 2, self.rows)
        v0, v1 = max(int(c.min()) - 1, 0), min(int(c.max()) + 2, self.cols)
        masks, cols = self._masks, self.cols
        for row in range(w0, w1):
            masks[row * cols + v0:row * cols + v1] = window[row - r0, v0 - c0:v1 - c0].tolist()

    def update_penalty(self, penalty: np.ndarray) -> int:
        """Replace the cell penalties (see ``__init__``) and repair the vertices whose moves changed cost
        (each changed cell and its 8 neighbours); returns the number of changed cells."""
        new = self._checked_penalty(penalty)
        old = self.penalty if self.penalty is not None else [0.0] * len(new)
        self.penalty = new
        changed = np.flatnonzero(np.asarray(new) != np.asarray(old))
        self._repair(self._blocks(changed))
        return len(changed)

    def _blocks(self, cells: "list[int] | np.ndarray") -> set[int]:
        """The changed cells (flat indices) and their in-grid 8 neighbours: the vertices whose moves they change."""
        r, c = np.divmod(np.asarray(cells, dtype=np.int64), self.cols)
        rr = (r[:, None] + _BLOCK_ROWS).ravel()
        cc = (c[:, None] + _BLOCK_COLS).ravel()
        inside = (rr >= 0) & (rr < self.rows) & (cc >= 0) & (cc < self.cols)
        return set((rr[inside] * self.cols + cc[inside]).tolist())

    def _checked_penalty(self, penalty: np.ndarray) -> list[float]:
        pen = np.asarray(penalty, dtype=float)
        if pen.shape != (self.rows, self.cols) or not np.all(np.isfinite(pen)) or np.any(pen < 0):
            raise ValueError(f"penalty must be a finite, non-negative {self.rows} x {self.cols} array")
        return pen.reshape(-1).tolist()

    def _repair(self, touched: set[int]) -> None:
        """Recompute the rhs of the ``touched`` vertices (the minimum over their moves of c + g) and requeue
        the inconsistent ones (UpdateVertex), written out as in :meth:`compute_shortest_path`."""
        moves, g, rhs, heap, open_, km = self._moves, self.g, self.rhs, self.heap, self.open, self.km
        for v in touched:  # their moves changed (see neighbours)
            moves[v] = None
        if not touched:
            return
        h = self._heuristic()
        goal = self._index(self.goal)
        cols, free, push = self.cols, self.free, heapq.heappush
        for v in sorted(touched):
            if not free[v // cols][v % cols]:
                g[v] = INF
            if v != goal:
                best = INF
                for q, w in self.neighbours(v):
                    if w + g[q] < best:
                        best = w + g[q]
                rhs[v] = best
            if g[v] != rhs[v]:
                m = g[v] if g[v] < rhs[v] else rhs[v]
                k1 = m + h[v] + km
                open_[v] = (k1, m)
                push(heap, (k1, m, v))
            elif v in open_:
                del open_[v]


class _OctileFrom(dict):
    """Vertex -> its octile distance in cells from one start (:func:`~planners.grid_graph.octile_cells`), computed
    on first use."""

    def __init__(self, start: Cell, cols: int):
        super().__init__()
        self.start_row, self.start_col = start
        self.cols = cols

    def __missing__(self, v: int) -> float:
        vr, vc = divmod(v, self.cols)
        h = self[v] = octile_cells(vr - self.start_row, vc - self.start_col)
        return h
