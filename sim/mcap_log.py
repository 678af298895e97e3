"""The run log: a Recorder that writes an MCAP file Foxglove opens as is.

One :class:`McapRecorder` per run.  It owns one ``foxglove.Context``; the MCAP
file and, with ``live=True``, a loopback WebSocket server for Foxglove are both
sinks of that context, so they see exactly the same messages.

Channels (Foxglove well-known protobuf schemas unless said otherwise):

======================  ===============================================================
``/tf``                 FrameTransform world -> base_link, every control step
``/robot/pose``         PoseInFrame in ``world``, every control step
``/planner/path``       PosesInFrame in ``world``; at the start and after any replan
``/obstacles``          SceneUpdate, one cylinder / cube entity per obstacle with a fixed
                        ``id``; sent once when nothing moves, otherwise every control
                        step with *all* entities (so a seek in Foxglove, which only
                        back-fills the latest message of a topic, still shows the static
                        ones)
``/range/scan``         LaserScan in ``base_link``; misses are NaN
``/wheels``             JSON ``swarmnav.WheelSpeeds``: commanded and measured rad/s
``/controller``         JSON ``swarmnav.ControllerState``: v, omega, active waypoint
``/events``             JSON ``swarmnav.Event``: goal_reached, collision_begin/end, timeout
======================  ===============================================================

Time: ``log_time`` = ``publish_time`` = every message's own timestamp = simulation
time in ns from 0.  No wall-clock time is written, so two runs with the same seed
give identical message bytes on every channel.

Metadata records: ``scenario`` (name, TOML text), ``planner`` and ``navigator`` (name, JSON params),
``run`` (seed, world seed, time steps, sensor layout, obstacles), ``versions`` and, from
``finish``, ``outcome`` (the runner's summary, JSON-encoded values).  Attachment:
``scene.xml``, the compiled MJCF.  Everything needed to re-simulate is in the file.

Writer choice: the foxglove SDK (Rust core, ~63k messages/s here against ~37k for
mcap + protobuf and ~22k for plain mcap + JSON) with ``disable_seeking=True``, so
the file is written strictly front to back and a killed process never leaves a
half-rewritten chunk header behind.  ``flush`` closes the current chunk; we flush at
least once per simulated second (``flush_interval_s``), so a SIGKILL loses at most
that much and ``swarmnav log recover`` rebuilds an indexed file from the rest.
"""

from __future__ import annotations

import importlib.metadata
import json
import math
import sys
import threading
import time
from pathlib import Path
from typing import Any

import foxglove
import numpy as np
from foxglove.channels import (
    FrameTransformChannel,
    LaserScanChannel,
    PoseInFrameChannel,
    PosesInFrameChannel,
    SceneUpdateChannel,
)
from foxglove.mcap import MCAPCompression, MCAPWriteOptions
from foxglove.websocket import ServerListener
from foxglove.messages import (
    Color,
    CubePrimitive,
    CylinderPrimitive,
    FrameTransform,
    LaserScan,
    Pose,
    PoseInFrame,
    PosesInFrame,
    Quaternion,
    SceneEntity,
    SceneUpdate,
    Timestamp,
    Vector3,
)

from swarmnav.models.errors import ConfigError
from swarmnav.sim.recording import ObstacleInfo, RunContext, StepFrame

TOPICS = (
    "/tf",
    "/robot/pose",
    "/planner/path",
    "/obstacles",
    "/range/scan",
    "/wheels",
    "/controller",
    "/events",
)
WORLD_FRAME = "world"
BASE_FRAME = "base_link"
MJCF_ATTACHMENT = "scene.xml"
LOG_PROFILE = "swarmnav"
DEFAULT_LIVE_PORT = 8765

WHEELS_SCHEMA = {
    "title": "swarmnav.WheelSpeeds",
    "type": "object",
    "properties": {
        "command_left_rad_s": {"type": "number"},
        "command_right_rad_s": {"type": "number"},
        "measured_left_rad_s": {"type": "number"},
        "measured_right_rad_s": {"type": "number"},
    },
}
CONTROLLER_SCHEMA = {
    "title": "swarmnav.ControllerState",
    "type": "object",
    "properties": {
        "linear_m_s": {"type": "number"},
        "angular_rad_s": {"type": "number"},
        "waypoint_index": {"type": "integer"},
    },
}
EVENT_SCHEMA = {
    "title": "swarmnav.Event",
    "type": "object",
    "properties": {
        "kind": {
            "type": "string",
            "description": "goal_reached | collision_begin | collision_end | timeout",
        },
        "details": {"type": "object"},
    },
}

_STATIC_COLOUR = (0.55, 0.35, 0.25, 1.0)
_MOVING_COLOUR = (0.85, 0.25, 0.2, 1.0)


def time_ns(time_s: float) -> int:
    """Simulation seconds to the integer nanoseconds used as MCAP log time."""
    return int(round(time_s * 1e9))


def _stamp(t_ns: int) -> Timestamp:
    return Timestamp(t_ns // 1_000_000_000, t_ns % 1_000_000_000)


def _json_value(value: Any) -> Any:
    """Turn numpy scalars / arrays (and anything else odd) into JSON-able values."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    return str(value)


def dumps(value: Any) -> str:
    """Deterministic JSON text for metadata values and JSON messages."""
    return json.dumps(value, sort_keys=True, default=_json_value)


def _json_schema(schema: dict[str, Any]) -> foxglove.Schema:
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


def _obstacle_entity(info: ObstacleInfo, x_m: float, y_m: float, t_ns: int) -> SceneEntity:
    kind, primitive = _obstacle_primitive(info, x_m, y_m)
    return SceneEntity(
        timestamp=_stamp(t_ns), frame_id=WORLD_FRAME, id=info.entity_id, **{kind: [primitive]}
    )


def _yaw_quaternion(yaw_rad: float) -> Quaternion:
    return Quaternion(z=math.sin(0.5 * yaw_rad), w=math.cos(0.5 * yaw_rad))


def beam_origin(context: RunContext) -> tuple[float, float]:
    """(distance from base_link's origin, height) of the rangefinder sites.

    The rangefinders sit on the rim of the body and point outward, so a beam's
    reading plus this distance is the range from base_link's origin that a
    LaserScan needs.
    """
    return float(context.sensor_offset_m), float(context.sensor_height_m)


def versions(run_versions: dict[str, str]) -> dict[str, str]:
    """The run's versions (swarmnav, MuJoCo, Python) plus the log writer's."""
    try:
        writer = importlib.metadata.version("foxglove-sdk")
    except importlib.metadata.PackageNotFoundError:
        writer = "unknown"
    return {"foxglove_sdk": writer, **run_versions}


class _LateSubscribers(ServerListener):
    """Server listener: remembers topics a Foxglove client subscribed to.

    The path and the static obstacles are sent once, at t = 0; a client that
    connects later would never see them.  The recorder re-sends them on the next
    step after such a subscription (to every sink, so the MCAP file gets the
    extra copy too, but only when someone actually watched).
    """

    def __init__(self) -> None:
        super().__init__()
        self._lock = threading.Lock()
        self._topics: set[str] = set()

    def on_subscribe(self, client, channel) -> None:
        with self._lock:
            self._topics.add(channel.topic)

    def take(self) -> set[str]:
        with self._lock:
            topics, self._topics = self._topics, set()
        return topics


class McapRecorder:
    """Writes one run to an MCAP file (and optionally serves it live).

    Args:
        path: the ``.mcap`` file to create (parent directories are made).
        flush_interval_s: close the current chunk at least this often in simulated
            time; 1 s loses at most one simulated second to a SIGKILL.
        live: also serve every channel over Foxglove's WebSocket protocol.
        live_host, live_port: where the live server listens (loopback by default;
            port 0 picks a free one, see :attr:`live_port_bound`).
        live_speed: with ``live``, hold the run to this multiple of real time so a
            viewer can follow it (``None`` or 0: as fast as it goes).  Only the
            pacing uses the wall clock; nothing of it reaches the log.
        overwrite: replace an existing file instead of refusing.
    """

    def __init__(
        self,
        path: str | Path,
        *,
        flush_interval_s: float = 1.0,
        live: bool = False,
        live_host: str = "127.0.0.1",
        live_port: int = DEFAULT_LIVE_PORT,
        live_speed: float | None = 1.0,
        overwrite: bool = False,
    ):
        if flush_interval_s <= 0:
            raise ValueError("flush_interval_s must be positive")
        self.file_path = Path(path)
        self.flush_interval_s = float(flush_interval_s)
        self.live = live
        self.live_host = live_host
        self.live_port = live_port
        self.live_speed = live_speed if live and live_speed else None
        self.overwrite = overwrite
        self.messages_written = 0
        self._listener: _LateSubscribers | None = None
        self._wall_start_s = 0.0
        self._last_path: PosesInFrame | None = None
        self.flushes = 0
        self._writer = None
        self._server = None
        self._context: RunContext | None = None
        self._next_flush_ns = 0
        self._last_ns = 0
        self._moving_infos: tuple[ObstacleInfo, ...] = ()
        self._static_entities: list[SceneEntity] = []

    # -- Recorder protocol -------------------------------------------------

    def start(self, context: RunContext) -> None:
        """Open the file (and server), write metadata, attachment and t=0 obstacles."""
        self._context = context
        self.file_path.parent.mkdir(parents=True, exist_ok=True)
        self._fox = foxglove.Context()
        options = MCAPWriteOptions(
            compression=MCAPCompression.Zstd,
            profile=LOG_PROFILE,
            disable_seeking=True,
            compression_threads=0,  # the 2 cores belong to the simulation
        )
        self._writer = foxglove.open_mcap(
            self.file_path, allow_overwrite=self.overwrite, context=self._fox, writer_options=options
        )
        if self.live:
            self._listener = _LateSubscribers()
            try:
                self._server = foxglove.start_server(
                    name=f"swarmnav {context.scenario_name}",
                    host=self.live_host,
                    port=self.live_port,
                    context=self._fox,
                    server_listener=self._listener,
                )
            except Exception as error:  # foxglove raises its own error types
                self._writer.close()
                self._writer = None
                raise ConfigError(
                    "--live", f"cannot serve on {self.live_host}:{self.live_port} ({error})"
                ) from error
            self._wall_start_s = time.perf_counter()
            # The one line a user needs to connect; the CLI cannot know the port earlier.
            print(f"live view: ws://{self.live_host}:{self._server.port} "
                  f"(Foxglove: Open connection > Foxglove WebSocket)", file=sys.stderr)
        self._tf = FrameTransformChannel("/tf", context=self._fox)
        self._pose = PoseInFrameChannel("/robot/pose", context=self._fox)
        self._path = PosesInFrameChannel("/planner/path", context=self._fox)
        self._obstacles = SceneUpdateChannel("/obstacles", context=self._fox)
        self._scan = LaserScanChannel("/range/scan", context=self._fox)
        self._wheels = foxglove.Channel(
            "/wheels", schema=_json_schema(WHEELS_SCHEMA), message_encoding="json", context=self._fox
        )
        self._controller = foxglove.Channel(
            "/controller", schema=_json_schema(CONTROLLER_SCHEMA), message_encoding="json", context=self._fox
        )
        self._events = foxglove.Channel(
            "/events", schema=_json_schema(EVENT_SCHEMA), message_encoding="json", context=self._fox
        )
        self._write_run_records(context)

        angles = np.asarray(context.sensor_angles_rad, dtype=float)
        self._scan_start_rad = float(angles[0]) if angles.size else 0.0
        self._scan_end_rad = float(angles[-1]) if angles.size else 0.0
        if angles.size > 2 and not np.allclose(np.diff(angles), angles[1] - angles[0]):
            raise ValueError("LaserScan needs evenly spaced sensor angles")
        # Rangefinders sit on the body's rim; a LaserScan has one origin, so ranges
        # are reported from base_link's origin: distance + rim offset.
        self._beam_offset_m, height_m = beam_origin(context)
        self._scan_pose = Pose(position=Vector3(z=height_m), orientation=Quaternion(w=1.0))
        self._moving_infos = tuple(o for o in context.obstacles if o.moving)
        self._static_entities = [
            _obstacle_entity(o, o.position_m[0], o.position_m[1], 0)
            for o in context.obstacles
            if not o.moving
        ]
        self._obstacles.log(self._scene_update(0, None), log_time=0)
        self.messages_written += 1
        self._next_flush_ns = time_ns(self.flush_interval_s)

    def path(self, time_s: float, waypoints_m: np.ndarray) -> None:
        """Log the planned path (at the start and after every replan)."""
        t_ns = time_ns(time_s)
        points = np.asarray(waypoints_m, dtype=float)
        if points.ndim != 2 or points.shape[0] == 0:
            return
        deltas = np.diff(points[:, :2], axis=0)
        headings = np.arctan2(deltas[:, 1], deltas[:, 0]) if len(deltas) else np.zeros(0)
        headings = np.append(headings, headings[-1] if len(headings) else 0.0)
        poses = [
            Pose(position=Vector3(x=float(x), y=float(y), z=0.01), orientation=_yaw_quaternion(float(h)))
            for (x, y), h in zip(points[:, :2], headings)
        ]
        message = PosesInFrame(timestamp=_stamp(t_ns), frame_id=WORLD_FRAME, poses=poses)
        self._path.log(message, log_time=t_ns)
        self._last_path = message
        self._after_write(t_ns, 1)

    def step(self, frame: StepFrame) -> None:
        """Log one control step on every per-step channel."""
        t_ns = time_ns(frame.time_s)
        stamp = _stamp(t_ns)
        px, py, pz = (float(v) for v in frame.position_m)
        qw, qx, qy, qz = (float(v) for v in frame.quaternion_wxyz)
        translation = Vector3(x=px, y=py, z=pz)
        rotation = Quaternion(x=qx, y=qy, z=qz, w=qw)
        self._tf.log(
            FrameTransform(
                timestamp=stamp,
                parent_frame_id=WORLD_FRAME,
                child_frame_id=BASE_FRAME,
                translation=translation,
                rotation=rotation,
            ),
            log_time=t_ns,
        )
        self._pose.log(
            PoseInFrame(
                timestamp=stamp,
                frame_id=WORLD_FRAME,
                pose=Pose(position=translation, orientation=rotation),
            ),
            log_time=t_ns,
        )
        ranges = np.asarray(frame.range_m, dtype=float)
        ranges = np.where(np.isfinite(ranges) & (ranges >= 0.0), ranges + self._beam_offset_m, np.nan)
        self._scan.log(
            LaserScan(
                timestamp=stamp,
                frame_id=BASE_FRAME,
                pose=self._scan_pose,
                start_angle=self._scan_start_rad,
                end_angle=self._scan_end_rad,  # inclusive
                ranges=ranges.tolist(),
            ),
            log_time=t_ns,
        )
        command = frame.wheel_command_rad_s
        measured = frame.wheel_measured_rad_s
        self._wheels.log(
            dumps(
                {
                    "command_left_rad_s": float(command[0]),
                    "command_right_rad_s": float(command[1]),
                    "measured_left_rad_s": float(measured[0]),
                    "measured_right_rad_s": float(measured[1]),
                }
            ),
            log_time=t_ns,
        )
        self._controller.log(
            dumps(
                {
                    "linear_m_s": float(frame.linear_m_s),
                    "angular_rad_s": float(frame.angular_rad_s),
                    "waypoint_index": int(frame.waypoint_index),
                }
            ),
            log_time=t_ns,
        )
        written = 5
        late = self._listener.take() if self._listener is not None else ()
        if self._moving_infos or "/obstacles" in late:
            self._obstacles.log(self._scene_update(t_ns, frame.moving_obstacles_m), log_time=t_ns)
            written += 1
        if "/planner/path" in late and self._last_path is not None:
            self._path.log(self._last_path, log_time=t_ns)
            written += 1
        self._after_write(t_ns, written)
        if self.live_speed:
            ahead_s = frame.time_s / self.live_speed - (time.perf_counter() - self._wall_start_s)
            if ahead_s > 0:
                time.sleep(ahead_s)

    def event(self, time_s: float, kind: str, details: dict[str, Any]) -> None:
        """Log a discrete event and flush, so it survives a crash right after."""
        t_ns = time_ns(time_s)
        self._events.log(dumps({"kind": kind, "details": details}), log_time=t_ns)
        self._after_write(t_ns, 1)
        self._flush()

    def finish(self, summary: dict[str, Any]) -> None:
        """Write the outcome, close the file (indexed summary section) and the server."""
        if self._writer is None:
            return
        try:
            # Wall-clock figures would make two identical runs' logs differ: left out.
            outcome = {k: dumps(v) for k, v in summary.items() if not k.startswith("wall_")}
            self._writer.write_metadata("outcome", outcome)
            self._writer.close()
        finally:
            self._writer = None
            for channel in (self._wheels, self._controller, self._events):
                # foxglove keeps every JSON Channel in a module-level dict: drop ours.
                foxglove.channel._channels_by_id.pop(channel.id(), None)
            if self._server is not None:
                self._server.stop()
                self._server = None

    # -- helpers -----------------------------------------------------------

    @property
    def live_port_bound(self) -> int | None:
        """The port the live server actually listens on (``live_port=0`` picks one)."""
        return None if self._server is None else self._server.port

    def _write_run_records(self, context: RunContext) -> None:
        writer = self._writer
        writer.write_metadata(
            "scenario", {"name": context.scenario_name, "toml": context.scenario_toml}
        )
        writer.write_metadata(
            "planner", {"name": context.planner_name, "params": dumps(context.planner_params)}
        )
        writer.write_metadata(
            "navigator", {"name": context.navigator_name, "params": dumps(context.navigator_params)}
        )
        writer.write_metadata(
            "run",
            {
                "seed": str(int(context.seed)),
                "world_seed": str(int(context.world_seed)),
                "control_dt_s": repr(float(context.control_dt_s)),
                "physics_dt_s": repr(float(context.physics_dt_s)),
                "sensor_angles_rad": dumps([float(a) for a in context.sensor_angles_rad]),
                "sensor_range_m": repr(float(context.sensor_range_m)),
                "sensor_offset_m": repr(beam_origin(context)[0]),
                "sensor_height_m": repr(beam_origin(context)[1]),
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
            },
        )
        writer.write_metadata("versions", versions(context.versions))
        writer.attach(
            log_time=0,
            create_time=0,
            name=MJCF_ATTACHMENT,
            media_type="application/xml",
            data=context.mjcf_xml.encode(),
        )

    def _scene_update(self, t_ns: int, moving_xy_m: np.ndarray | None) -> SceneUpdate:
        entities = list(self._static_entities)
        if moving_xy_m is None:
            moving_xy_m = np.array([o.position_m[:2] for o in self._moving_infos]).reshape(-1, 2)
        for info, (x_m, y_m) in zip(self._moving_infos, np.asarray(moving_xy_m, dtype=float)):
            entities.append(_obstacle_entity(info, float(x_m), float(y_m), t_ns))
        return SceneUpdate(entities=entities)

    def _after_write(self, t_ns: int, count: int) -> None:
        self.messages_written += count
        self._last_ns = max(self._last_ns, t_ns)
        if t_ns >= self._next_flush_ns:
            self._flush()

    def _flush(self) -> None:
        if self._writer is None:
            return
        self._writer.flush()
        self.flushes += 1
        step_ns = time_ns(self.flush_interval_s)
        self._next_flush_ns = (self._last_ns // step_ns + 1) * step_ns


def default_log_path(scenario: str, planner: str, seed: int, stamp: str, directory: str | Path = "logs") -> Path:
    """``logs/<scenario>_<planner>_seed<N>_<stamp>.mcap`` (the caller supplies the stamp)."""
    return Path(directory) / f"{scenario}_{planner}_seed{seed}_{stamp}.mcap"
