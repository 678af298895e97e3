"""Which points lie inside any of many discs, exactly as the brute-force test decides it, found through a k-d tree.

``dwa`` asks, for every point of every arc in its window, whether the robot's disc there overlaps an obstacle:
``hypot(px - ox, py - oy) < r`` for some obstacle (centre ``ox, oy``, ``r`` its radius plus the robot's).  On a
sensed map the obstacles are the occupied cells near the robot, thousands of them, and the (points x
obstacles) distance array cost ~90 % of a BARN run's CPU.  :func:`inside_any` answers the same question from
each point's nearest centre (:class:`scipy.spatial.cKDTree`, one query per distinct radius) and settles the
points whose nearest distance lies within :data:`BAND_M` of the radius by the brute-force expression itself,
so the answer is the brute-force answer bit for bit (the tree's distances differ from ``np.hypot``'s by a few
units in the last place, far inside the band).

:class:`LatticeDiscs` / :func:`lattice_inside_any`: when the discs are a sensed map's cells (one radius, centred
on its grid's cells), a distance transform of the grid with each cell's nearest disc, kept while the map is,
decides almost every point from its cell and the eight around (with the same band) and leaves the rest to
:func:`inside_any`: the same answer, without a tree built at every step.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

BAND_M = 1e-9          # nearest distances this close to a radius are recomputed with np.hypot
BRUTE_FORCE_MAX = 32   # with at most this many discs the (points x discs) array is cheaper than a tree
BRUTE_FORCE_PAIRS = 20_000  # ... or with at most this many (point, disc) pairs (a few points: LatticeDiscs' rest)


def inside_any(px: np.ndarray, py: np.ndarray, ox: np.ndarray, oy: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Boolean array shaped like ``px``: ``np.hypot(px - ox[n], py - oy[n]) < radius[n]`` for some n.

    ``ox``, ``oy``, ``radius``: (N,) the discs' centres and radii, in the points' frame."""
    shape = np.shape(px)
    if len(ox) <= BRUTE_FORCE_MAX or np.size(px) * len(ox) <= BRUTE_FORCE_PAIRS:
        return _brute(np.ravel(px), np.ravel(py), ox, oy, radius).reshape(shape)
    points = np.column_stack([np.ravel(px), np.ravel(py)])
    out = np.zeros(len(points), dtype=bool)
    for r in np.unique(radius):
        mine = radius == r
        cx, cy = ox[mine], oy[mine]
        nearest, _ = cKDTree(np.column_stack([cx, cy])).query(points, k=1, distance_upper_bound=float(r) + BAND_M)
        out |= nearest < r - BAND_M
        close = np.flatnonzero(np.abs(nearest - r) <= BAND_M)
        if len(close):
            out[close] |= _brute(points[close, 0], points[close, 1], cx, cy, radius[mine])
    return out.reshape(shape)


def _brute(px: np.ndarray, py: np.ndarray, ox: np.ndarray, oy: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """(P,) the test itself, over every (point, disc) pair."""
    return (np.hypot(px[:, None] - ox[None, :], py[:, None] - oy[None, :]) < radius[None, :]).any(axis=1)


class LatticeDiscs:
    """Discs of one radius centred on cells of a grid (a sensed map's occupied cells, each a point at its cell's
    centre), with each grid cell's distance to the nearest of them (a Euclidean distance transform, kept while
    the discs are): what :meth:`settled` needs to decide most points without a k-d tree.

    Build with :meth:`of`, which returns None unless every centre is exactly a cell's centre as
    :class:`controllers.world_map.SensedMap` computes it (``(index + 0.5) * cell_m + origin``)."""

    def __init__(self, occupied: np.ndarray, origin_m: tuple[float, float], cell_m: float):
        from scipy.ndimage import distance_transform_edt
        self.origin_m = (float(origin_m[0]), float(origin_m[1]))
        self.cell_m = float(cell_m)
        self.rows, self.cols = occupied.shape
        cells, nearest = distance_transform_edt(~occupied, return_indices=True)
        # Per cell (flat): the distance from its centre to the nearest disc centre, that centre's x and y.
        self._distance = (cells * self.cell_m).reshape(-1)
        self._nearest_x = ((nearest[1] + 0.5) * self.cell_m + self.origin_m[0]).reshape(-1)
        self._nearest_y = ((nearest[0] + 0.5) * self.cell_m + self.origin_m[1]).reshape(-1)
        self._bounds: dict[float, tuple[np.ndarray, np.ndarray]] = {}  # _cell_bounds' tables by radius

    @classmethod
    def of(cls, centres_m: np.ndarray, origin_m: tuple[float, float], cell_m: float, rows: int, cols: int
           ) -> LatticeDiscs | None:
        """The lattice of ``centres_m`` ((N, 2), N >= 1, world frame) on the grid, or None if a centre is not a
        cell's centre of it."""
        centres = np.asarray(centres_m, dtype=float).reshape(-1, 2)
        if not len(centres):
            return None
        origin = np.array(origin_m, dtype=float)
        index = np.rint((centres - origin) / cell_m - 0.5).astype(np.int64)                 # (N, 2) col, row
        if (index < 0).any() or (index[:, 0] >= cols).any() or (index[:, 1] >= rows).any() or \
                not np.array_equal((index + 0.5) * cell_m + origin, centres):
            return None
        occupied = np.zeros((rows, cols), dtype=bool)
        occupied[index[:, 1], index[:, 0]] = True
        return cls(occupied, (float(origin[0]), float(origin[1])), cell_m)

    def settled(self, wx: np.ndarray, wy: np.ndarray, radius_m: float) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                                                  np.ndarray]:
        """For points (world frame, flat): (surely outside every disc's ``radius_m``, surely inside the nearest
        one's, that nearest centre's x and y where inside): outside when a cell's distance less the point's
        offset from the cell's centre (a lower bound of the distance to any centre) exceeds the radius by
        :data:`BAND_M`, inside when the distance to a cell's nearest centre (an upper bound) falls short of it by
        as much.  First by the point's cell alone, the offset taken at its largest (half a cell diagonal: a
        table per radius), then for the points left with their own offset, then with the eight cells around.
        Points off the grid are neither."""
        x0, y0 = self.origin_m
        cell = self.cell_m
        col = np.floor((wx - x0) / cell)
        row = np.floor((wy - y0) / cell)
        if len(col) and col.min() >= 0 and row.min() >= 0 and col.max() < self.cols and row.max() < self.rows:
            on = None  # every point on the grid (the usual case)
            index = row.astype(np.int64) * self.cols + col.astype(np.int64)
        else:
            on = (col >= 0) & (col < self.cols) & (row >= 0) & (row < self.rows)
            index = np.where(on, row, 0).astype(np.int64) * self.cols + np.where(on, col, 0).astype(np.int64)
        far, close = self._cell_bounds(radius_m)
        outside, inside = far.take(index), close.take(index)
        if on is not None:
            outside &= on
            inside &= on
        nx, ny = np.zeros(len(index)), np.zeros(len(index))
        sure = np.flatnonzero(inside)
        nx[sure], ny[sure] = self._nearest_x.take(index[sure]), self._nearest_y.take(index[sure])
        rest = np.flatnonzero(~(outside | inside) if on is None else on & ~outside & ~inside)
        if len(rest):  # the point's own offset and its cell's nearest centre
            px, py, at = wx[rest], wy[rest], index[rest]
            offset = np.hypot(px - ((col[rest] + 0.5) * cell + x0), py - ((row[rest] + 0.5) * cell + y0))
            out = self._distance.take(at) - offset > radius_m + BAND_M
            ax, ay = self._nearest_x.take(at), self._nearest_y.take(at)
            into = ~out & (np.hypot(px - ax, py - ay) < radius_m - BAND_M)
            outside[rest], inside[rest], nx[rest], ny[rest] = out, into, ax, ay
            rest = rest[~out & ~into]
        if len(rest):  # the eight cells around too
            px, py = wx[rest, None], wy[rest, None]
            rc = np.clip(row[rest, None].astype(np.int64) + _AROUND[0], 0, self.rows - 1)     # (U, 9)
            cc = np.clip(col[rest, None].astype(np.int64) + _AROUND[1], 0, self.cols - 1)
            around = rc * self.cols + cc
            lower = (self._distance.take(around) - np.hypot(px - ((cc + 0.5) * cell + x0),
                                                            py - ((rc + 0.5) * cell + y0))).max(axis=1)
            ax, ay = self._nearest_x.take(around), self._nearest_y.take(around)
            d = np.hypot(px - ax, py - ay)
            k = d.argmin(axis=1)
            rows = np.arange(len(rest))
            outside[rest] = lower > radius_m + BAND_M
            inside[rest] = d[rows, k] < radius_m - BAND_M
            nx[rest], ny[rest] = ax[rows, k], ay[rows, k]
        return outside, inside, nx, ny

    def _cell_bounds(self, radius_m: float) -> tuple[np.ndarray, np.ndarray]:
        """Per cell (flat): every point in it is surely outside ``radius_m`` of every centre (its distance less half
        a diagonal exceeds the radius by :data:`BAND_M`), or surely inside its nearest centre's (its distance plus
        half a diagonal falls short by as much).  Kept for the last two radii asked."""
        bounds = self._bounds.get(radius_m)
        if bounds is None:
            half_diagonal = self.cell_m * math.sqrt(0.5)
            bounds = (self._distance - half_diagonal > radius_m + BAND_M,
                      self._distance + half_diagonal < radius_m - BAND_M)
            if len(self._bounds) >= 2:
                self._bounds.pop(next(iter(self._bounds)))
            self._bounds[radius_m] = bounds
        return bounds


def lattice_inside_any(lattice: LatticeDiscs, x0: float, y0: float, c: float, s: float, px: np.ndarray,
                       py: np.ndarray, ox: np.ndarray, oy: np.ndarray, radius_m: float, centre_radius_m: float,
                       near_m: float) -> np.ndarray:
    """:func:`inside_any` ``(px, py, ox, oy, radius_m)`` bit for bit, for points and discs in the frame of a
    robot at ``(x0, y0)`` heading ``(c, s)`` = (cos, sin), where the discs are exactly the lattice's centres
    ``(cx, cy)`` with ``np.hypot(cx - x0, cy - y0) - centre_radius_m <= near_m`` (as
    :meth:`controllers.prediction.LocalObstacles.near` keeps them), turned into that frame.  The lattice
    settles most points in the world frame (:meth:`LatticeDiscs.settled`: a point inside counts only if the
    centre found is one of those kept); :func:`inside_any` decides the rest.  The band of
    :data:`BAND_M` covers the frames' rounding (~1e-14 m)."""
    outside, inside, nx, ny = lattice.settled(x0 + c * px - s * py, y0 + s * px + c * py, radius_m)
    sure = np.flatnonzero(inside)
    inside[sure] = np.hypot(nx[sure] - x0, ny[sure] - y0) - centre_radius_m <= near_m
    open_ = np.flatnonzero(~(outside | inside))
    if len(open_):
        inside[open_] = inside_any(px[open_], py[open_], ox, oy, np.full(len(ox), radius_m))
    return inside


_AROUND = np.array([[-1, -1, -1, 0, 0, 0, 1, 1, 1], [-1, 0, 1, -1, 0, 1, -1, 0, 1]])  # (row, col) offsets
