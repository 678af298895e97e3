"""A scenario's ``[[boxes]]``: static axis-aligned boxes given by their corners (``scenarios import`` writes
them for a Gazebo world's box geometry), beside the boxes a ``[map]`` makes.

Each is ``x_min_m``, ``y_min_m``, ``x_max_m``, ``y_max_m`` in the arena, with min < max; read with the one TOML
reader, every problem naming the file and the field (``boxes[2].x_max_m``).
"""

from __future__ import annotations

from swarmnav.models.scenario_limits import MIN_LENGTH_M
from swarmnav.models.toml_table import TomlTable
from swarmnav.models.world import Box

MAX_BOXES = 100_000


def read_boxes(top: TomlTable, width_m: float, height_m: float) -> tuple[Box, ...]:
    tables = top.tables("boxes", [])
    if len(tables) > MAX_BOXES:
        top.fail("boxes", f"{len(tables):,} boxes (at most {MAX_BOXES:,})")
    out = []
    for t in tables:
        corners = [t.number(key) for key in ("x_min_m", "y_min_m", "x_max_m", "y_max_m")]
        t.close()
        x0, y0, x1, y1 = corners
        for key, low, high in (("x_max_m", x0, x1), ("y_max_m", y0, y1)):
            if not high - low >= MIN_LENGTH_M:
                t.fail(key, f"must exceed the min corner by at least {MIN_LENGTH_M:g} m, got {low:g} .. {high:g}")
        if not (0.0 <= x0 and x1 <= width_m and 0.0 <= y0 and y1 <= height_m):
            t.fail("x_min_m", f"the box ({x0:g}, {y0:g}) .. ({x1:g}, {y1:g}) must lie in the arena "
                              f"[0, {width_m:g}] x [0, {height_m:g}]")
        out.append(Box(x0, y0, x1, y1))
    return tuple(out)
