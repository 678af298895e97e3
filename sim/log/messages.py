"""The foxglove messages of a run log, built from what a recorder receives.

Pure construction, no I/O: :class:`swarmnav.log.writer.McapRecorder` logs them.
"""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ElementTree
from typing import Any

import foxglove
from foxglove.messages import (
    ArrowPrimitive,
    Color,
    CubePrimitive,
    Log,
    LogLevel,
    CylinderPrimitive,
    LinePrimitive,
    LinePrimitiveLineType,
    Point3,
    Pose,
    Quaternion,
    SceneEntity,
    SceneEntityDeletion,
    SceneEntityDeletionType,
    SceneUpdate,
    Timestamp,
    Vector3,
)

from swarmnav.sim import palette
from swarmnav.log.format import (
    ARENA_ENTITY,
    BASE_FRAME,
    FOOTPRINT_ENTITY,
    WORLD_FRAME,
    dumps,
    event_text,
)
from swarmnav.sim.recording import ObstacleInfo, RunContext

# The shared palette (sim.palette), as plot and the video draw obstacles.
_STATIC_COLOUR = palette.rgba(palette.OBSTACLE)
_MOVING_COLOUR = palette.rgba(palette.MOVING_OBSTACLE)


def stamp(t_ns: int) -> Timestamp:
    return Timestamp(t_ns // 1_000_000_000, t_ns % 1_000_000_000)


def json_schema(schema: dict[str, Any]) -> foxglove.Schema:
    return foxglove.Schema(
        name=schema["title"], encoding="jsonschema", data=json.dumps(schema).encode()
    )


def _obstacle_primitive(info: ObstacleInfo, x_m: float, y_m: float, with_pose: bool = True):
    """A SceneEntity primitive for one obstacle (cylinder or box) at (x, y) (its pose left out without ``with_pose``)."""
    z_m = info.position_m[2]
    rgba = _MOVING_COLOUR if info.moving else _STATIC_COLOUR
    colour = Color(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3])
    pose = Pose(position=Vector3(x=x_m, y=y_m, z=z_m), orientation=Quaternion(w=1.0)) if with_pose else None
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


def obstacle_template(info: ObstacleInfo) -> tuple[str, float, bytes]:
    """What :class:`swarmnav.log.encoding.SceneEncoder` needs to encode :func:`obstacle_entity` at any
    position: the primitive list's name ("cylinders" or "cubes"), the centre's height and the
    primitive's encoding without its pose (size, scales, colour); the pose is the position and
    the identity orientation."""
    kind, primitive = _obstacle_primitive(info, 0.0, 0.0, with_pose=False)
    return kind, float(info.position_m[2]), primitive.encode()


def obstacle_entity(info: ObstacleInfo, x_m: float, y_m: float, t_ns: int) -> SceneEntity:
    kind, primitive = _obstacle_primitive(info, x_m, y_m)
    return SceneEntity(
        timestamp=stamp(t_ns), frame_id=WORLD_FRAME, id=info.entity_id, **{kind: [primitive]}
    )


_SENSED_COLOUR = Color(r=0.2, g=0.45, b=0.95, a=0.55)
_PREDICTED_COLOUR = Color(r=0.2, g=0.45, b=0.95, a=0.2)
_SENSED_HEIGHT_M = 0.05
_SENSED_Z_M = 0.35  # thin discs a little above the robot's rangefinders, through the true cylinders


def belief_update(obstacles, horizon_s: float, t_ns: int) -> SceneUpdate:
    """``/navigator``: delete what was drawn, then one entity per obstacle the navigator acted on.

    Each entity (``sensed_<track id>``) is the estimated footprint (a thin disc),
    the footprint predicted ``horizon_s`` ahead along the estimated velocity, the
    two edges of the swept band between them, and an arrow along the velocity.
    With no obstacles the update only deletes (what the robot believes now is nothing).
    """
    time_stamp = stamp(t_ns)
    entities = []
    for ob in obstacles:
        x, y, r = float(ob.x_m), float(ob.y_m), float(ob.radius_m)
        vx, vy = float(ob.vx_m_s), float(ob.vy_m_s)
        ex, ey = x + vx * horizon_s, y + vy * horizon_s
        size = Vector3(x=2 * r, y=2 * r, z=_SENSED_HEIGHT_M)
        cylinders = [CylinderPrimitive(pose=Pose(position=Vector3(x=x, y=y, z=_SENSED_Z_M), orientation=Quaternion(w=1.0)),
                                       size=size, bottom_scale=1.0, top_scale=1.0, color=_SENSED_COLOUR)]
        lines, arrows = [], []
        travel = math.hypot(ex - x, ey - y)
        if travel > 1e-9:
            cylinders.append(CylinderPrimitive(
                pose=Pose(position=Vector3(x=ex, y=ey, z=_SENSED_Z_M), orientation=Quaternion(w=1.0)),
                size=size, bottom_scale=1.0, top_scale=1.0, color=_PREDICTED_COLOUR))
            nx, ny = -(ey - y) / travel * r, (ex - x) / travel * r
            points = [Point3(x=x + nx, y=y + ny, z=_SENSED_Z_M), Point3(x=ex + nx, y=ey + ny, z=_SENSED_Z_M),
                      Point3(x=x - nx, y=y - ny, z=_SENSED_Z_M), Point3(x=ex - nx, y=ey - ny, z=_SENSED_Z_M)]
            lines.append(LinePrimitive(type=LinePrimitiveLineType.LineList, thickness=0.01, points=points,
                                       color=_PREDICTED_COLOUR))
            head = min(0.1, 0.5 * travel)
            arrows.append(ArrowPrimitive(
                pose=Pose(position=Vector3(x=x, y=y, z=_SENSED_Z_M + _SENSED_HEIGHT_M),
                          orientation=yaw_quaternion(math.atan2(vy, vx))),
                shaft_length=travel - head, shaft_diameter=0.02, head_length=head, head_diameter=0.06,
                color=_SENSED_COLOUR))
        entities.append(SceneEntity(timestamp=time_stamp, frame_id=WORLD_FRAME, id=f"sensed_{int(ob.track_id)}",
                                    cylinders=cylinders, lines=lines, arrows=arrows))
    return SceneUpdate(deletions=[SceneEntityDeletion(timestamp=time_stamp, type=SceneEntityDeletionType.All)],
                       entities=entities)


_WARNING_EVENTS = {"collision_begin", "stopped_on_collision", "timeout", "left_arena"}
_ERROR_EVENTS = {"error", "interrupted"}
_ARENA_Z_M = 0.002
_FOOTPRINT_HEIGHT_M = 0.01
_FOOTPRINT_Z_M = 0.005  # just above the floor, under the chassis


def event_severity(kind: str) -> str:
    """An event's level: ``warning`` for collisions and timeouts, ``error`` for errors, else ``info``."""
    return "warning" if kind in _WARNING_EVENTS else "error" if kind in _ERROR_EVENTS else "info"


def event_log(time_s_ns: int, kind: str, details: dict[str, Any]) -> Log:
    """``/events``: one ``foxglove.Log`` (Foxglove's Log panel lists it, filterable by level)."""
    level = {"warning": LogLevel.Warning, "error": LogLevel.Error, "info": LogLevel.Info}[event_severity(kind)]
    return Log(timestamp=stamp(time_s_ns), level=level, message=event_text(kind, details), name="swarmnav")


def _colour(hex_colour: str, alpha: float = 1.0) -> Color:
    r, g, b, a = palette.rgba(hex_colour, alpha)
    return Color(r=r, g=g, b=b, a=a)


def chassis_radius_m(mjcf_xml: str) -> float:
    """The robot's footprint radius: the size of the ``chassis`` geom of the run's MJCF (a cylinder's radius);
    for a box chassis (the catalogue's Jackal and Burger) its circumscribed circle about the base origin, the
    disc the planners plan for (``models.robots``).

    Raises:
        ValueError: the MJCF has no chassis geom with a size.
    """
    for geom in ElementTree.fromstring(mjcf_xml).iter("geom"):
        if geom.get("name") == "chassis" and geom.get("size"):
            size = [float(v) for v in geom.get("size").split()]
            if geom.get("type") == "box":
                x, y = ([float(v) for v in geom.get("pos", "0 0 0").split()] + [0.0, 0.0])[:2]
                return max(math.hypot(x + sx * size[0], y + sy * size[1]) for sx in (-1, 1) for sy in (-1, 1))
            return size[0]
    raise ValueError("the scene has no chassis geom with a size")


def chassis_box_m(mjcf_xml: str) -> tuple[float, float, float, float] | None:
    """The plan view of a box ``chassis`` geom of the run's MJCF, (centre x, centre y, half length, half width)
    in the base frame; None for a cylinder chassis (the disc robot) or none."""
    for geom in ElementTree.fromstring(mjcf_xml).iter("geom"):
        if geom.get("name") == "chassis" and geom.get("size") and geom.get("type") == "box":
            size = [float(v) for v in geom.get("size").split()]
            x, y = ([float(v) for v in geom.get("pos", "0 0 0").split()] + [0.0, 0.0])[:2]
            return x, y, size[0], size[1]
    return None


def scene_update(arena_size_m: tuple[float, float], robot_radius_m: float,
                 box_m: tuple[float, float, float, float] | None = None) -> SceneUpdate:
    """``/scene`` at t = 0: the arena's outline in ``world`` and the robot's footprint in ``base_link``: a disc
    of ``robot_radius_m``, or the box ``box_m`` (:func:`chassis_box_m`) of a box robot; the heading arrow's
    size follows ``robot_radius_m``.

    The footprint is ``frame_locked``: Foxglove moves it with ``base_link`` as ``/tf`` goes, so
    it is sent once and never expires (no lifetime).
    """
    width_m, height_m = (float(v) for v in arena_size_m)
    corners = [Point3(x=x, y=y, z=_ARENA_Z_M) for x, y in ((0.0, 0.0), (width_m, 0.0), (width_m, height_m),
                                                           (0.0, height_m))]
    arena = SceneEntity(timestamp=stamp(0), frame_id=WORLD_FRAME, id=ARENA_ENTITY, lines=[LinePrimitive(
        type=LinePrimitiveLineType.LineLoop, thickness=0.04, points=corners, color=_colour(palette.ARENA))])
    r = float(robot_radius_m)
    if box_m is None:
        shape = {"cylinders": [CylinderPrimitive(pose=Pose(position=Vector3(x=0.0, y=0.0, z=_FOOTPRINT_Z_M),
                                                           orientation=Quaternion(w=1.0)),
                                                 size=Vector3(x=2 * r, y=2 * r, z=_FOOTPRINT_HEIGHT_M),
                                                 bottom_scale=1.0, top_scale=1.0, color=_colour(palette.ROBOT, 0.6))]}
    else:
        cx, cy, hx, hy = (float(v) for v in box_m)
        shape = {"cubes": [CubePrimitive(pose=Pose(position=Vector3(x=cx, y=cy, z=_FOOTPRINT_Z_M),
                                                   orientation=Quaternion(w=1.0)),
                                         size=Vector3(x=2 * hx, y=2 * hy, z=_FOOTPRINT_HEIGHT_M),
                                         color=_colour(palette.ROBOT, 0.6))]}
    footprint = SceneEntity(
        timestamp=stamp(0), frame_id=BASE_FRAME, id=FOOTPRINT_ENTITY, frame_locked=True, **shape,
        arrows=[ArrowPrimitive(pose=Pose(position=Vector3(x=0.0, y=0.0, z=2 * _FOOTPRINT_Z_M),
                                         orientation=Quaternion(w=1.0)),
                               shaft_length=0.7 * r, shaft_diameter=0.15 * r, head_length=0.3 * r,
                               head_diameter=0.35 * r, color=_colour(palette.DRIVEN))])
    return SceneUpdate(entities=[arena, footprint])


def yaw_quaternion(yaw_rad: float) -> Quaternion:
    return Quaternion(z=math.sin(0.5 * yaw_rad), w=math.cos(0.5 * yaw_rad))


def run_metadata(context: RunContext) -> dict[str, str]:
    """The ``run`` metadata record: what a re-simulation and the readers need."""
    return {
        "seed": str(int(context.seed)),
        "world_seed": str(int(context.world_seed)),
        **({} if context.clearance_m is None else {"clearance_m": repr(float(context.clearance_m))}),
        **({} if context.map_knowledge is None else {"map_knowledge": dumps(context.map_knowledge)}),
        **({} if context.pose_source is None else {"pose_source": dumps(context.pose_source)}),
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
    # A non-finite value makes the sum inf or nan; finite values whose sum overflows take the
    # ``dumps`` path too, which writes the same text for finite numbers.
    return math.isfinite(sum(values))


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
