"""The foxglove messages of a run log, built from what a recorder receives.

Pure construction, no I/O: :class:`sim.mcap_log.McapRecorder` logs them.
"""

from __future__ import annotations

import json
import math
from typing import Any

import foxglove
from foxglove.messages import (
    Color,
    CubePrimitive,
    CylinderPrimitive,
    Pose,
    Quaternion,
    SceneEntity,
    Timestamp,
    Vector3,
)

from swarmnav.sim.log_format import WORLD_FRAME, dumps
from swarmnav.sim.recording import ObstacleInfo, RunContext

_STATIC_COLOUR = (0.55, 0.35, 0.25, 1.0)
_MOVING_COLOUR = (0.85, 0.25, 0.2, 1.0)


def stamp(t_ns: int) -> Timestamp:
    return Timestamp(t_ns // 1_000_000_000, t_ns % 1_000_000_000)


def json_schema(schema: dict[str, Any]) -> foxglove.Schema:
    return foxglove.Schema(
        name=schema["title"], encoding="jsonschema", data=json.dumps(schema).encode()
    )


def _obstacle_primitive(info: ObstacleInfo, x_m: float, y_m: float):
    """A SceneEntity primitive for one obstacle (cylinder or box) at (x, y)."""
    z_m = info.position_m[2]
    rgba = _MOVING_COLOUR if info.moving else _STATIC_COLOUR
    colour = Color(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3])
    pose = Pose(position=Vector3(x=x_m, y=y_m, z=z_m), orientation=Quaternion(w=1.0))
    if info.shape == "box":
        hx, hy, hz = info.size_m
        return "cubes", CubePrimitive(
            pose=pose, size=Vector3(x=2 * hx, y=2 * hy, z=2 * hz), color=colour
        )
    radius_m, half_height_m = info.size_m[0], info.size_m[1]
    # bottom_scale / top_scale default to 0, which draws nothing: set both to 1.
    return "cylinders", CylinderPrimitive(
        pose=pose,
        size=Vector3(x=2 * radius_m, y=2 * radius_m, z=2 * half_height_m),
        bottom_scale=1.0,
        top_scale=1.0,
        color=colour,
    )


def obstacle_entity(info: ObstacleInfo, x_m: float, y_m: float, t_ns: int) -> SceneEntity:
    kind, primitive = _obstacle_primitive(info, x_m, y_m)
    return SceneEntity(
        timestamp=stamp(t_ns), frame_id=WORLD_FRAME, id=info.entity_id, **{kind: [primitive]}
    )


def yaw_quaternion(yaw_rad: float) -> Quaternion:
    return Quaternion(z=math.sin(0.5 * yaw_rad), w=math.cos(0.5 * yaw_rad))


def run_metadata(context: RunContext) -> dict[str, str]:
    """The ``run`` metadata record: what a re-simulation and the readers need."""
    return {
        "seed": str(int(context.seed)),
        "world_seed": str(int(context.world_seed)),
        "control_dt_s": repr(float(context.control_dt_s)),
        "physics_dt_s": repr(float(context.physics_dt_s)),
        "sensor_angles_rad": dumps([float(a) for a in context.sensor_angles_rad]),
        "sensor_range_m": repr(float(context.sensor_range_m)),
        "sensor_offset_m": repr(float(context.sensor_offset_m)),
        "sensor_height_m": repr(float(context.sensor_height_m)),
        "arena_size_m": dumps(list(context.arena_size_m)),
        "obstacles": dumps(
            [
                {
                    "entity_id": o.entity_id,
                    "shape": o.shape,
                    "size_m": list(o.size_m),
                    "position_m": list(o.position_m),
                    "moving": bool(o.moving),
                }
                for o in context.obstacles
            ]
        ),
    }


# The JSON messages of every step, formatted directly: the keys in sorted order and the
# numbers as ``repr`` writes them, which is what ``dumps`` (json with sort_keys) writes for
# finite floats, so the bytes are the same; anything non-finite goes through ``dumps``.
_WHEELS_JSON = ('{"command_left_rad_s": %r, "command_right_rad_s": %r, '
                '"measured_left_rad_s": %r, "measured_right_rad_s": %r}')
_CONTROLLER_JSON = '{"angular_rad_s": %r, "linear_m_s": %r, "waypoint_index": %d}'


def _finite(*values: float) -> bool:
    return all(-math.inf < v < math.inf for v in values)


def wheels_json(command_rad_s: Any, measured_rad_s: Any) -> str:
    """``/wheels`` text for commanded and measured (left, right) wheel speeds."""
    values = (float(command_rad_s[0]), float(command_rad_s[1]), float(measured_rad_s[0]), float(measured_rad_s[1]))
    if _finite(*values):
        return _WHEELS_JSON % values
    keys = ("command_left_rad_s", "command_right_rad_s", "measured_left_rad_s", "measured_right_rad_s")
    return dumps(dict(zip(keys, values)))


def controller_json(linear_m_s: float, angular_rad_s: float, waypoint_index: int) -> str:
    """``/controller`` text for the controller's (v, omega) and active waypoint."""
    linear, angular, index = float(linear_m_s), float(angular_rad_s), int(waypoint_index)
    if _finite(linear, angular):
        return _CONTROLLER_JSON % (angular, linear, index)
    return dumps({"linear_m_s": linear, "angular_rad_s": angular, "waypoint_index": index})
