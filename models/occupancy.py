"""A log-odds occupancy grid built from a 2-D laser: what the robot knows of the static world when it is
given no map (``knowledge = { map = "unknown" }``).

The classic inverse sensor model of Thrun, Burgard & Fox, *Probabilistic Robotics* (2005), Table 9.1 and
eq. 9.7: every scan adds ``l_occ`` to the cell of each hit and ``l_free`` to the cells each beam crossed
before it, the log odds clamped to ``[l_min, l_max]`` (as ROS' costmaps and OctoMap clamp, so a cell that
was seen occupied can be cleared again).  Ours, stated:

* A beam clears (marks free) at most ``raytrace_max_m`` from the laser (Nav2's obstacle layer
  ``raytrace_max_range``, 3.0 m by default) and marks a hit at most ``obstacle_max_m`` away (Nav2's
  ``obstacle_max_range``, 2.5 m); a beam with nothing in range clears to the sensor's range or
  ``raytrace_max_m``, whichever is nearer.
* The cells a beam crosses are those of a DDA line from its origin's cell (one per step along the major
  axis), each counted once per scan; the hit's cell gets ``l_occ`` after the free update, so a cell both
  crossed and hit ends occupied.
* A cell is occupied when its log odds exceed ``occupied_above`` (0.85: p = 0.7); never-seen cells have
  log odds 0 (p = 0.5) and count as free (Nav2's ``allow_unknown``).

No MuJoCo here: plain arrays in, the grid out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarmnav.models.world import Rect

ANGLE_BINS = 3600  # world directions the beams' cell lists are tabulated for
MAX_MAP_CELLS = 4_000_000  # a sensed map's cells (the log-odds grid and its masks: a few tens of MB at most)


@dataclass(frozen=True)
class SensorModel:
    """The inverse sensor model's numbers (log odds, metres)."""

    l_occ: float = 0.85
    l_free: float = -0.4
    l_min: float = -2.0
    l_max: float = 3.5
    occupied_above: float = 0.85
    raytrace_max_m: float = 3.0
    obstacle_max_m: float = 2.5


class LogOddsGrid:
    """The grid over ``bounds`` at ``cell_m`` (rows grow with y, columns with x, as
    :class:`models.world.OccupancyGrid`), updated by :meth:`integrate` one scan at a time.

    Beams are traversed one cell per step along their major axis (a DDA line from the cell of the beam's
    origin), so a scan of K beams costs K x (reach / cell) index operations, all in a few NumPy calls; the
    grid is kept inside a border as wide as the reach, so no index needs a bounds check.

    Raises:
        ValueError: more than :data:`MAX_MAP_CELLS` cells.
    """

    def __init__(self, bounds: Rect, cell_m: float, model: SensorModel = SensorModel()):
        self.cols = max(1, int(math.ceil(bounds.width_m / cell_m - 1e-9)))
        self.rows = max(1, int(math.ceil(bounds.height_m / cell_m - 1e-9)))
        if self.rows * self.cols > MAX_MAP_CELLS:
            raise ValueError(f"{self.rows} x {self.cols} cells (at most {MAX_MAP_CELLS:,})")
        self.bounds, self.cell_m, self.model = bounds, float(cell_m), model
        self.origin_m = (bounds.x_min_m, bounds.y_min_m)
        self.steps = int(math.ceil(model.raytrace_max_m / self.cell_m)) + 1
        pad = self.pad = self.steps + 1
        self._padded = np.zeros((self.rows + 2 * pad, self.cols + 2 * pad), dtype=np.float32)
        self.width = self._padded.shape[1]
        self._flat = self._padded.reshape(-1)
        self.log_odds = self._padded[pad:pad + self.rows, pad:pad + self.cols]  # a view
        self._js = np.arange(self.steps)
        # Each beam's cells as flat offsets from its origin's cell, tabulated per world direction
        # (ANGLE_BINS of them: 0.1 degree, 5 mm sideways at 3 m): one gather per scan instead of the arithmetic.
        bins = 2.0 * math.pi * np.arange(ANGLE_BINS) / ANGLE_BINS
        cos, sin = np.cos(bins), np.sin(bins)
        self._major = np.maximum(np.abs(cos), np.abs(sin))
        self._table = (np.rint(np.outer(sin / self._major, self._js)).astype(np.int64) * self.width
                       + np.rint(np.outer(cos / self._major, self._js)).astype(np.int64))
        self.scans = 0

    def integrate(self, x_m: float, y_m: float, heading_rad: float, ranges_m: np.ndarray,
                  angles_rad: np.ndarray, offset_m: float = 0.0, range_m: float = math.inf) -> None:
        """One scan: beams ``angles_rad`` (base frame) from the base at (x, y, heading), each starting
        ``offset_m`` out from it, reading ``ranges_m`` (``inf``: nothing within the sensor's ``range_m``, so
        the beam clears up to it, or to ``raytrace_max_m`` if nearer)."""
        model, cell, pad, width = self.model, self.cell_m, self.pad, self.width
        world = heading_rad + np.asarray(angles_rad, dtype=float)
        cos, sin = np.cos(world), np.sin(world)
        ranges = np.asarray(ranges_m, dtype=float)
        ox, oy = x_m + offset_m * cos, y_m + offset_m * sin  # (K,) beam origins
        col0 = np.floor((ox - self.origin_m[0]) / cell).astype(np.int64) + pad
        row0 = np.floor((oy - self.origin_m[1]) / cell).astype(np.int64) + pad
        bins = np.rint(world * (ANGLE_BINS / (2.0 * math.pi))).astype(np.int64) % ANGLE_BINS
        # Steps before the hit (or the reach): step j of a beam lies j * cell / major along it.
        free_m = np.minimum(ranges, min(model.raytrace_max_m, range_m))
        n = np.minimum((free_m * self._major[bins] / cell).astype(np.int64), self.steps)
        cells = self._table[bins][self._js[None, :] < n[:, None]] + np.repeat(row0 * width + col0, n)
        flat = self._flat
        # Once per distinct cell (a fancy-index write keeps one value per index), clamped as it goes.
        values = flat[cells]
        values += model.l_free
        np.maximum(values, model.l_min, out=values)
        flat[cells] = values
        hit = ranges <= model.obstacle_max_m
        if hit.any():
            # Half a millimetre past the surface: the cell of the obstacle, not of the free space before it.
            r = ranges[hit] + 5e-4
            hc = np.floor((ox[hit] + r * cos[hit] - self.origin_m[0]) / cell).astype(np.int64) + pad
            hr = np.floor((oy[hit] + r * sin[hit] - self.origin_m[1]) / cell).astype(np.int64) + pad
            cells = hr * width + hc
            flat[cells] = np.minimum(flat[cells] + model.l_occ, model.l_max)
        self.scans += 1

    @property
    def occupied(self) -> np.ndarray:
        """(rows, cols) bool: cells believed occupied."""
        return self.log_odds > self.model.occupied_above

    @property
    def known(self) -> np.ndarray:
        """(rows, cols) bool: cells ever updated (seen free or occupied)."""
        return self.log_odds != 0.0

    def probabilities(self) -> np.ndarray:
        """(rows, cols) occupancy probabilities, 0.5 where never seen."""
        return 1.0 - 1.0 / (1.0 + np.exp(self.log_odds.astype(float)))
