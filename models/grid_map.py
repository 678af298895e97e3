"""Moving AI grid maps and scenarios, and merging map cells into boxes.

The format (N. Sturtevant, "Benchmarks for Grid-Based Pathfinding", IEEE TCIAIG
4(2), 2012): a header ``type octile`` / ``height H`` / ``width W`` / ``map``,
then H rows of W characters, ``.`` ``G`` ``S`` passable and ``@`` ``O`` ``T``
``W`` not.  The first row of the file is the *top* of the map, while an
:class:`~models.world.OccupancyGrid` has rows growing with y, so
:func:`map_to_grid` flips the rows.  Scenario lines are tab-separated: bucket,
map, width, height, start x, start y, goal x, goal y, optimal length, with
(x, y) = (column, row from the top).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path as FilePath

import numpy as np

from swarmnav.models.errors import ConfigError
from swarmnav.models.world import Box, OccupancyGrid, Rect, rasterise

PASSABLE = frozenset(".GS")
BLOCKED = frozenset("@OTW")
BENCHMARK_ENV = "SWARMNAV_MOVINGAI_DIR"


@dataclass(frozen=True)
class MovingAIScenario:
    """One scenario line.  Cells are (column, row) counted from the top-left, as in the file."""

    bucket: int
    map_name: str
    width: int
    height: int
    start_col: int
    start_row: int
    goal_col: int
    goal_row: int
    optimal_length: float

    def start_cell(self) -> tuple[int, int]:
        """(row, col) in file order (row 0 at the top)."""
        return self.start_row, self.start_col

    def goal_cell(self) -> tuple[int, int]:
        return self.goal_row, self.goal_col


def parse_map(text: str, source: str = "<map>", max_cells: int | None = None) -> np.ndarray:
    """Occupied cells of a Moving AI map, in file order (row 0 = the file's first map row).

    Every row is checked before the grid is allocated, so a header that
    declares more cells than the file holds (or than ``max_cells``) costs nothing.

    Raises:
        ConfigError: a malformed header, a wrong row count or width, an unknown
            character, or more than ``max_cells`` cells.
    """
    lines = text.splitlines()
    header: dict[str, str] = {}
    i = 0
    while i < len(lines) and lines[i].strip().lower() != "map":
        parts = lines[i].split()
        if len(parts) == 2:
            header[parts[0].lower()] = parts[1]
        elif parts:
            raise ConfigError(f"line {i + 1}", f"unexpected header line {lines[i]!r}", source)
        i += 1
    if i == len(lines):
        raise ConfigError("map", "no 'map' line", source)
    try:
        height, width = int(header["height"]), int(header["width"])
    except (KeyError, ValueError):
        raise ConfigError("header", "needs integer 'height' and 'width'", source) from None
    if height < 1 or width < 1:
        raise ConfigError("header", f"height and width must be positive, got {height} x {width}", source)
    if max_cells is not None and height * width > max_cells:
        raise ConfigError("header", f"a {width} x {height} map has {height * width:,} cells "
                          f"(at most {max_cells:,})", source)
    rows = [line.rstrip("\r\n") for line in lines[i + 1:i + 1 + height]]
    if len(rows) != height:
        raise ConfigError("map", f"expected {height} rows, found {len(rows)}", source)
    for r, row in enumerate(rows):
        if len(row) < width:
            raise ConfigError(f"map row {r}", f"expected {width} characters, found {len(row)}", source)
    # One code point per cell, classified with NumPy rather than per character.
    codes = np.frombuffer("".join(row[:width] for row in rows).encode("utf-32-le"),
                          dtype=np.uint32).reshape(height, width)
    occupied = np.isin(codes, [ord(ch) for ch in BLOCKED])
    unknown = ~occupied & ~np.isin(codes, [ord(ch) for ch in PASSABLE])
    if unknown.any():
        r, c = np.argwhere(unknown)[0]
        raise ConfigError(f"map row {r}", f"unknown character {chr(codes[r, c])!r} at column {c}", source)
    return occupied


def read_map(path: str | os.PathLike, max_cells: int | None = None) -> np.ndarray:
    """:func:`parse_map` of a file (a text file: a binary one is a ConfigError)."""
    path = FilePath(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ConfigError("map", f"cannot be read ({exc.strerror or exc})", str(path)) from None
    except UnicodeDecodeError as exc:
        raise ConfigError("map", f"is not a text map (byte {exc.start} is not UTF-8)", str(path)) from None
    return parse_map(text, str(path), max_cells)


def format_map(occupied_file_order: np.ndarray) -> str:
    """Moving AI text of a map given in file order (row 0 at the top)."""
    occ = np.asarray(occupied_file_order, dtype=bool)
    rows = ["".join("@" if v else "." for v in row) for row in occ]
    return "\n".join(["type octile", f"height {occ.shape[0]}", f"width {occ.shape[1]}", "map", *rows]) + "\n"


def read_scenarios(path: str | os.PathLike) -> list[MovingAIScenario]:
    """Every scenario line of a ``.scen`` file; lines without 9 tab-separated fields are skipped."""
    out = []
    for line in FilePath(path).read_text(encoding="utf-8").splitlines():
        fields = line.rstrip("\r\n").split("\t")
        if len(fields) != 9:
            continue
        try:
            out.append(MovingAIScenario(int(fields[0]), fields[1], int(fields[2]), int(fields[3]),
                                        int(fields[4]), int(fields[5]), int(fields[6]), int(fields[7]),
                                        float(fields[8])))
        except ValueError:
            continue
    return out


def map_to_grid(occupied_file_order: np.ndarray, cell_m: float,
                origin_m: tuple[float, float] = (0.0, 0.0)) -> OccupancyGrid:
    """World grid of a map: rows flipped so that grid row 0 is the map's bottom row."""
    return OccupancyGrid(occupied=np.ascontiguousarray(np.asarray(occupied_file_order, dtype=bool)[::-1]),
                         cell_m=float(cell_m), origin_m=(float(origin_m[0]), float(origin_m[1])))


def file_cell_to_world_xy(col: int, row: int, height: int, cell_m: float,
                          origin_m: tuple[float, float] = (0.0, 0.0)) -> tuple[float, float]:
    """World centre of the map cell at (column, row from the top)."""
    return (origin_m[0] + (col + 0.5) * cell_m, origin_m[1] + (height - 1 - row + 0.5) * cell_m)


def merge_boxes(occupied: np.ndarray, cell_m: float,
                origin_m: tuple[float, float] = (0.0, 0.0)) -> tuple[Box, ...]:
    """Cover the occupied cells of a world grid (rows grow with y) with few disjoint boxes.

    Runs of occupied cells along each row become strips; a strip is grown
    upwards while the rows above hold the very same run.  The boxes are
    disjoint and cover exactly the occupied cells (greedy, not minimal).

    Returns:
        Boxes in metres, in row-major order of their lower-left cell.
    """
    occ = np.asarray(occupied, dtype=bool)
    rows, cols = occ.shape
    used = np.zeros_like(occ)
    boxes = []
    ox, oy = origin_m
    for r in range(rows):
        row = occ[r] & ~used[r]
        if not row.any():
            continue
        padded = np.concatenate([[False], row, [False]])
        edges = np.flatnonzero(padded[1:] != padded[:-1])
        for c0, c1 in zip(edges[0::2], edges[1::2]):
            r1 = r + 1
            while r1 < rows and occ[r1, c0:c1].all() and not used[r1, c0:c1].any():
                r1 += 1
            used[r:r1, c0:c1] = True
            boxes.append(Box(ox + c0 * cell_m, oy + r * cell_m, ox + c1 * cell_m, oy + r1 * cell_m))
    return tuple(boxes)


def benchmarks_dir() -> FilePath:
    """Where the Moving AI benchmark files live: ``$SWARMNAV_MOVINGAI_DIR``, else
    ``<repo>/../shared/benchmarks/movingai``.  It may not exist."""
    override = os.environ.get(BENCHMARK_ENV)
    if override:
        return FilePath(override)
    repo = FilePath(__file__).resolve().parent.parent
    return repo.parent / "shared" / "benchmarks" / "movingai"


def benchmark_sets(directory: FilePath | None = None) -> list[tuple[FilePath, FilePath]]:
    """(map, scen) file pairs found in the benchmark folder; empty when it is absent."""
    directory = benchmarks_dir() if directory is None else directory
    if not directory.is_dir():
        return []
    pairs = []
    for scen in sorted(directory.glob("*.scen")):
        maps = {s.map_name for s in read_scenarios(scen)}
        for name in sorted(maps):
            candidate = directory / FilePath(name).name
            if candidate.is_file():
                pairs.append((candidate, scen))
    return pairs


def inflated_map_grid(occupied: np.ndarray, cell_m: float, inflation_m: float,
                      boxes: tuple[Box, ...] | None = None,
                      origin_m: tuple[float, float] = (0.0, 0.0)) -> OccupancyGrid:
    """The planning grid of a map at its own resolution, for a robot kept ``inflation_m`` from obstacles.

    When ``inflation_m <= cell_m / 2`` the map is used as it is: a free cell's
    centre is then at least ``cell_m / 2`` from every occupied cell, and every
    legal move between free centres (no corner cutting) keeps that distance,
    so a robot of diameter up to one cell passes the map's one-cell gaps, as in
    the papers.  Wider robots get :func:`models.world.rasterise` of the
    merged boxes, which blocks every cell whose centre is within
    ``inflation_m + cell_m / sqrt(2)`` of an occupied cell.

    Args:
        occupied: (rows, cols) world grid (rows grow with y).
    """
    occ = np.asarray(occupied, dtype=bool)
    if inflation_m <= cell_m / 2.0 + 1e-12:
        return OccupancyGrid(occupied=occ.copy(), cell_m=float(cell_m), origin_m=origin_m)
    rows, cols = occ.shape
    if boxes is None:
        boxes = merge_boxes(occ, cell_m, origin_m)
    bounds = Rect(origin_m[0], origin_m[1], origin_m[0] + cols * cell_m, origin_m[1] + rows * cell_m)
    return rasterise(bounds, (), tuple(boxes), inflation_m, cell_m)
