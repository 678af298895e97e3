"""A scenario's optional ``[map]`` table (a Moving AI ``.map`` file and its cell size) and the grid's size.

Read with the one TOML reader (:mod:`swarmnav.models.toml_table`): every problem names the file and the
field (``map.pairs[2]``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path as FilePath

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario_limits import MAX_GRID_CELLS, MIN_LENGTH_M
from swarmnav.models.toml_table import TomlTable, fail, within
from swarmnav.models.world import Box, OccupancyGrid

MAPS_DIR = FilePath(__file__).resolve().parent / "maps"


@dataclass(frozen=True)
class MapSection:
    """A read ``[map]``: its merged boxes, its world grid before inflation, its cell size and start/goal pairs."""

    boxes: tuple[Box, ...]
    grid: OccupancyGrid
    cell_m: float
    pairs: tuple[tuple[int, int, int, int], ...]


def read_map_section(top: TomlTable, scenario_dir: FilePath, width_m: float, height_m: float) -> MapSection | None:
    """The optional ``[map]`` table (None without one).

    ``file`` is looked up beside the scenario (``scenario_dir`` for a text with no file), then under
    ``models/maps/``.  The map must span the arena exactly (map cell (0, 0) of the file is the top-left
    corner).  Occupied cells become merged box obstacles.  ``pairs`` optionally lists [x0, y0, x1, y1]
    start/goal cells (column, row counted from the bottom) for ``swarmnav bench grid``.
    """
    if not top.has("map"):
        return None
    from swarmnav.models.grid_map import map_to_grid, merge_boxes, read_map

    source = top.source
    t = top.table("map")
    name = t.string("file")
    cell_m = t.number("cell_m", bounds=within(MIN_LENGTH_M))
    pairs = t.raw("pairs", [])
    t.close()
    if not isinstance(pairs, list) or not all(
            isinstance(p, list) and len(p) == 4 and all(isinstance(v, int) and not isinstance(v, bool) for v in p)
            for p in pairs):
        t.fail("pairs", "expected an array of [x0, y0, x1, y1] integer cells")
    here = FilePath(source).resolve().parent if source and not source.startswith("<") else scenario_dir
    path = next((c for c in (here / name, MAPS_DIR / name) if c.is_file()), None)
    if path is None:
        t.fail("file", f"no map file {name!r} beside the scenario or under models/maps/")
    try:
        occupied = read_map(path, MAX_GRID_CELLS)
    except ConfigError as exc:
        t.fail("file", f"{path.name}: {exc.field}: {exc.problem}")
    rows, cols = occupied.shape
    if rows * cols > MAX_GRID_CELLS:
        t.fail("file", f"a {cols} x {rows} map has {rows * cols:,} cells (at most {MAX_GRID_CELLS:,})")
    if abs(cols * cell_m - width_m) > 1e-6 or abs(rows * cell_m - height_m) > 1e-6:
        t.fail("cell_m", f"a {cols} x {rows} map at {cell_m:g} m per cell spans {cols * cell_m:g} x "
                         f"{rows * cell_m:g} m, not the arena's {width_m:g} x {height_m:g} m")
    for i, (x0, y0, x1, y1) in enumerate(pairs):
        for x, y in ((x0, y0), (x1, y1)):
            if not (0 <= x < cols and 0 <= y < rows):
                t.fail(f"pairs[{i}]", f"cell ({x}, {y}) is outside the {cols} x {rows} map")
    grid = map_to_grid(occupied, cell_m)
    return MapSection(merge_boxes(grid.occupied, cell_m), grid, cell_m, tuple(tuple(p) for p in pairs))


def check_grid_size(width_m: float, height_m: float, cell_m: float, field_name: str, source: str | None,
                    limit: int = MAX_GRID_CELLS) -> None:
    """The planning grid of the arena at ``cell_m``, against :data:`MAX_GRID_CELLS` (or ``limit``)."""
    cells = math.ceil(min(width_m / cell_m, 1e300)) * math.ceil(min(height_m / cell_m, 1e300))
    if cells > limit:
        smallest = math.sqrt(width_m * height_m / limit)
        fail(field_name, f"a {width_m:g} x {height_m:g} m arena at {cell_m:g} m per cell needs "
                         f"{min(cells, 1e300):.4g} grid cells (at most {limit:,}; a cell of about "
                         f"{smallest:.3g} m or more fits)", source)
