"""The channels of a log of profile ``swarmnav``: Foxglove's protobuf schemas and JSON.

What :class:`swarmnav.log.writer.McapRecorder` writes on each channel when ``log_format`` is
``swarmnav`` (the default); the table of channels is in :mod:`swarmnav.log.format`.  The
per-step protobuf messages are encoded by :mod:`swarmnav.log.encoding`, the rest built by
:mod:`swarmnav.log.messages`.
"""

from __future__ import annotations

from typing import Any

import foxglove
import numpy as np
from foxglove.channels import LogChannel, PoseInFrameChannel, PosesInFrameChannel, SceneUpdateChannel
from foxglove.messages import FrameTransform, LaserScan, Pose, PoseInFrame, PosesInFrame, SceneUpdate, Vector3

from swarmnav.log.encoding import SceneEncoder, StepEncoder, timestamp_field
from swarmnav.log.map_channel import MapChannel
from swarmnav.log.format import (
    BASE_FRAME,
    CONTROLLER_SCHEMA,
    EVENTS_TOPIC,
    LOG_PROFILE,
    NAVIGATOR_TOPIC,
    ODOM_TOPIC,
    SCENE_TOPIC,
    WHEELS_SCHEMA,
    WORLD_FRAME,
    scan_list_from_ranges,
)
from swarmnav.log.messages import (
    belief_update,
    chassis_box_m,
    chassis_radius_m,
    controller_json,
    event_log,
    json_schema,
    obstacle_entity,
    obstacle_template,
    scene_update,
    stamp,
    wheels_json,
    yaw_quaternion,
)
from swarmnav.sim.recording import ObstacleInfo, RunContext, StepFrame


class SwarmnavChannels:
    """The ``swarmnav`` profile's channels of one run, on one ``foxglove.Context``.

    Each method writes its messages and returns how many it wrote.
    """

    profile = LOG_PROFILE

    def __init__(self) -> None:
        self._last_path: PosesInFrame | None = None
        self._moving_infos: tuple[ObstacleInfo, ...] = ()
        self._json_channels: list[foxglove.Channel] = []
        self._navigator: SceneUpdateChannel | None = None  # made at the first belief with obstacles
        self._odom: PoseInFrameChannel | None = None  # /odom, made at the first odometry pose
        self._belief_drawn = False
        self._map: MapChannel | None = None  # /map, made at the first sensed map (only with the map unknown)

    def open(self, fox: foxglove.Context, context: RunContext) -> None:
        """Make the channels (before the run's metadata is written)."""
        self._fox = fox
        # The per-step protobuf channels take bytes from a StepEncoder (swarmnav.log.encoding): the SDK's
        # schemas and encoding, without building its message objects every step.
        self._tf, self._pose = (
            foxglove.Channel(topic, schema=message.get_schema(), message_encoding="protobuf", context=fox)
            for topic, message in (("/tf", FrameTransform), ("/robot/pose", PoseInFrame)))
        self._path = PosesInFrameChannel("/planner/path", context=fox)
        self._obstacles = foxglove.Channel("/obstacles", schema=SceneUpdate.get_schema(), message_encoding="protobuf",
                                           context=fox)
        self._scan = foxglove.Channel("/range/scan", schema=LaserScan.get_schema(), message_encoding="protobuf",
                                      context=fox)
        self._wheels, self._controller = self._json_channels = [
            foxglove.Channel(topic, schema=json_schema(schema), message_encoding="json", context=fox)
            for topic, schema in (("/wheels", WHEELS_SCHEMA), ("/controller", CONTROLLER_SCHEMA))
        ]
        self._events = LogChannel(EVENTS_TOPIC, context=fox)
        self._scene_channel = SceneUpdateChannel(SCENE_TOPIC, context=fox)

    def begin(self, context: RunContext) -> int:
        """The t = 0 messages: the obstacles where they start and the scene."""
        angles = np.asarray(context.sensor_angles_rad, dtype=float)
        self._beam_offset_m = float(context.sensor_offset_m)
        self._encoder = StepEncoder(WORLD_FRAME, BASE_FRAME,
                                    ((0.0, 0.0, float(context.sensor_height_m)), (0.0, 0.0, 0.0, 1.0)),
                                    float(angles[0]) if angles.size else 0.0,
                                    float(angles[-1]) if angles.size else 0.0)  # end: inclusive
        self._moving_infos = tuple(o for o in context.obstacles if o.moving)
        static_entities = [obstacle_entity(o, o.position_m[0], o.position_m[1], 0).encode()
                           for o in context.obstacles if not o.moving]
        self._scene = SceneEncoder(static_entities, WORLD_FRAME,
                                   [(o.entity_id, obstacle_template(o)) for o in self._moving_infos])
        self._obstacles.base.log(self._scene_update(0, None), 0, None)
        self._scene_message = scene_update(context.arena_size_m, chassis_radius_m(context.mjcf_xml),
                                           chassis_box_m(context.mjcf_xml))
        self._scene_channel.log(self._scene_message, log_time=0)
        return 2

    def path(self, t_ns: int, points: np.ndarray) -> int:
        deltas = np.diff(points[:, :2], axis=0)
        headings = np.arctan2(deltas[:, 1], deltas[:, 0]) if len(deltas) else np.zeros(0)
        headings = np.append(headings, headings[-1] if len(headings) else 0.0)
        poses = [
            Pose(position=Vector3(x=float(x), y=float(y), z=0.01), orientation=yaw_quaternion(float(h)))
            for (x, y), h in zip(points[:, :2], headings)
        ]
        message = PosesInFrame(timestamp=stamp(t_ns), frame_id=WORLD_FRAME, poses=poses)
        self._path.log(message, log_time=t_ns)
        self._last_path = message
        return 1

    def step(self, frame: StepFrame, t_ns: int, late: set[str] | tuple = ()) -> int:
        time_stamp = timestamp_field(t_ns)
        px, py, pz = np.asarray(frame.position_m, dtype=float).tolist()
        qw, qx, qy, qz = np.asarray(frame.quaternion_wxyz, dtype=float).tolist()
        encoder = self._encoder
        tf, pose = encoder.transform(time_stamp, (px, py, pz), (qx, qy, qz, qw))
        self._tf.base.log(tf, t_ns, None)
        self._pose.base.log(pose, t_ns, None)
        self._scan.base.log(encoder.scan(time_stamp, scan_list_from_ranges(frame.range_m, self._beam_offset_m)),
                            t_ns, None)
        # The JSON channels' own ``log`` only encodes text and calls its ``base``: called directly.
        self._wheels.base.log(wheels_json(frame.wheel_command_rad_s, frame.wheel_measured_rad_s).encode(), t_ns, None)
        self._controller.base.log(
            controller_json(frame.linear_m_s, frame.angular_rad_s, frame.waypoint_index).encode(), t_ns, None)
        written = 5
        if self._moving_infos or "/obstacles" in late:
            self._obstacles.base.log(self._scene_update(t_ns, frame.moving_obstacles_m), t_ns, None)
            written += 1
        if SCENE_TOPIC in late:
            self._scene_channel.log(self._scene_message, log_time=t_ns)
            written += 1
        if "/planner/path" in late and self._last_path is not None:
            self._path.log(self._last_path, log_time=t_ns)
            written += 1
        if frame.odometry is not None:
            written += self._log_odometry(frame.odometry, t_ns)
        return written + self._log_belief(frame.belief, t_ns)

    def _log_odometry(self, pose: Any, t_ns: int) -> int:
        """``/odom``: the pose the navigator saw (integrated wheel speeds), in ``world`` (only with it)."""
        if self._odom is None:
            self._odom = PoseInFrameChannel(ODOM_TOPIC, context=self._fox)
        self._odom.log(PoseInFrame(timestamp=stamp(t_ns), frame_id=WORLD_FRAME,
                                   pose=Pose(position=Vector3(x=float(pose.x_m), y=float(pose.y_m), z=0.01),
                                             orientation=yaw_quaternion(float(pose.heading_rad)))), log_time=t_ns)
        return 1

    def event(self, t_ns: int, kind: str, details: dict[str, Any]) -> int:
        self._events.log(event_log(t_ns, kind, details), log_time=t_ns)
        return 1

    def occupancy(self, t_ns: int, grid: Any) -> int:
        """``/map``: the sensed map (:mod:`swarmnav.log.map_channel`; the channel made at the first)."""
        if self._map is None:
            self._map = MapChannel(self._fox)
        self._map.log(t_ns, grid)
        return 1

    def versions(self) -> dict[str, str]:
        """Versions of what encodes this profile's messages, beyond the writer's (none: the SDK's own)."""
        return {}

    def close(self) -> None:
        for channel in self._json_channels:
            # foxglove keeps JSON channels in a registry of its own; closing is its public API.
            channel.close()

    def _scene_update(self, t_ns: int, moving_xy_m: np.ndarray | None) -> bytes:
        """``/obstacles``: every entity, the moving ones at ``moving_xy_m`` (None: where they start)."""
        if moving_xy_m is None:
            moving_xy_m = np.array([o.position_m[:2] for o in self._moving_infos]).reshape(-1, 2)
        return self._scene.update(timestamp_field(t_ns), np.asarray(moving_xy_m, dtype=float).tolist())

    def _log_belief(self, belief: Any, t_ns: int) -> int:
        """``/navigator`` while the navigator acts on sensed obstacles, and once more when it stops."""
        obstacles = belief.obstacles if belief is not None else ()
        if not obstacles and not self._belief_drawn:
            return 0
        if self._navigator is None:
            self._navigator = SceneUpdateChannel(NAVIGATOR_TOPIC, context=self._fox)
        self._navigator.log(belief_update(obstacles, belief.horizon_s if belief is not None else 0.0, t_ns),
                            log_time=t_ns)
        self._belief_drawn = bool(obstacles)
        return 1
