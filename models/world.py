"""The world's description: poses, obstacle footprints, bounds and occupancy grids.

This is the ground floor of swarmnav: plain data and NumPy, imported by the
planners, the controllers and the simulation alike.  Lengths are metres,
angles radians (CCW from +x).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarmnav.models.geometry import segment_box_distances

def wrap_angle_rad(angle_rad):
    """Wrap an angle (a float or an array) to [-pi, pi)."""
    return (angle_rad + math.pi) % (2.0 * math.pi) - math.pi


@dataclass(frozen=True, init=False)
class Pose2D:
    """A planar pose: position in metres, heading in radians (CCW from +x)."""

    x_m: float
    y_m: float
    heading_rad: float = 0.0

    def __init__(self, x_m: float, y_m: float, heading_rad: float = 0.0):
        # Built every control step: the frozen fields set once, straight into the dict (the generated
        # __init__ goes through object.__setattr__ per field, about twice the cost).
        self.__dict__.update(x_m=x_m, y_m=y_m, heading_rad=heading_rad)

    @property
    def xy(self) -> np.ndarray:
        return np.array([self.x_m, self.y_m], dtype=float)


@dataclass(frozen=True)
class Disc:
    """A circular obstacle footprint (not inflated)."""

    x_m: float
    y_m: float
    radius_m: float


@dataclass(frozen=True)
class Box:
    """An axis-aligned rectangular obstacle footprint (not inflated)."""

    x_min_m: float
    y_min_m: float
    x_max_m: float
    y_max_m: float


@dataclass(frozen=True)
class Rect:
    """Axis-aligned bounds of the workspace, in metres."""

    x_min_m: float
    y_min_m: float
    x_max_m: float
    y_max_m: float

    @property
    def width_m(self) -> float:
        return self.x_max_m - self.x_min_m

    @property
    def height_m(self) -> float:
        return self.y_max_m - self.y_min_m

    def contains(self, x_m: float, y_m: float, margin_m: float = 0.0) -> bool:
        return (self.x_min_m + margin_m <= x_m <= self.x_max_m - margin_m
                and self.y_min_m + margin_m <= y_m <= self.y_max_m - margin_m)


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """A boolean occupancy grid over a :class:`Rect`.

    ``occupied[row, col]`` covers x in ``[x_min + col*cell_m, x_min + (col+1)*cell_m)``
    and y in ``[y_min + row*cell_m, ...)``: rows grow with y, columns with x.
    """

    occupied: np.ndarray  # (rows, cols) bool
    cell_m: float
    origin_m: tuple[float, float]  # world (x, y) of the corner of cell (0, 0)

    @property
    def shape(self) -> tuple[int, int]:
        return self.occupied.shape  # type: ignore[return-value]

    def cell_of(self, x_m: float, y_m: float) -> tuple[int, int]:
        """(row, col) of the cell containing a world point, clamped to the grid."""
        rows, cols = self.occupied.shape
        col = int(math.floor((x_m - self.origin_m[0]) / self.cell_m))
        row = int(math.floor((y_m - self.origin_m[1]) / self.cell_m))
        return min(max(row, 0), rows - 1), min(max(col, 0), cols - 1)

    def centres_m(self, cells: np.ndarray) -> np.ndarray:
        """World (x, y) centres of an (N, 2) array of (row, col) cells."""
        cells = np.asarray(cells, dtype=float).reshape(-1, 2)
        x = self.origin_m[0] + (cells[:, 1] + 0.5) * self.cell_m
        y = self.origin_m[1] + (cells[:, 0] + 0.5) * self.cell_m
        return np.column_stack([x, y])


def rasterise(bounds: Rect, discs: tuple[Disc, ...], boxes: tuple[Box, ...],
              inflation_m: float, cell_m: float) -> OccupancyGrid:
    """Occupancy grid whose blocked cells have centres within ``inflation_m`` of an obstacle.

    A further margin of ``cell_m / sqrt(2)`` is added so that the straight move
    between the centres of two free 8-neighbours never enters an inflated
    obstacle (with endpoints at least R + h/sqrt(2) from a centre, the midpoint
    of a move of length h*sqrt(2) stays at least R away).

    Each obstacle is rasterised only over the window of cells its grown
    footprint can reach, so the cost is the obstacles' area, not obstacles x grid.
    """
    if cell_m <= 0:
        raise ValueError("cell_m must be positive")
    cols = max(1, int(math.ceil(bounds.width_m / cell_m - 1e-9)))
    rows = max(1, int(math.ceil(bounds.height_m / cell_m - 1e-9)))
    xs = bounds.x_min_m + (np.arange(cols) + 0.5) * cell_m
    ys = bounds.y_min_m + (np.arange(rows) + 0.5) * cell_m
    reach = inflation_m + cell_m / math.sqrt(2.0)
    occupied = np.zeros((rows, cols), dtype=bool)

    def window(x_lo: float, x_hi: float, y_lo: float, y_hi: float) -> tuple[slice, slice]:
        c0 = max(0, int(math.floor((x_lo - bounds.x_min_m) / cell_m)))
        c1 = min(cols, int(math.ceil((x_hi - bounds.x_min_m) / cell_m)) + 1)
        r0 = max(0, int(math.floor((y_lo - bounds.y_min_m) / cell_m)))
        r1 = min(rows, int(math.ceil((y_hi - bounds.y_min_m) / cell_m)) + 1)
        return slice(r0, max(r0, r1)), slice(c0, max(c0, c1))

    if discs:
        _mark_discs(occupied, xs, ys, bounds, discs, reach, cell_m)
    for box in boxes:
        rs, cs = window(box.x_min_m - reach, box.x_max_m + reach, box.y_min_m - reach, box.y_max_m + reach)
        dx = np.maximum(np.maximum(box.x_min_m - xs[cs], xs[cs] - box.x_max_m), 0.0)
        dy = np.maximum(np.maximum(box.y_min_m - ys[rs], ys[rs] - box.y_max_m), 0.0)
        occupied[rs, cs] |= dy[:, None] ** 2 + dx[None, :] ** 2 < reach * reach
    return OccupancyGrid(occupied=occupied, cell_m=float(cell_m),
                         origin_m=(bounds.x_min_m, bounds.y_min_m))


RASTER_CHUNK_CELLS = 1 << 14  # cells tested per NumPy pass of _mark_discs (bounds its memory; fastest here)


def _mark_discs(occupied: np.ndarray, xs: np.ndarray, ys: np.ndarray, bounds: Rect, discs: tuple[Disc, ...],
                reach_m: float, cell_m: float) -> None:
    """Mark the cells of :func:`rasterise`'s discs, many discs per NumPy pass.

    Each disc is tested on a square box of cells from the first row and column of its window (a cell of the
    box beyond the window is farther than the grown radius by more than half a cell, so it fails the test;
    indices clipped into the grid repeat cells of the window), with the same test per cell as one disc at a
    time: ``dy**2 + dx**2 < grown**2``.  All discs go in one pass when their boxes, sized by the largest,
    hold at most ``RASTER_CHUNK_CELLS`` cells; otherwise in groups of a box size (powers of two, each box its
    group's largest), at most that many cells per pass (one disc at least), so one large disc among many
    small ones costs its own box, not theirs.
    """
    rows, cols = occupied.shape
    arr = np.array([(d.x_m, d.y_m, d.radius_m) for d in discs], dtype=float)
    grown = arr[:, 2] + reach_m
    c0 = np.floor((arr[:, 0] - grown - bounds.x_min_m) / cell_m)
    r0 = np.floor((arr[:, 1] - grown - bounds.y_min_m) / cell_m)
    spans = np.ceil(2.0 * grown / cell_m).astype(np.int64) + 3    # the window's width, at most
    top = int(spans.max())
    size_class = np.zeros(len(spans), dtype=np.int64) if len(spans) * top * top <= RASTER_CHUNK_CELLS \
        else np.ceil(np.log2(spans)).astype(np.int64)               # all in one pass when that is small
    for size in np.unique(size_class).tolist():
        members = np.flatnonzero(size_class == size)
        box = int(spans[members].max())
        per_pass = max(1, RASTER_CHUNK_CELLS // (box * box))
        for first in range(0, len(members), per_pass):
            k = members[first:first + per_pass]
            span = np.arange(int(spans[k].max()))
            cc = np.clip(c0[k, None] + span, 0, cols - 1).astype(np.int64)
            rr = np.clip(r0[k, None] + span, 0, rows - 1).astype(np.int64)
            dx = xs[cc] - arr[k, 0:1]
            dy = ys[rr] - arr[k, 1:2]
            g = grown[k]
            d, i, j = np.nonzero(dy[:, :, None] ** 2 + dx[:, None, :] ** 2 < (g * g)[:, None, None])
            occupied[rr[d, i], cc[d, j]] = True


def nearest_obstacle(x_m: float, y_m: float, disc_centres_m: np.ndarray, disc_radii_m: np.ndarray,
                     boxes_m: np.ndarray, inflation_m: float) -> tuple[str, int, float]:
    """The obstacle nearest a point: ("disc" or "box", its index, signed gap to its inflated footprint).

    Args:
        disc_centres_m: (C, 2) disc centres; disc_radii_m: (C,) radii, not inflated.
        boxes_m: (B, 4) boxes as rows of (x_min, y_min, x_max, y_max), not inflated.

    Returns:
        ("", -1, inf) with no obstacle.  A point inside a box scores ``-inflation_m``.
    """
    best = ("", -1, math.inf)
    if len(disc_centres_m):
        d = np.hypot(disc_centres_m[:, 0] - x_m, disc_centres_m[:, 1] - y_m) - (disc_radii_m + inflation_m)
        i = int(np.argmin(d))
        best = ("disc", i, float(d[i]))
    if len(boxes_m):
        p = np.array([[x_m, y_m]])
        d = segment_box_distances(p, p, boxes_m)[0] - inflation_m
        i = int(np.argmin(d))
        if d[i] < best[2]:
            best = ("box", i, float(d[i]))
    return best


def endpoint_problem(pose: Pose2D, bounds: Rect, disc_centres_m: np.ndarray, disc_radii_m: np.ndarray,
                     boxes_m: np.ndarray, inflation_m: float, tolerance_m: float = 0.0) -> str | None:
    """Why a start or goal pose is unusable (outside the bounds, inside a grown obstacle), or None.

    The one endpoint check: scenario validation turns the answer into a
    ``ConfigError``, the planners into ``StartBlocked`` / ``GoalBlocked``.
    """
    if not bounds.contains(pose.x_m, pose.y_m):
        return (f"({pose.x_m:g}, {pose.y_m:g}) is outside the bounds [{bounds.x_min_m:g}, {bounds.x_max_m:g}] x "
                f"[{bounds.y_min_m:g}, {bounds.y_max_m:g}]")
    kind, index, gap = nearest_obstacle(pose.x_m, pose.y_m, disc_centres_m, disc_radii_m, boxes_m, inflation_m)
    if gap < -tolerance_m:
        what = f"obstacles[{index}]" if kind == "disc" else "a map obstacle"
        return f"({pose.x_m:g}, {pose.y_m:g}) is inside {what} grown by {inflation_m:g} m (by {-gap:.3f} m)"
    return None
