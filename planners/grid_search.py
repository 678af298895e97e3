"""Grid search baselines: A*, Dijkstra, Theta* and D* Lite on one neighbour table.

All searches are 8-connected with **no corner cutting** (a diagonal move needs
both orthogonal cells it passes to be free), the Moving AI convention, so
A* and Dijkstra reproduce the benchmark's optimal octile lengths.

Speed: the legal moves of every cell are found once per grid with NumPy
(:func:`neighbour_table`) and kept as one 8-bit mask per cell, cached by the
grid's content; the searches then run over plain Python lists with ``heapq``,
reading each cell's moves from a table of the 256 masks (:func:`moves_by_mask`).

Every planner here turns the cell path into waypoints in metres (the exact
start and goal replace the centres of their cells), keeps the raw cell path in
``stats.extra["raw_cells"]``, and by default shortcuts it by exact line of
sight (:func:`exact_shortcut`).
"""

from __future__ import annotations

import heapq
import math
import time
from collections import OrderedDict
from dataclasses import dataclass, replace
from typing import Any, Callable, ClassVar, Iterable

import numpy as np

from swarmnav.planners.errors import GoalBlocked, NoPathFound, StartBlocked, check_parameters
from swarmnav.models.geometry import segment_box_distance, segment_box_distances, segment_disc_distances
from swarmnav.models.world import OccupancyGrid
from swarmnav.planners.problem import Path, Problem, check_endpoints

SQRT2 = math.sqrt(2.0)
INF = float("inf")
#: (d_row, d_col) of the 8 moves: 4 orthogonal first, then 4 diagonal.
DIRECTIONS = ((-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (-1, 1), (1, -1), (1, 1))
#: Cost in cells of each move of :data:`DIRECTIONS`.
STEP_COSTS = (1.0, 1.0, 1.0, 1.0, SQRT2, SQRT2, SQRT2, SQRT2)
# (d_row, d_col, cost in cells), the foundation's name for the same moves.
MOVES_8 = tuple((dr, dc, cost) for (dr, dc), cost in zip(DIRECTIONS, STEP_COSTS))

Cell = tuple[int, int]


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
_MASK_BITS = 1 << np.arange(8, dtype=np.int64)


class _AdjacencyCache:
    """Neighbour tables and legal-move masks of recently seen grids, keyed by content.

    A search reads the moves out of cell ``u`` as ``moves_by_mask(cols)[masks[u]]``,
    offsets to add to ``u``: building that for a new grid is one vectorised
    table and a list of N small ints (a fraction of a millisecond on 50 x 50),
    not N Python lists.
    """

    def __init__(self, size: int = 16):
        self.size = size
        self.entries: OrderedDict[tuple, tuple[np.ndarray, list[int]]] = OrderedDict()

    def get(self, occupied: np.ndarray) -> tuple[np.ndarray, list[int]]:
        """(neighbour table (N, 8), legal-move mask of every cell as a list)."""
        occ = np.ascontiguousarray(occupied, dtype=bool)
        key = (occ.shape, occ.tobytes())
        hit = self.entries.get(key)
        if hit is not None:
            self.entries.move_to_end(key)
            return hit
        table = neighbour_table(occ)
        masks = ((table >= 0) @ _MASK_BITS).tolist()
        self.entries[key] = (table, masks)
        if len(self.entries) > self.size:
            self.entries.popitem(last=False)
        return table, masks


ADJACENCY = _AdjacencyCache()


def _octile_to(goal: Cell, shape: tuple[int, int]) -> list[float]:
    rows, cols = shape
    dr = np.abs(np.arange(rows) - goal[0])[:, None]
    dc = np.abs(np.arange(cols) - goal[1])[None, :]
    return ((SQRT2 - 1.0) * np.minimum(dr, dc) + np.maximum(dr, dc)).ravel().tolist()


def _check_cells(occupied: np.ndarray, start: Cell, goal: Cell) -> None:
    rows, cols = occupied.shape
    for cell, error, label in ((start, StartBlocked, "start"), (goal, GoalBlocked, "goal")):
        if not (0 <= cell[0] < rows and 0 <= cell[1] < cols):
            raise error(f"{label} cell {cell} is outside the {rows} x {cols} grid")
        if occupied[cell]:
            raise error(f"{label} cell {cell} is occupied")


def astar_cells(occupied: np.ndarray, start: Cell, goal: Cell,
                heuristic_weight: float = 1.0) -> tuple[list[Cell], float, int]:
    """A* (or Dijkstra with ``heuristic_weight=0``) over an 8-connected grid without corner cutting.

    Ties on f are broken towards the larger g, which keeps A* expansions low on open maps.

    Args:
        occupied: (rows, cols) bool, True where blocked.
        start, goal: (row, col) cells; both must be free.
        heuristic_weight: 1.0 for optimal A* (octile heuristic), 0.0 for Dijkstra.

    Returns:
        (cells from start to goal, cost in cells, number of expansions).

    Raises:
        StartBlocked, GoalBlocked: an endpoint is outside the grid or occupied.
        NoPathFound: the goal is unreachable.
    """
    occupied = np.asarray(occupied, dtype=bool)
    _check_cells(occupied, start, goal)
    rows, cols = occupied.shape
    _, masks = ADJACENCY.get(occupied)
    moves = moves_by_mask(cols)
    s = start[0] * cols + start[1]
    t = goal[0] * cols + goal[1]
    n = rows * cols
    g = [INF] * n
    parent = [-1] * n
    closed = bytearray(n)
    g[s] = 0.0
    push, pop = heapq.heappush, heapq.heappop
    if heuristic_weight:
        h = _octile_to(goal, occupied.shape)
        if heuristic_weight != 1.0:
            h = [heuristic_weight * v for v in h]
        heap = [(h[s], 0.0, s)]
    else:
        h = None
        heap = [(0.0, 0.0, s)]
    expansions = 0
    while heap:
        _, _, u = pop(heap)
        if closed[u]:
            continue
        closed[u] = 1
        expansions += 1
        if u == t:
            break
        gu = g[u]
        for off, w in moves[masks[u]]:
            v = u + off
            nv = gu + w
            if nv < g[v]:
                g[v] = nv
                parent[v] = u
                push(heap, ((nv + h[v]) if h is not None else nv, -nv, v))
    if not closed[t]:
        raise NoPathFound(f"goal cell {goal} is unreachable from start cell {start}")
    return _walk_back(parent, t, cols), g[t], expansions


def dijkstra_cells(occupied: np.ndarray, start: Cell, goal: Cell) -> tuple[list[Cell], float, int]:
    """Dijkstra over the same graph as :func:`astar_cells` (no heuristic)."""
    return astar_cells(occupied, start, goal, heuristic_weight=0.0)


def _walk_back(parent: list[int], t: int, cols: int) -> list[Cell]:
    cells = []
    cur = t
    while cur != -1:
        cells.append(divmod(cur, cols))
        cur = parent[cur]
    cells.reverse()
    return cells


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


def theta_star_cells(occupied: np.ndarray, start: Cell, goal: Cell,
                     line_of_sight: Callable[[Cell, Cell], bool] | None = None
                     ) -> tuple[list[Cell], float, int]:
    """Theta* (Nash, Daniel, Koenig & Felner 2007): A* whose parent may be any visible ancestor.

    Args:
        occupied: (rows, cols) bool.
        start, goal: (row, col) free cells.
        line_of_sight: visibility test between two cells; by default
            :func:`grid_line_of_sight` on ``occupied``.  Each pair is asked
            at most once (answers are kept for the search).

    Returns:
        (corner cells from start to goal, Euclidean length in cells, expansions).
    """
    occupied = np.asarray(occupied, dtype=bool)
    _check_cells(occupied, start, goal)
    rows, cols = occupied.shape
    _, masks = ADJACENCY.get(occupied)
    moves = moves_by_mask(cols)
    free = (~occupied).tolist()
    los = line_of_sight or (lambda p, q: grid_line_of_sight(free, p, q))
    s = start[0] * cols + start[1]
    t = goal[0] * cols + goal[1]
    n = rows * cols
    g = [INF] * n
    parent = [-1] * n
    closed = bytearray(n)
    seen: dict[int, bool] = {}      # line of sight by (parent, cell): Theta* asks most pairs several times
    g[s] = 0.0
    parent[s] = s
    gr, gc = goal

    def h(v: int) -> float:
        vr, vc = divmod(v, cols)
        return math.hypot(vr - gr, vc - gc)

    heap = [(h(s), 0.0, s)]
    expansions = 0
    while heap:
        _, _, u = heapq.heappop(heap)
        if closed[u]:
            continue
        closed[u] = 1
        expansions += 1
        if u == t:
            break
        pu = parent[u]
        pr, pc = divmod(pu, cols)
        ur, uc = divmod(u, cols)
        for off, w in moves[masks[u]]:
            v = u + off
            if closed[v]:
                continue
            vr, vc = divmod(v, cols)
            if pu != u:
                key = pu * n + v
                visible = seen.get(key)
                if visible is None:
                    visible = seen[key] = los((pr, pc), (vr, vc))
            else:
                visible = False
            if visible:
                cand, par = g[pu] + math.hypot(vr - pr, vc - pc), pu
            else:
                cand, par = g[u] + w, u
            if cand < g[v] - 1e-12:
                g[v] = cand
                parent[v] = par
                heapq.heappush(heap, (cand + h(v), -cand, v))
    if not closed[t]:
        raise NoPathFound(f"goal cell {goal} is unreachable from start cell {start}")
    cells = []
    cur = t
    while True:
        cells.append(divmod(cur, cols))
        if cur == s:
            break
        cur = parent[cur]
    cells.reverse()
    return cells, g[t], expansions


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

    def __init__(self, occupied: np.ndarray, start: Cell, goal: Cell):
        occ = np.asarray(occupied, dtype=bool)
        _check_cells(occ, start, goal)
        self.rows, self.cols = occ.shape
        self.free = (~occ).tolist()
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
        for (dr, dc), w in zip(DIRECTIONS, STEP_COSTS):
            nr, nc = r + dr, c + dc
            if 0 <= nr < rows and 0 <= nc < cols and free[nr][nc]:
                if dr and dc and not (free[r][nc] and free[nr][c]):
                    continue
                yield nr * cols + nc, w

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
            for dr in (-1, 0, 1):
                for dc in (-1, 0, 1):
                    nr, nc = r + dr, c + dc
                    if 0 <= nr < self.rows and 0 <= nc < self.cols:
                        touched.add(nr * self.cols + nc)
        for v in sorted(touched):
            if not self.free[v // self.cols][v % self.cols]:
                self.g[v] = INF
            self._recompute_rhs(v)
            self._update_vertex(v)


# -- from cells to a Path ------------------------------------------------------

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


def segments_clear(problem: Problem, a: np.ndarray, bs: np.ndarray, tolerance_m: float = 1e-9) -> np.ndarray:
    """For each end point in ``bs`` (K, 2), whether the segment from ``a`` keeps the inflation.

    Discs and boxes are tested exactly.  A grid given directly without boxes
    (a bare map) is tested cell by cell with :func:`grid_line_of_sight`.
    """
    bs = np.asarray(bs, dtype=float).reshape(-1, 2)
    a = np.asarray(a, dtype=float).reshape(1, 2)
    ok = np.ones(len(bs), dtype=bool)
    b = problem.bounds
    ok &= (bs[:, 0] >= b.x_min_m - tolerance_m) & (bs[:, 0] <= b.x_max_m + tolerance_m)
    ok &= (bs[:, 1] >= b.y_min_m - tolerance_m) & (bs[:, 1] <= b.y_max_m + tolerance_m)
    starts = np.repeat(a, len(bs), axis=0)
    if problem.obstacles:
        d = segment_disc_distances(starts, bs, problem.disc_centres_m)
        ok &= np.all(d - problem.inflated_radii_m[None, :] >= -tolerance_m, axis=1)
    if problem.boxes:
        # Only boxes that reach the fan's bounding box (grown by the inflation) can matter.
        boxes = problem.box_array_m
        lo = np.minimum(a[0], bs.min(axis=0)) - problem.inflation_m
        hi = np.maximum(a[0], bs.max(axis=0)) + problem.inflation_m
        near = (boxes[:, 0] <= hi[0]) & (boxes[:, 2] >= lo[0]) & (boxes[:, 1] <= hi[1]) & (boxes[:, 3] >= lo[1])
        if near.any():
            d = segment_box_distances(starts, bs, boxes[near])
            ok &= (d.min(axis=1) - problem.inflation_m >= -tolerance_m)
    elif problem.grid_override is not None:
        grid = problem.grid
        free = (~grid.occupied).tolist()
        ca = grid.cell_of(*a[0])
        for k in np.flatnonzero(ok):
            ok[k] = grid_line_of_sight(free, ca, grid.cell_of(*bs[k]))
    return ok


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

    Visibility is :func:`segments_clear`, evaluated ``window`` vertices at a
    time in one NumPy call; while the last vertex of a window is still visible
    the next window is tried too, so a long straight run collapses to one
    segment.  Consecutive vertices are assumed visible (grid moves between free
    cells are), so this never fails.
    """
    pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    if len(pts) <= 2:
        return pts.copy()
    kept = [0]
    i = 0
    last = len(pts) - 1
    while i < last:
        j = i + 1
        lo = i + 1
        while lo <= last:
            hi = min(lo + window, last + 1)
            visible = np.flatnonzero(segments_clear(problem, pts[i], pts[lo:hi]))
            if visible.size:
                j = lo + int(visible[-1])
            if not visible.size or j != hi - 1:
                break
            lo = hi
        kept.append(j)
        i = j
    return pts[kept]


def count_bends(cells: list[Cell] | np.ndarray) -> int:
    """Number of direction changes along a cell path."""
    arr = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    if len(arr) < 3:
        return 0
    steps = np.diff(arr, axis=0)
    return int(np.count_nonzero(np.any(steps[1:] != steps[:-1], axis=1)))


@dataclass
class GridPlanner:
    """Shared plumbing of the grid planners: endpoints, waypoints, shortcut and stats.

    Subclasses define ``name`` and :meth:`search`.
    """

    name: ClassVar[str] = ""
    cell_m: float | None = None
    shortcut: bool = True

    def __post_init__(self) -> None:
        check_parameters(self, (("cell_m", self.cell_m is None or self.cell_m > 0, "must be positive"),))

    def search(self, problem: Problem, grid: OccupancyGrid, start: Cell, goal: Cell
               ) -> tuple[list[Cell], float, int, dict[str, Any]]:
        """Return (cells, cost in cells, expansions, extra stats)."""
        raise NotImplementedError

    def plan(self, problem: Problem, rng: np.random.Generator) -> Path:
        t0 = time.perf_counter()
        check_endpoints(problem)
        if self.cell_m is not None and self.cell_m != problem.cell_m and problem.grid_override is None:
            problem = replace(problem, cell_m=self.cell_m)
        grid = problem.grid
        start, goal = grid_endpoints(problem, grid)
        cells, cost_cells, expansions, extra = self.search(problem, grid, start, goal)
        raw = cells_to_waypoints(problem, grid, cells)
        waypoints = exact_shortcut(problem, raw) if self.shortcut else raw
        stats = {"raw_cells": [list(c) for c in cells], "raw_length_m": cost_cells * grid.cell_m,
                 "bends": count_bends(cells)}
        stats.update(extra)
        return Path.from_waypoints(waypoints, time.perf_counter() - t0, iterations=expansions,
                                   evaluations=expansions, extra=stats)


@dataclass
class AStarPlanner(GridPlanner):
    """Grid A* (octile heuristic, no corner cutting), then exact line-of-sight shortcutting.

    Args:
        cell_m: grid resolution; ``None`` keeps the problem's.
        shortcut: apply line-of-sight shortcutting (on by default for execution).
    """

    name: ClassVar[str] = "astar"

    def search(self, problem, grid, start, goal):
        cells, cost, expansions = astar_cells(grid.occupied, start, goal)
        return cells, cost, expansions, {}


@dataclass
class DijkstraPlanner(GridPlanner):
    """Grid Dijkstra over the same 8-connected graph as A* (the uninformed baseline)."""

    name: ClassVar[str] = "dijkstra"

    def search(self, problem, grid, start, goal):
        cells, cost, expansions = dijkstra_cells(grid.occupied, start, goal)
        return cells, cost, expansions, {}


@dataclass
class ThetaStarPlanner(GridPlanner):
    """Theta*, any-angle: the grid yardstick for the length of a path that need not follow moves.

    Line of sight is checked cell by cell on the inflated grid and, where the
    problem has box obstacles (maps), also exactly against the inflated boxes
    (:func:`box_line_of_sight`).
    """

    name: ClassVar[str] = "theta_star"

    def search(self, problem, grid, start, goal):
        los = box_line_of_sight(problem, grid) if problem.boxes else None
        cells, cost, expansions = theta_star_cells(grid.occupied, start, goal, los)
        return cells, cost, expansions, {}


@dataclass
class DStarLitePlanner(GridPlanner):
    """D* Lite planned once from scratch (its incremental API is :class:`DStarLite`)."""

    name: ClassVar[str] = "dstar_lite"

    def search(self, problem, grid, start, goal):
        planner = DStarLite(grid.occupied, start, goal)
        cells = planner.plan()
        return cells, planner.cost_cells, planner.expansions, {}
