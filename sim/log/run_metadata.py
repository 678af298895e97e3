"""The ``run`` metadata record of a log, checked once when the log is read (a log is data from elsewhere).

Every reader (``log info``, ``plot``, ``replay --video``, ``replay --verify``) takes the values from
:func:`checked_run_metadata`, so a seed that is ``"nan"``, an obstacle entry without its ``size_m`` or an
arena that is a string is one :class:`LogError` naming the log and the field, the same for all of them.
"""

from __future__ import annotations

import math
from typing import Any

from swarmnav.models.contained_files import loads_json
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import MAP_KNOWLEDGE, POSE_SOURCES
from swarmnav.models.scenario_limits import MAX_MOVING_OBSTACLES, MAX_SENSORS, MAX_STATIC_OBSTACLES
from swarmnav.log.records import LogError

MAX_SEED = 2**63 - 1


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _numbers(value: Any, length: int | None = None, most: int = 1_000_000) -> bool:
    return (isinstance(value, list) and all(_number(v) for v in value)
            and (len(value) == length if length is not None else len(value) <= most))


def _obstacle(value: Any) -> bool:
    return (isinstance(value, dict) and isinstance(value.get("entity_id"), str)
            and value.get("shape") in ("cylinder", "box", "disc") and _numbers(value.get("size_m"), most=3)
            and len(value["size_m"]) >= 1 and _numbers(value.get("position_m"), most=3)
            and len(value["position_m"]) >= 2 and isinstance(value.get("moving"), bool))


# key -> (what it must be, the check)
RUN_FIELDS = {
    "seed": ("an integer seed from 0 to 2**63 - 1",
             lambda v: isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= MAX_SEED),
    "world_seed": ("an integer seed from 0 to 2**63 - 1",
                   lambda v: isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= MAX_SEED),
    "clearance_m": ("a finite number of at least 0", lambda v: _number(v) and v >= 0),
    "map_knowledge": (f"one of {', '.join(MAP_KNOWLEDGE)}", lambda v: v in MAP_KNOWLEDGE),
    "pose_source": (f"one of {', '.join(POSE_SOURCES)}", lambda v: v in POSE_SOURCES),
    "control_dt_s": ("a positive finite number", lambda v: _number(v) and v > 0),
    "physics_dt_s": ("a positive finite number", lambda v: _number(v) and v > 0),
    "sensor_angles_rad": (f"a list of at most {MAX_SENSORS} numbers", lambda v: _numbers(v, most=MAX_SENSORS)),
    "sensor_range_m": ("a finite number of at least 0", lambda v: _number(v) and v >= 0),
    "sensor_offset_m": ("a finite number of at least 0", lambda v: _number(v) and v >= 0),
    "sensor_height_m": ("a finite number", _number),
    "arena_size_m": ("two positive numbers", lambda v: _numbers(v, 2) and min(v) > 0),
    "obstacles": ("a list of obstacles, each with entity_id, shape, size_m, position_m and moving",
                  lambda v: isinstance(v, list) and len(v) <= MAX_STATIC_OBSTACLES + MAX_MOVING_OBSTACLES
                  and all(_obstacle(o) for o in v)),
}


def checked_run_metadata(path: str, record: dict[str, str]) -> dict[str, Any]:
    """The ``run`` record's values, JSON-decoded and checked (absent keys stay absent).

    Raises:
        LogError: a value that is not JSON or not what :data:`RUN_FIELDS` says, naming ``run.KEY``.
    """
    values: dict[str, Any] = {}
    for key, text in record.items():
        if key not in RUN_FIELDS:
            continue
        what, ok = RUN_FIELDS[key]
        try:
            value = loads_json(text, path, f"run.{key}")
        except ConfigError as exc:
            raise LogError(path, f"metadata run.{key}: {exc.problem}") from None
        if not ok(value):
            raise LogError(path, f"metadata run.{key}: expected {what}, got {text[:60]!r}")
        values[key] = value
    return values
