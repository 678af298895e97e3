"""BARN's difficulty metrics of a world (Perille, Truong, Xiao and Stone 2020, Sec. III-B), and success against
them.

Each metric is computed on the world's 0.15 m cell grid of the obstacle field (the 30 rows y = 5.0 .. 9.5 m
where the reference path runs, and the 32 columns x = -4.65 .. 0.15 m, the side walls included) made into a
C-space by growing every occupied cell by one cell (3 x 3): the largest growth that keeps every shipped
reference path free (checked on every world; a growth of two cells blocks 115 of 677 path cells).  Each is
averaged over the reference path's cells (``paths/path_N.npy``), except tortuosity.  The definitions follow the
paper's and its generator's (dperille/jackal-map-creation, ``difficulty_quant.py``), read and reimplemented:

* ``distance_to_closest_obstacle`` (cells): the Euclidean distance from the cell to the nearest occupied cell;
* ``average_visibility`` (cells): along the 8 compass directions, the free cells before an occupied one, over
  the directions that meet one before leaving the grid;
* ``dispersion``: along 16 directions (the 8 compass ones and the 8 between them, slopes +-1/2 and +-2, whose
  steps count 2) out to :data:`DISPERSION_RADIUS_CELLS`, whether an occupied cell is met; the number of changes
  between met and not met going once around;
* ``characteristic_dimension`` (cells): over 4 axes (vertical, horizontal, 2 diagonals), the free length
  through the cell along the axis both ways (a diagonal step counts sqrt 2), the least of the four;
* ``tortuosity``: the path's length over the straight line between its ends (both in cells).
"""

from __future__ import annotations

import math
import numpy as np

CELL_M = 0.15
FIELD_ROW0 = 33             # world cell row of path row 0: round((5.075 - 0.075) / 0.15)
FIELD_ROWS, FIELD_COLS = 30, 32
DISPERSION_RADIUS_CELLS = 3  # the generator's radius
METRICS = ("distance_to_closest_obstacle", "average_visibility", "dispersion", "characteristic_dimension",
           "tortuosity")
COMPASS = [(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if (dr, dc) != (0, 0)]
SIXTEEN = [(0, 1), (1, 2), (1, 1), (2, 1), (1, 0), (2, -1), (1, -1), (1, -2), (0, -1), (-2, -1), (-1, -1), (-1, -2),
           (-1, 0), (-2, 1), (-1, 1), (-1, 2)]  # in order around the circle
AXES = [(0, 1), (1, 1), (1, 0), (1, -1)]


def field_grid(cylinders_xy: np.ndarray) -> np.ndarray:
    """The obstacle field's occupied cells (rows up the y axis) from cylinder centres in the world's frame."""
    grid = np.zeros((FIELD_ROWS, FIELD_COLS), dtype=bool)
    rows = np.round((cylinders_xy[:, 1] - 0.075) / CELL_M).astype(int) - FIELD_ROW0
    cols = np.round((cylinders_xy[:, 0] + 4.575) / CELL_M).astype(int)
    keep = (rows >= 0) & (rows < FIELD_ROWS) & (cols >= 0) & (cols < FIELD_COLS)
    grid[rows[keep], cols[keep]] = True
    return grid


def c_space(grid: np.ndarray) -> np.ndarray:
    from scipy.ndimage import binary_dilation
    return binary_dilation(grid, np.ones((3, 3), dtype=bool))


def _ray(space: np.ndarray, r: int, c: int, dr: int, dc: int, limit: int | None = None) -> tuple[int, bool]:
    """Steps taken from (r, c) along (dr, dc) over free cells, and whether an occupied cell ended the ray
    (False: it left the grid, or ``limit`` steps were taken)."""
    steps = 0
    while limit is None or steps < limit:
        r, c = r + dr, c + dc
        if not (0 <= r < space.shape[0] and 0 <= c < space.shape[1]):
            return steps, False
        if space[r, c]:
            return steps, True
        steps += 1
    return steps, False


def cell_metrics(space: np.ndarray, r: int, c: int, clearance: np.ndarray) -> tuple[float, float, float, float]:
    """Distance to the closest obstacle, average visibility, dispersion, characteristic dimension of one cell."""
    seen = [s + 1 for s, hit in (_ray(space, r, c, dr, dc) for dr, dc in COMPASS) if hit]
    visibility = sum(seen) / len(seen) if seen else float(max(space.shape))
    walls = []
    for dr, dc in SIXTEEN:
        double = 2 in (abs(dr), abs(dc))
        limit = math.ceil(DISPERSION_RADIUS_CELLS / 2) if double else DISPERSION_RADIUS_CELLS
        walls.append(_ray(space, r, c, dr, dc, limit)[1])
    dispersion = sum(walls[k] != walls[k - 1] for k in range(len(walls)))
    widths = []
    for dr, dc in AXES:
        length = sum(_ray(space, r, c, sr * dr, sr * dc)[0] for sr in (1, -1))
        widths.append(length * math.hypot(dr, dc))
    return float(clearance[r, c]), float(visibility), float(dispersion), float(min(widths))


def world_metrics(cylinders_xy: np.ndarray, path_cells: np.ndarray) -> dict[str, float]:
    """The five metrics of a world (see the module docstring); ``path_cells``: (n, 2) of (column, row)."""
    from scipy.ndimage import distance_transform_edt
    space = c_space(field_grid(cylinders_xy))
    clearance = distance_transform_edt(~space)
    per_cell = np.array([cell_metrics(space, int(b), int(a), clearance) for a, b in path_cells])
    steps = np.diff(path_cells.astype(float), axis=0)
    chord = float(np.linalg.norm(path_cells[-1].astype(float) - path_cells[0]))
    arc = float(np.linalg.norm(steps, axis=1).sum())
    means = per_cell.mean(axis=0)
    return {**{k: round(float(v), 6) for k, v in zip(METRICS[:4], means)},
            "tortuosity": round(arc / chord, 6) if chord > 0 else 1.0}


def spearman(a: list[float], b: list[float]) -> float | None:
    """Spearman's rank correlation (average ranks for ties); None when either side is constant."""
    from scipy.stats import spearmanr
    if len(set(a)) < 2 or len(set(b)) < 2:
        return None
    return round(float(spearmanr(a, b).statistic), 4)


def success_against_difficulty(rows: list[dict], navigator: str) -> dict[str, dict[str, float | None]]:
    """For one navigator's per-run rows (each with ``world``, ``success_rate``, ``difficulty``): per metric the
    Spearman correlation of the world's success with the metric, and the success in the metric's lower and
    upper half of worlds (split at the median)."""
    mine = [r for r in rows if r["navigator"] == navigator and r.get("difficulty")]
    by_world: dict[int, list[float]] = {}
    for r in mine:
        by_world.setdefault(r["world"], []).append(r["success_rate"])
    worlds = sorted(by_world)
    success = [sum(by_world[w]) / len(by_world[w]) for w in worlds]
    metric_of = {r["world"]: r["difficulty"] for r in mine}
    out = {}
    for key in METRICS:
        values = [metric_of[w][key] for w in worlds]
        median = float(np.median(values)) if values else 0.0
        low = [s for s, v in zip(success, values) if v <= median]
        high = [s for s, v in zip(success, values) if v > median]
        out[key] = {"spearman": spearman(values, success),
                    "success_low_half": round(sum(low) / len(low), 4) if low else None,
                    "success_high_half": round(sum(high) / len(high), 4) if high else None}
    return out
