"""The channels of a log of profile ``ros2``: CDR messages of the standard ROS 2 types.

What :class:`swarmnav.log.writer.McapRecorder` writes on each channel when ``log_format`` is
``ros2`` (the table is in :mod:`swarmnav.log.format`).  Messages are built as plain dicts and
serialised to CDR by ``mcap-ros2-support``'s serialiser for the schema's definition
(:mod:`swarmnav.log.ros2_types`), the one its ``mcap_ros2.writer.Writer`` uses; the bytes are
logged on the recorder's ``foxglove.Context``, so the file, the metadata, the flushing and
the live view are the recorder's, the same as for profile ``swarmnav``.
"""

from __future__ import annotations

import importlib.metadata
import math
from typing import Any, Callable

import foxglove
import numpy as np
from mcap_ros2._dynamic import serialize_dynamic

from swarmnav.sim import palette
from swarmnav.log.format import (
    BASE_FRAME,
    MAP_FRAME,
    ODOM_FRAME,
    ROS2_CHANNELS,
    ROS2_EVENTS_TOPIC,
    ROS2_PROFILE,
    SCAN_FRAME,
    WORLD_FRAME,
    event_text,
)
from swarmnav.log.map_channel import occupancy_percent
from swarmnav.log.messages import chassis_box_m, chassis_radius_m, event_severity
from swarmnav.log.ros2_types import (
    LOG_ERROR,
    LOG_INFO,
    LOG_WARN,
    MARKER_ADD,
    MARKER_ARROW,
    MARKER_CUBE,
    MARKER_CYLINDER,
    MARKER_DELETEALL,
    MARKER_LINE_STRIP,
    msgdef,
)
from swarmnav.sim.recording import ObstacleInfo, RunContext, StepFrame

WHEEL_JOINTS = ["left_wheel", "right_wheel"]
_LEVELS = {"info": LOG_INFO, "warning": LOG_WARN, "error": LOG_ERROR}
_IDENTITY = {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}
_ZERO = {"x": 0.0, "y": 0.0, "z": 0.0}
_PATH_Z_M = 0.01
_SENSED_COLOUR = (0.2, 0.45, 0.95, 0.55)
_SENSED_HEIGHT_M, _SENSED_Z_M = 0.05, 0.35


# Latched topics: a late subscriber gets the last message (durability TRANSIENT_LOCAL, as tf2 and Nav2 publish them).
LATCHED_TOPICS = ("/tf_static", "/map")


def offered_qos(latched: bool) -> str:
    """The channel's ``offered_qos_profiles`` (the MCAP ros2 profile asks for it; ``ros2 bag play`` republishes
    each topic with it): one publisher, reliable, keep last, volatile or transient-local, every duration the
    default (0 s).  The values are rmw's enums: history KEEP_LAST 1; reliability RELIABLE 1; durability
    TRANSIENT_LOCAL 1, VOLATILE 2; liveliness AUTOMATIC 1."""
    zero = "\n    sec: 0\n    nsec: 0"
    return (f"- history: 1\n  depth: {1 if latched else 10}\n  reliability: 1\n  durability: {1 if latched else 2}\n"
            f"  deadline:{zero}\n  lifespan:{zero}\n  liveliness: 1\n  liveliness_lease_duration:{zero}\n"
            "  avoid_ros_namespace_conventions: false")


def stamp(t_ns: int) -> dict[str, int]:
    """``builtin_interfaces/Time`` of simulation time ``t_ns``."""
    return {"sec": t_ns // 1_000_000_000, "nanosec": t_ns % 1_000_000_000}


def header(t_ns: int, frame_id: str) -> dict[str, Any]:
    return {"stamp": stamp(t_ns), "frame_id": frame_id}


def _colour(hex_or_rgba: str | tuple, alpha: float = 1.0) -> dict[str, float]:
    r, g, b, a = palette.rgba(hex_or_rgba, alpha) if isinstance(hex_or_rgba, str) else hex_or_rgba
    return {"r": r, "g": g, "b": b, "a": a}


def _yaw(yaw_rad: float) -> dict[str, float]:
    return {"x": 0.0, "y": 0.0, "z": math.sin(0.5 * yaw_rad), "w": math.cos(0.5 * yaw_rad)}


def transform(t_ns: int, parent: str, child: str, xyz, xyzw) -> dict[str, Any]:
    """A ``geometry_msgs/TransformStamped`` ``parent`` -> ``child``."""
    x, y, z = xyz
    qx, qy, qz, qw = xyzw
    return {"header": header(t_ns, parent), "child_frame_id": child,
            "transform": {"translation": {"x": x, "y": y, "z": z}, "rotation": {"x": qx, "y": qy, "z": qz, "w": qw}}}


def obstacle_marker(info: ObstacleInfo, x_m: float, y_m: float, t_ns: int) -> dict[str, Any]:
    """One obstacle as a CYLINDER or CUBE marker in ``map``; its ``ns`` is the entity id."""
    if info.shape == "box":
        kind, (sx, sy, sz) = MARKER_CUBE, (2 * v for v in info.size_m[:3])
    else:
        kind, (sx, sy, sz) = MARKER_CYLINDER, (2 * info.size_m[0], 2 * info.size_m[0], 2 * info.size_m[1])
    return {"header": header(t_ns, MAP_FRAME), "ns": info.entity_id, "id": 0, "type": kind, "action": MARKER_ADD,
            "pose": {"position": {"x": x_m, "y": y_m, "z": info.position_m[2]}, "orientation": _IDENTITY},
            "scale": {"x": sx, "y": sy, "z": sz},
            "color": _colour(palette.MOVING_OBSTACLE if info.moving else palette.OBSTACLE)}


def scene_markers(arena_size_m: tuple[float, float], robot_radius_m: float,
                  box_m: tuple[float, float, float, float] | None = None) -> list[dict[str, Any]]:
    """``/scene``: the arena's outline in ``map``, the footprint (a disc, or a box robot's box ``box_m``:
    :func:`swarmnav.log.messages.chassis_box_m`) and heading arrow in ``base_link``."""
    w, h = (float(v) for v in arena_size_m)
    r = float(robot_radius_m)
    outline = [{"x": x, "y": y, "z": 0.002} for x, y in ((0.0, 0.0), (w, 0.0), (w, h), (0.0, h), (0.0, 0.0))]
    base = {"header": header(0, BASE_FRAME), "id": 0, "action": MARKER_ADD, "frame_locked": True}
    return [
        {"header": header(0, MAP_FRAME), "ns": "arena", "id": 0, "type": MARKER_LINE_STRIP, "action": MARKER_ADD,
         "pose": {"position": _ZERO, "orientation": _IDENTITY}, "scale": {"x": 0.04, "y": 0.0, "z": 0.0},
         "color": _colour(palette.ARENA), "points": outline},
        {**base, "ns": "robot_footprint", "type": MARKER_CYLINDER,
         "pose": {"position": {"x": 0.0, "y": 0.0, "z": 0.005}, "orientation": _IDENTITY},
         "scale": {"x": 2 * r, "y": 2 * r, "z": 0.01}, "color": _colour(palette.ROBOT, 0.6)} if box_m is None else
        {**base, "ns": "robot_footprint", "type": MARKER_CUBE,
         "pose": {"position": {"x": float(box_m[0]), "y": float(box_m[1]), "z": 0.005}, "orientation": _IDENTITY},
         "scale": {"x": 2 * float(box_m[2]), "y": 2 * float(box_m[3]), "z": 0.01},
         "color": _colour(palette.ROBOT, 0.6)},
        {**base, "ns": "robot_heading", "type": MARKER_ARROW,
         "pose": {"position": {"x": 0.0, "y": 0.0, "z": 0.01}, "orientation": _IDENTITY},
         "scale": {"x": r, "y": 0.15 * r, "z": 0.35 * r}, "color": _colour(palette.DRIVEN)},
    ]


def belief_markers(obstacles, horizon_s: float, t_ns: int) -> list[dict[str, Any]]:
    """``/navigator``: delete all, then per sensed obstacle its disc, its disc ``horizon_s`` ahead and
    an arrow along its velocity (ns ``sensed_<track id>``)."""
    markers: list[dict[str, Any]] = [{"header": header(t_ns, MAP_FRAME), "action": MARKER_DELETEALL}]
    for ob in obstacles:
        x, y, r = float(ob.x_m), float(ob.y_m), float(ob.radius_m)
        ex, ey = x + float(ob.vx_m_s) * horizon_s, y + float(ob.vy_m_s) * horizon_s
        ns = f"sensed_{int(ob.track_id)}"
        disc = {"header": header(t_ns, MAP_FRAME), "ns": ns, "type": MARKER_CYLINDER, "action": MARKER_ADD,
                "scale": {"x": 2 * r, "y": 2 * r, "z": _SENSED_HEIGHT_M}, "color": _colour(_SENSED_COLOUR)}
        markers.append({**disc, "id": 0, "pose": {"position": {"x": x, "y": y, "z": _SENSED_Z_M},
                                                  "orientation": _IDENTITY}})
        if math.hypot(ex - x, ey - y) > 1e-9:
            markers.append({**disc, "id": 1, "pose": {"position": {"x": ex, "y": ey, "z": _SENSED_Z_M},
                                                      "orientation": _IDENTITY},
                            "color": _colour(_SENSED_COLOUR[:3] + (0.2,))})
            markers.append({**disc, "id": 2, "type": MARKER_ARROW, "pose": {"position": _ZERO, "orientation": _IDENTITY},
                            "scale": {"x": 0.02, "y": 0.06, "z": 0.1},
                            "points": [{"x": x, "y": y, "z": _SENSED_Z_M + _SENSED_HEIGHT_M},
                                       {"x": ex, "y": ey, "z": _SENSED_Z_M + _SENSED_HEIGHT_M}]})
    return markers


def occupancy_grid(t_ns: int, cells: np.ndarray, resolution_m: float, origin_xy_m: tuple[float, float]) -> dict[str, Any]:
    """A ``nav_msgs/OccupancyGrid`` in ``map`` from (rows, cols) cells in percent (0..100, -1 unknown; row 0 at
    ``origin_xy_m``'s y, column 0 at its x: :func:`swarmnav.log.map_channel.occupancy_percent` of a log-odds grid)."""
    grid = np.asarray(cells, dtype=np.int8)
    return {"header": header(t_ns, MAP_FRAME),
            "info": {"map_load_time": stamp(t_ns), "resolution": float(resolution_m),
                     "width": int(grid.shape[1]), "height": int(grid.shape[0]),
                     "origin": {"position": {"x": float(origin_xy_m[0]), "y": float(origin_xy_m[1]), "z": 0.0},
                                "orientation": _IDENTITY}},
            "data": grid.ravel().tolist()}


class Ros2Channels:
    """The ``ros2`` profile's channels of one run, on one ``foxglove.Context``.

    Each method writes its messages and returns how many it wrote.  A run with
    ``knowledge.pose = "odometry"`` hands its dead-reckoned pose on ``StepFrame.odometry`` (a ``Pose2D``
    in ``odom``): ``/odom`` is that estimate and ``map`` -> ``odom`` carries its error; without it
    odometry is the simulator's pose.  A run whose map is unknown hands the
    map it builds to :meth:`occupancy` (the recorder's ``occupancy``), written on ``/map``.
    """

    profile = ROS2_PROFILE

    def __init__(self) -> None:
        self._channels: dict[str, tuple[foxglove.Channel, Callable[[Any], bytes]]] = {}
        self._last_path: bytes | None = None
        self._moving: tuple[ObstacleInfo, ...] = ()
        self._belief_drawn = False
        self._previous: tuple[int, float, float, float] | None = None  # t_ns, x, y, yaw of the last step

    def open(self, fox: foxglove.Context, context: RunContext) -> None:
        self._fox = fox
        self._encoders: dict[str, Callable[[Any], bytes]] = {}

    def _log(self, topic: str, message: dict[str, Any], t_ns: int) -> bytes:
        entry = self._channels.get(topic)
        if entry is None:
            schema = ROS2_CHANNELS[topic][1]
            short = schema.replace("/msg/", "/")
            encode = self._encoders.get(schema)
            if encode is None:
                encode = self._encoders[schema] = serialize_dynamic(schema, msgdef(short))[schema]
            channel = foxglove.Channel(topic, schema=foxglove.Schema(name=schema, encoding="ros2msg",
                                                                     data=msgdef(short).encode()),
                                       message_encoding="cdr", context=self._fox,
                                       metadata={"offered_qos_profiles": offered_qos(topic in LATCHED_TOPICS)})
            entry = self._channels[topic] = (channel, encode)
        channel, encode = entry
        data = encode(message)
        channel.base.log(data, t_ns, None)
        return data

    def begin(self, context: RunContext) -> int:
        self._dt_s = float(context.control_dt_s)
        self._infos = context.obstacles
        self._moving = tuple(o for o in context.obstacles if o.moving)
        self._scan_offset_m = float(context.sensor_offset_m)
        angles = np.asarray(context.sensor_angles_rad, dtype=float)
        increment = float(angles[1] - angles[0]) if angles.size > 1 else 0.0
        self._scan_head = {"angle_min": float(angles[0]) if angles.size else 0.0,
                           "angle_max": float(angles[-1]) if angles.size else 0.0,
                           "angle_increment": increment, "time_increment": 0.0, "scan_time": self._dt_s,
                           "range_min": self._scan_offset_m,
                           "range_max": self._scan_offset_m + float(context.sensor_range_m), "intensities": []}
        # world -> map (identity): the frame the Foxglove layout looks from, the one swarmnav logs use.
        self._static = [transform(0, WORLD_FRAME, MAP_FRAME, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
                        transform(0, BASE_FRAME, SCAN_FRAME, (0.0, 0.0, float(context.sensor_height_m)),
                                  (0.0, 0.0, 0.0, 1.0))]
        self._static_map_odom = transform(0, MAP_FRAME, ODOM_FRAME, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
        self._static_written = False
        self._scene = {"markers": scene_markers(context.arena_size_m, chassis_radius_m(context.mjcf_xml),
                                                chassis_box_m(context.mjcf_xml))}
        self._log("/obstacles", self._obstacle_array(0, None), 0)
        self._log("/scene", self._scene, 0)
        return 2

    def path(self, t_ns: int, points: np.ndarray) -> int:
        deltas = np.diff(points[:, :2], axis=0)
        headings = np.arctan2(deltas[:, 1], deltas[:, 0]) if len(deltas) else np.zeros(0)
        headings = np.append(headings, headings[-1] if len(headings) else 0.0)
        poses = [{"header": header(t_ns, MAP_FRAME),
                  "pose": {"position": {"x": float(x), "y": float(y), "z": _PATH_Z_M}, "orientation": _yaw(float(h))}}
                 for (x, y), h in zip(points[:, :2], headings)]
        self._last_path = {"header": header(t_ns, MAP_FRAME), "poses": poses}
        self._log("/plan", self._last_path, t_ns)
        return 1

    def step(self, frame: StepFrame, t_ns: int, late: set[str] | tuple = ()) -> int:
        position = np.asarray(frame.position_m, dtype=float).tolist()
        qw, qx, qy, qz = np.asarray(frame.quaternion_wxyz, dtype=float).tolist()
        odometry = frame.odometry  # a Pose2D with knowledge.pose = "odometry", else None
        written = 0
        if not self._static_written or "/tf_static" in late:
            static = self._static + ([] if odometry is not None else [self._static_map_odom])
            self._log("/tf_static", {"transforms": static}, t_ns if self._static_written else 0)
            self._static_written = True
            written += 1
        if odometry is None:  # odom is the simulator's frame: odom -> base_link is the true pose
            odom_xyz, odom_q = position, (qx, qy, qz, qw)
            transforms = [transform(t_ns, ODOM_FRAME, BASE_FRAME, odom_xyz, odom_q)]
            x, y, yaw = position[0], position[1], float(frame.heading_rad)
        else:  # map -> odom carries the estimate's error: map -> odom -> base_link is the true pose
            x, y, yaw = float(odometry.x_m), float(odometry.y_m), float(odometry.heading_rad)
            odom_xyz, odom_q = (x, y, position[2]), tuple(_yaw(yaw)[k] for k in "xyzw")
            true_yaw = float(frame.heading_rad)
            drift = true_yaw - yaw
            c, s = math.cos(drift), math.sin(drift)
            transforms = [transform(t_ns, MAP_FRAME, ODOM_FRAME,
                                    (position[0] - (c * x - s * y), position[1] - (s * x + c * y), 0.0),
                                    tuple(_yaw(drift)[k] for k in "xyzw")),
                          transform(t_ns, ODOM_FRAME, BASE_FRAME, odom_xyz, odom_q)]
        self._log("/tf", {"transforms": transforms}, t_ns)
        self._log("/odom", {"header": header(t_ns, ODOM_FRAME), "child_frame_id": BASE_FRAME,
                            "pose": {"pose": {"position": dict(zip("xyz", odom_xyz)),
                                              "orientation": dict(zip("xyzw", odom_q))}, "covariance": [0.0] * 36},
                            "twist": {"twist": self._twist(t_ns, x, y, yaw), "covariance": [0.0] * 36}}, t_ns)
        ranges = [math.inf if r == math.inf or r == -math.inf else r + self._scan_offset_m
                  for r in np.asarray(frame.range_m, dtype=float).tolist()]
        self._log("/scan", {"header": header(t_ns, SCAN_FRAME), **self._scan_head, "ranges": ranges}, t_ns)
        for topic, speeds in (("/joint_states", frame.wheel_measured_rad_s), ("/wheels/command", frame.wheel_command_rad_s)):
            self._log(topic, {"header": header(t_ns, BASE_FRAME), "name": WHEEL_JOINTS, "position": [],
                              "velocity": [float(speeds[0]), float(speeds[1])], "effort": []}, t_ns)
        self._log("/cmd_vel", {"linear": {"x": float(frame.linear_m_s), "y": 0.0, "z": 0.0},
                               "angular": {"x": 0.0, "y": 0.0, "z": float(frame.angular_rad_s)}}, t_ns)
        self._log("/clock", {"clock": stamp(t_ns)}, t_ns)
        written += 7
        if self._moving or "/obstacles" in late:
            self._log("/obstacles", self._obstacle_array(t_ns, frame.moving_obstacles_m), t_ns)
            written += 1
        if "/scene" in late:
            self._log("/scene", self._scene, t_ns)
            written += 1
        if "/plan" in late and self._last_path is not None:
            self._log("/plan", self._last_path, t_ns)
            written += 1
        return written + self._log_belief(frame.belief, t_ns)

    def event(self, t_ns: int, kind: str, details: dict[str, Any]) -> int:
        self._log(ROS2_EVENTS_TOPIC, {"stamp": stamp(t_ns), "level": _LEVELS[event_severity(kind)], "name": "swarmnav",
                                      "msg": event_text(kind, details), "file": "", "function": "", "line": 0}, t_ns)
        return 1

    def occupancy(self, t_ns: int, grid: Any) -> int:
        """``/map``: a sensed :class:`models.occupancy.LogOddsGrid` as a ``nav_msgs/OccupancyGrid`` (the same
        cells in percent as the ``swarmnav`` profile's ``foxglove.Grid``)."""
        self._log("/map", occupancy_grid(t_ns, occupancy_percent(grid.log_odds), grid.cell_m, grid.origin_m), t_ns)
        return 1

    def versions(self) -> dict[str, str]:
        """The serialiser's version, recorded in the ``versions`` metadata beside the writer's."""
        return {"mcap_ros2_support": importlib.metadata.version("mcap-ros2-support")}

    def close(self) -> None:
        """Nothing to release: the channels are the context's."""

    def _twist(self, t_ns: int, x: float, y: float, yaw: float) -> dict[str, Any]:
        """The base's velocity over the last control period, in ``base_link`` (zero at the first step)."""
        previous, self._previous = self._previous, (t_ns, x, y, yaw)
        if previous is None or t_ns <= previous[0]:
            return {"linear": _ZERO, "angular": _ZERO}
        dt_s = (t_ns - previous[0]) * 1e-9
        dx, dy = x - previous[1], y - previous[2]
        c, s = math.cos(yaw), math.sin(yaw)
        turn = math.atan2(math.sin(yaw - previous[3]), math.cos(yaw - previous[3]))
        return {"linear": {"x": (c * dx + s * dy) / dt_s, "y": (-s * dx + c * dy) / dt_s, "z": 0.0},
                "angular": {"x": 0.0, "y": 0.0, "z": turn / dt_s}}

    def _obstacle_array(self, t_ns: int, moving_xy_m: np.ndarray | None) -> dict[str, Any]:
        """Every obstacle; the moving ones at ``moving_xy_m`` (None: where they start)."""
        moving = iter(np.asarray(moving_xy_m, dtype=float).reshape(-1, 2).tolist()) if moving_xy_m is not None else None
        markers = []
        for info in self._infos:
            x, y = info.position_m[0], info.position_m[1]
            if info.moving and moving is not None:
                x, y = next(moving)
            markers.append(obstacle_marker(info, float(x), float(y), t_ns))
        return {"markers": markers}

    def _log_belief(self, belief: Any, t_ns: int) -> int:
        obstacles = belief.obstacles if belief is not None else ()
        if not obstacles and not self._belief_drawn:
            return 0
        self._log("/navigator", {"markers": belief_markers(obstacles, belief.horizon_s if belief is not None else 0.0,
                                                           t_ns)}, t_ns)
        self._belief_drawn = bool(obstacles)
        return 1
