"""A uniform grid of cells, each listing the discs that may contain a point of it.

The obstacle penalty of Kamil et al. (2020), Eqs. (3)-(5), is a sum over every
(sample, disc) pair, but a pair contributes only when the sample lies inside the
disc.  :class:`DiscCells` finds the few pairs that can: it maps a point to its
cell with two multiplications, and the cell's row of :attr:`DiscCells.table`
holds every disc whose bounding square (grown by a rounding margin) meets the
cell, padded with a *sentinel disc* far away whose term is exactly 0.  A point
outside the grid lies in no disc; it is clamped into a border cell only to keep
the index valid.

Choices: the grid covers the union of the discs' squares and a free ring of
cells around it; the cell side is half the median disc radius, grown until the grid has at most :data:`MAX_CELLS` cells;
cells that no disc meets are marked free in :attr:`DiscCells.occupied`, so a
sample in a free cell is dropped with one lookup.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: Most cells of the grid.
MAX_CELLS = 1 << 16
#: Centre coordinate of the sentinel disc that pads the table (its squared distance stays finite).
SENTINEL_CENTRE_M = 1e150


@dataclass(frozen=True, eq=False)
class DiscCells:
    """Cells over a set of discs (see the module docstring).

    Attributes:
        centres_m: (C, 2) disc centres.
        radii_m: (C,) radii.
        origin_m: (2,) lower-left corner of the grid.
        cell_m: side of a cell.
        shape: (nx, ny) cells per axis.
        occupied: (nx * ny,) whether any disc meets the cell (index ``ix * ny + iy``).
        table: (M, nx * ny) disc indices of each cell (a column), padded with ``C`` (the sentinel).
        centre_x, centre_y, inverse_radius: (C + 1,) per disc, the sentinel last.
    """

    centres_m: np.ndarray
    radii_m: np.ndarray
    origin_m: np.ndarray = field(init=False)
    cell_m: float = field(init=False)
    shape: tuple[int, int] = field(init=False)
    occupied: np.ndarray = field(init=False)
    table: np.ndarray = field(init=False)
    centre_x: np.ndarray = field(init=False)
    centre_y: np.ndarray = field(init=False)
    inverse_radius: np.ndarray = field(init=False)
    _scaled_origin: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        centres = np.asarray(self.centres_m, dtype=float).reshape(-1, 2)
        radii = np.asarray(self.radii_m, dtype=float).reshape(-1)
        count = centres.shape[0]
        set_ = object.__setattr__
        set_(self, "centres_m", centres)
        set_(self, "radii_m", radii)
        set_(self, "centre_x", np.append(centres[:, 0], SENTINEL_CENTRE_M))
        set_(self, "centre_y", np.append(centres[:, 1], SENTINEL_CENTRE_M))
        set_(self, "inverse_radius", np.append(1.0 / radii, 1.0) if count else np.ones(1))
        if count == 0:
            set_(self, "origin_m", np.zeros(2))
            set_(self, "cell_m", 1.0)
            set_(self, "shape", (1, 1))
            set_(self, "occupied", np.zeros(1, dtype=bool))
            set_(self, "table", np.zeros((1, 1), dtype=np.intp))
            set_(self, "_scaled_origin", np.zeros((2, 1, 1)))
            return
        low = (centres - radii[:, None]).min(axis=0)
        high = (centres + radii[:, None]).max(axis=0)
        extent = np.maximum(high - low, 1e-9)
        cell = max(0.5 * float(np.median(radii)), 1e-9)
        while (math.ceil(extent[0] / cell) + 2) * (math.ceil(extent[1] / cell) + 2) > MAX_CELLS:
            cell *= 1.5
        # A free ring of cells around the discs' union: points clamped into it are dropped.
        low = low - cell
        nx, ny = (int(math.ceil(e / cell)) + 2 for e in extent)
        # Each disc's square grown by a margin far above the rounding of cells_of().
        grown = radii[:, None] + 1e-9 * max(cell, float(np.abs(np.concatenate([low, high])).max()))
        first = np.clip(np.floor((centres - grown - low) / cell), 0, [nx - 1, ny - 1]).astype(np.intp)
        last = np.clip(np.floor((centres + grown - low) / cell), 0, [nx - 1, ny - 1]).astype(np.intp)
        spans_x = last[:, 0] - first[:, 0] + 1
        spans_y = last[:, 1] - first[:, 1] + 1
        per_disc = spans_x * spans_y
        disc = np.repeat(np.arange(count), per_disc)
        offset = np.arange(disc.size) - np.repeat(np.cumsum(per_disc) - per_disc, per_disc)
        cell_x = first[disc, 0] + offset // spans_y[disc]
        cell_y = first[disc, 1] + offset % spans_y[disc]
        flat = cell_x * ny + cell_y
        order = np.lexsort((disc, flat))
        flat, disc = flat[order], disc[order]
        per_cell = np.bincount(flat, minlength=nx * ny)
        width = int(per_cell.max())
        table = np.full((width, nx * ny), count, dtype=np.intp)
        rank = np.arange(flat.size) - np.repeat(np.cumsum(per_cell) - per_cell, per_cell)
        table[rank, flat] = disc
        set_(self, "origin_m", low)
        set_(self, "cell_m", cell)
        set_(self, "shape", (nx, ny))
        set_(self, "occupied", per_cell > 0)
        set_(self, "table", table)
        set_(self, "_scaled_origin", (low / cell).reshape(2, 1, 1))

    def cells_of(self, block: np.ndarray) -> np.ndarray:
        """Flat cell index ``ix * ny + iy`` of the points of a (2, ...) array (x then y), shape
        ``block.shape[1:]``.

        Not clamped: a point outside the grid gets some index, possibly out of range
        (look it up with ``take(..., mode="clip")``), and so some cell; that is harmless,
        since a point outside the grid lies in no disc and each of its terms is 0.
        Points inside the grid get their own cell (to rounding, which the discs'
        grown squares absorb)."""
        scaled = np.multiply(block, 1.0 / self.cell_m)
        scaled -= self._scaled_origin
        index = scaled.astype(np.intp)
        flat = index[0]
        flat *= self.shape[1]
        flat += index[1]
        return flat
