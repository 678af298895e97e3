"""BARN-like worlds at fresh seeds (``bench navigation --suite barn-like``): a check of the BARN figures on
worlds made the way BARN's were (Perille et al. 2020, Sec. III-A; the generator's parameters read from
dperille/jackal-map-creation, ``generator.py`` and ``gen_world_ca.py``, and reimplemented):

* the obstacle field is 30 x 30 cells of 0.15 m; across the direction of travel its first and last cells are
  wall (the side walls), every other cell is filled with probability ``fill`` (BARN: 0.15, 0.20, 0.25, 0.30);
* ``smoothing`` passes (BARN: 2, 3, 4) of a cellular automaton: a cell with more than 4 filled of its 8
  neighbours fills, one with fewer than 2 empties, any other keeps its state (beyond the side walls counts as
  filled, beyond the ends of the field as empty);
* a world whose field, its filled cells grown by two cells (5 x 5), has no 4-connected passage from its first
  row to its last (every one of 60 BARN worlds sampled, 0, 5, ..., 295, has one: a passage 0.75 m wide) gets
  one: the filled cells within two cells of its cheapest passage are emptied (:func:`clear_passage`), as
  BARN's generator cleared cells to join regions (a first version of this check, cells grown by one and paths
  cutting corners, let through worlds the stand-in's planner found no path in: 24 of 50);
* the field sits in BARN's frame (rows y = 5.0 .. 9.5 m), inside BARN's entry corridor (a wall of cylinders at
  y = 0.075 m and side walls at x = -4.425 and -0.075 m up to y = 9.525 m), every filled cell a cylinder of
  radius 0.075 m and height 1 m at the cell's centre, as in BARN's world files.

Seed ``s`` takes BARN's parameter pair ``s mod 12`` (fill, smoothing) and draws from
``numpy.random.default_rng([s, 34])``.  The reference path (BARN's OT) is the shortest 8-connected path over
the C-space's free cells from the first field row to the last, start and goal joined to its ends (as BARN's
``path_N.npy``), in the same cells (x = 0.15 a - 4.575, y = 0.15 b + 5.075).
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from swarmnav.models.gazebo_world import Cylinder, GazeboWorld

FIELD = 30                       # cells each way
FILLS = (0.15, 0.20, 0.25, 0.30)
SMOOTHINGS = (2, 3, 4)
RADIUS_M = 0.075
HEIGHT_M = 1.0
CELL_M = 0.15
MAX_DRAWS = 1000                 # redraws of one seed before giving up (a full field is never passable)


def parameters(seed: int) -> tuple[float, int]:
    pair = seed % (len(FILLS) * len(SMOOTHINGS))
    return FILLS[pair // len(SMOOTHINGS)], SMOOTHINGS[pair % len(SMOOTHINGS)]


def smooth(field: np.ndarray) -> np.ndarray:
    """One pass of the automaton over ``field`` (rows: along travel; columns: across, walls at both ends)."""
    padded = np.pad(field.astype(np.int8), 1, constant_values=0)
    padded[:, 0] = padded[:, -1] = 1              # beyond the side walls: filled
    neighbours = sum(np.roll(np.roll(padded, dr, 0), dc, 1) for dr in (-1, 0, 1) for dc in (-1, 0, 1)
                     if (dr, dc) != (0, 0))[1:-1, 1:-1]
    out = field.copy()
    out[neighbours > 4] = True
    out[neighbours < 2] = False
    return out


def draw_field(rng: np.random.Generator, fill: float, smoothing: int) -> np.ndarray:
    field = rng.random((FIELD, FIELD)) < fill
    field[:, 0] = field[:, -1] = True
    for _ in range(smoothing):
        field = smooth(field)
    field[:, 0] = field[:, -1] = True
    return field


def reference_cells(field: np.ndarray, start_cell: tuple[float, float], goal_cell: tuple[float, float]
                    ) -> np.ndarray | None:
    """(column, row) cells of the shortest 8-connected path over the C-space's free cells from the first row
    to the last, its ends joined to ``start_cell`` and ``goal_cell`` (cell coordinates); None without one."""
    from scipy.ndimage import binary_dilation
    free = ~binary_dilation(field, np.ones((3, 3), dtype=bool))
    dist = np.full(field.shape, np.inf)
    parent: dict[tuple[int, int], tuple[int, int] | None] = {}
    heap = []
    for c in np.flatnonzero(free[0]):
        d = math.dist(start_cell, (c, 0))
        dist[0, c] = d
        parent[(0, c)] = None
        heap.append((d, 0, int(c)))
    heapq.heapify(heap)
    best, end = math.inf, None
    while heap:
        d, r, c = heapq.heappop(heap)
        if d > dist[r, c] or d >= best:
            continue
        if r == FIELD - 1 and d + math.dist((c, r), goal_cell) < best:
            best, end = d + math.dist((c, r), goal_cell), (r, c)
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                rr, cc = r + dr, c + dc
                if (dr or dc) and 0 <= rr < FIELD and 0 <= cc < FIELD and free[rr, cc]:
                    nd = d + math.hypot(dr, dc)
                    if nd < dist[rr, cc]:
                        dist[rr, cc] = nd
                        parent[(rr, cc)] = (r, c)
                        heapq.heappush(heap, (nd, rr, cc))
    if end is None:
        return None
    cells = []
    node: tuple[int, int] | None = end
    while node is not None:
        cells.append((node[1], node[0]))
        node = parent[node]
    return np.array(cells[::-1], dtype=int)


def passable(field: np.ndarray, growth_cells: int = 2) -> bool:
    """A 4-connected passage from the field's first row to its last over the cells free of any filled cell
    within ``growth_cells`` (a square)."""
    from scipy.ndimage import binary_dilation, label
    size = 2 * growth_cells + 1
    regions, _ = label(~binary_dilation(field, np.ones((size, size), dtype=bool)))
    return bool(set(regions[0][regions[0] > 0]) & set(regions[-1][regions[-1] > 0]))


BLOCKED_STEP_COST = 20.0  # clear_passage: a step onto a cell without 2 cells of clearance, against 1 for a clear one


def clear_passage(field: np.ndarray, growth_cells: int = 2) -> np.ndarray:
    """``field`` with the filled cells within ``growth_cells`` of its cheapest 4-connected passage from the first
    row to the last emptied (a step onto a cell without that clearance costs :data:`BLOCKED_STEP_COST`, onto a
    clear one 1; the side walls stay): BARN's generator likewise cleared cells to join regions."""
    from scipy.ndimage import binary_dilation
    size = 2 * growth_cells + 1
    blocked = binary_dilation(field, np.ones((size, size), dtype=bool))
    inner = slice(growth_cells + 1, FIELD - growth_cells - 1)  # centres whose clearing keeps the side walls
    cost = np.where(blocked, BLOCKED_STEP_COST, 1.0)
    dist = np.full(field.shape, np.inf)
    parent: dict[tuple[int, int], tuple[int, int] | None] = {}
    heap = []
    for c in range(FIELD)[inner]:
        dist[0, c] = cost[0, c]
        parent[(0, c)] = None
        heap.append((cost[0, c], 0, c))
    heapq.heapify(heap)
    end = None
    while heap:
        d, r, c = heapq.heappop(heap)
        if d > dist[r, c]:
            continue
        if r == FIELD - 1:
            end = (r, c)
            break
        for rr, cc in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)):
            if 0 <= rr < FIELD and inner.start <= cc < inner.stop and d + cost[rr, cc] < dist[rr, cc]:
                dist[rr, cc] = d + cost[rr, cc]
                parent[(rr, cc)] = (r, c)
                heapq.heappush(heap, (dist[rr, cc], rr, cc))
    out = field.copy()
    node = end
    while node is not None:
        r, c = node
        out[max(r - growth_cells, 0):r + growth_cells + 1, c - growth_cells:c + growth_cells + 1] = False
        node = parent[node]
    out[:, 0] = out[:, -1] = True
    return out


def generate(seed: int) -> tuple[GazeboWorld, np.ndarray, tuple[float, int]]:
    """A BARN-like world (cylinders in BARN's frame), its reference path cells and its (fill, smoothing)."""
    fill, smoothing = parameters(seed)
    rng = np.random.default_rng([seed, 34])
    # BARN's start and goal in the field's cells: x = 0.15 a - 4.575, y = 0.15 b + 5.075
    # (field column j is BARN's cell column a = j + 1)
    start_cell = ((-2.25 + 4.575) / CELL_M - 1, (3.0 - 5.075) / CELL_M)
    goal_cell = ((-2.25 + 4.575) / CELL_M - 1, (13.0 - 5.075) / CELL_M)
    for _ in range(MAX_DRAWS):
        field = draw_field(rng, fill, smoothing)       # rows along y (travel), columns along x (walls at the ends)
        if not passable(field):
            field = clear_passage(field)
        path = reference_cells(field, start_cell, goal_cell) if passable(field) else None
        if path is not None:
            break
    else:
        raise RuntimeError(f"no passable BARN-like world in {MAX_DRAWS} draws of seed {seed}")
    cylinders = []
    for row in range(64):                               # the entry corridor and the field's side walls
        for col in (1, 30):
            cylinders.append((col, row))
    cylinders += [(col, 0) for col in range(2, 30)]
    rows, cols = np.nonzero(field[:, 1:-1])             # the field's inside (its side columns are the walls)
    cylinders += [(int(c) + 2, int(r) + 33) for r, c in zip(rows, cols)]
    world = GazeboWorld(f"barn-like seed {seed}", tuple(
        Cylinder(f"cell_{col}_{row}", round(CELL_M * col - 4.575, 6), round(CELL_M * row + 0.075, 6), RADIUS_M,
                 HEIGHT_M) for col, row in sorted(set(cylinders), key=lambda p: (p[1], p[0]))), ())
    return world, path + np.array([1, 0]), (fill, smoothing)
