"""A Gazebo world's obstacles as a scenario file (``swarmnav scenarios import``, ``swarmnav.import_world``).

A scenario's arena is ``[0, width] x [0, height]``; a world file has its own origin.  The import shifts every
point by the same offset, ``arena = world - origin`` with ``origin`` the whole metres below the obstacles,
start and goal less :data:`MARGIN_M`; the arena spans them plus the margin, without walls (a Gazebo world has
none but its own obstacles).  The origin is written in the file's description and a comment, so a point of
the run reads back in the world's frame.  Start and goal are given in the world's frame; by default the BARN
challenge's (Perille et al. 2020, the challenge's ``run.py``): start (-2.25, 3.0) heading 90 degrees, goal
(-2.25, 13.0) within 1 m, time limit 100 s.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path as FilePath
from typing import Any

from swarmnav.models.errors import ConfigError
from swarmnav.models.gazebo_world import GazeboWorld, read_world

MARGIN_M = 1.0
# The BARN challenge's protocol (its run.py): start pose, goal, goal radius, time limit.
BARN_START = (-2.25, 3.0, 90.0)    # x, y (metres, world frame), heading (degrees)
BARN_GOAL = (-2.25, 13.0, 1.0)     # x, y (metres, world frame), tolerance (metres)
BARN_TIME_LIMIT_S = 100.0


@dataclass(frozen=True)
class ImportSettings:
    """What a world file does not say: the scenario's name, endpoints (world frame) and the robot's tables.

    ``tables``: more top-level TOML tables of the scenario as plain dicts (``robot``, ``sensors``,
    ``planner``, ``navigator``, ``sim``, ...), written as inline tables in the order given.
    """

    name: str
    start: tuple[float, float, float] = BARN_START
    goal: tuple[float, float, float] = BARN_GOAL
    time_limit_s: float = BARN_TIME_LIMIT_S
    description: str = ""
    seed: int = 0
    tables: dict[str, dict[str, Any]] = field(default_factory=dict)


@dataclass(frozen=True)
class ImportedWorld:
    """The scenario text and the world-frame point of the arena's (0, 0)."""

    text: str
    origin_m: tuple[float, float]
    world: GazeboWorld


def scenario_from_world(world: GazeboWorld, settings: ImportSettings) -> ImportedWorld:
    """The scenario TOML of ``world``'s obstacles with ``settings`` (see the module docstring)."""
    xs = [settings.start[0], settings.goal[0]]
    ys = [settings.start[1], settings.goal[1]]
    tol = settings.goal[2]
    lows_x = [c.x_m - c.radius_m for c in world.cylinders] + [b.x_min_m for b in world.blocks] + xs
    lows_y = [c.y_m - c.radius_m for c in world.cylinders] + [b.y_min_m for b in world.blocks] + ys
    highs_x = [c.x_m + c.radius_m for c in world.cylinders] + [b.x_max_m for b in world.blocks] + xs
    highs_y = [c.y_m + c.radius_m for c in world.cylinders] + [b.y_max_m for b in world.blocks] + ys
    ox = math.floor(min(lows_x + [xs[1] - tol]) - MARGIN_M)
    oy = math.floor(min(lows_y + [ys[1] - tol]) - MARGIN_M)
    width = math.ceil(max(highs_x + [xs[1] + tol]) + MARGIN_M - ox)
    height = math.ceil(max(highs_y + [ys[1] + tol]) + MARGIN_M - oy)
    description = settings.description or (
        f"Imported from {FilePath(world.source).name}: {len(world.cylinders)} cylinders, {len(world.blocks)} boxes")
    description += f"; arena (0, 0) is the world's ({ox:g}, {oy:g})"
    lines = [f"# {description}", f"# world frame = arena frame + ({ox:g}, {oy:g})",
             f"name = {_value(settings.name)}", f"description = {_value(description)}",
             f"seed = {int(settings.seed)}", f"time_limit_s = {_value(float(settings.time_limit_s))}",
             f"arena = {{ width_m = {_value(float(width))}, height_m = {_value(float(height))}, walls = false }}",
             f"start = {{ x = {_value(settings.start[0] - ox)}, y = {_value(settings.start[1] - oy)}, "
             f"heading_deg = {_value(float(settings.start[2]))} }}",
             f"goal = {{ x = {_value(settings.goal[0] - ox)}, y = {_value(settings.goal[1] - oy)}, "
             f"tolerance_m = {_value(float(tol))} }}"]
    lines += [f"{key} = {_inline(value)}" for key, value in settings.tables.items()]
    for c in world.cylinders:
        lines += ["", "[[obstacles]]", f"# {c.model}", f"x = {_value(c.x_m - ox)}", f"y = {_value(c.y_m - oy)}",
                  f"radius_m = {_value(c.radius_m)}", f"height_m = {_value(c.height_m)}"]
    for b in world.blocks:
        lines += ["", "[[boxes]]", f"# {b.model}", f"x_min_m = {_value(b.x_min_m - ox)}",
                  f"y_min_m = {_value(b.y_min_m - oy)}", f"x_max_m = {_value(b.x_max_m - ox)}",
                  f"y_max_m = {_value(b.y_max_m - oy)}"]
    return ImportedWorld("\n".join(lines) + "\n", (float(ox), float(oy)), world)


def import_world(path: str | FilePath, settings: ImportSettings | None = None) -> ImportedWorld:
    """Read a Gazebo world file and make its scenario; the text is checked by loading it back.

    Raises:
        ConfigError: a bad world file (:func:`models.gazebo_world.read_world`) or a scenario that does not
            load (an endpoint inside an obstacle, an unknown robot model, ...), naming the file and field.
    """
    from swarmnav.models.scenario import parse_scenario
    world = read_world(path)
    if settings is None:
        settings = ImportSettings(name=_stem(path))
    imported = scenario_from_world(world, settings)
    try:
        parse_scenario(imported.text, str(path))
    except ConfigError as exc:
        raise ConfigError(f"imported scenario: {exc.field}", exc.problem, str(path)) from None
    return imported


def _stem(path: str | FilePath) -> str:
    name = FilePath(path).name
    for suffix in (".gz", ".world", ".sdf"):
        name = name.removesuffix(suffix)
    return name[:64] or "world"


def _value(v: Any) -> str:
    """A TOML scalar: a float by its shortest round-trip text, a string JSON-quoted (valid TOML)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        text = repr(v)
        return text if any(ch in text for ch in ".en") else text + ".0"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return _inline(v)
    raise TypeError(f"no TOML text for {type(v).__name__}")


def _inline(table: dict[str, Any]) -> str:
    return "{ " + ", ".join(f"{k} = {_value(v)}" for k, v in table.items()) + " }"


__all__ = ["BARN_GOAL", "BARN_START", "BARN_TIME_LIMIT_S", "ImportSettings", "ImportedWorld", "import_world",
           "scenario_from_world"]
