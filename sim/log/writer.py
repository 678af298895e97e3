"""The run log: a Recorder that writes an MCAP file Foxglove opens as is.

One :class:`McapRecorder` per run.  It owns one ``foxglove.Context``; the MCAP
file and, with ``live=True``, a loopback WebSocket server for Foxglove
(:mod:`sim.log.live_view`) are both sinks of that context, so they see exactly the
same messages.  The channels, time stamps and names are in :mod:`sim.log.format`.

Metadata records: ``scenario`` (name, TOML text), ``planner`` and ``navigator`` (name, JSON params),
``run`` (seed, world seed, time steps, sensor layout, obstacles), ``versions`` and, from
``finish``, ``outcome`` (the runner's summary).  Values are plain text where they are
strings (Foxglove shows ``goal_reached``, not ``"goal_reached"``) and JSON where they are
numbers, booleans, lists or objects (:func:`sim.log.format.metadata_text`).  Attachment:
``scene.xml``, the compiled MJCF.  Everything needed to re-simulate is in the file.

The writer is the foxglove SDK with ``disable_seeking=True``, so the file is
written strictly front to back and a killed process never leaves a
half-rewritten chunk header behind.  It writes into a :class:`sim.log.file.LogFile`,
so a failure to open or to write (a full disk) is an ``OSError`` naming the file.
``flush`` closes the current chunk; we flush at least once per simulated second
(``flush_interval_s``), so a SIGKILL loses at most that much and ``swarmnav log
recover`` rebuilds an indexed file from the rest.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any, Callable

import foxglove
import numpy as np
from foxglove.channels import LogChannel, PosesInFrameChannel, SceneUpdateChannel
from foxglove.mcap import MCAPCompression, MCAPWriteOptions
from foxglove.messages import (
    FrameTransform,
    LaserScan,
    Pose,
    PoseInFrame,
    PosesInFrame,
    SceneUpdate,
    Vector3,
)

from swarmnav.sim.log.map_channel import MapChannel
from swarmnav.sim.log.live_view import DEFAULT_LIVE_HOST, DEFAULT_LIVE_PORT, LiveServer
from swarmnav.sim.log.encoding import SceneEncoder, StepEncoder, timestamp_field
from swarmnav.sim.log.file import LogFile
from swarmnav.sim.log.format import (
    BASE_FRAME,
    CONTROLLER_SCHEMA,
    EVENTS_TOPIC,
    LOG_PROFILE,
    MJCF_ATTACHMENT,
    NAVIGATOR_TOPIC,
    SCENE_TOPIC,
    TOPICS,
    WHEELS_SCHEMA,
    WORLD_FRAME,
    default_log_path,
    dumps,
    metadata_text,
    scan_list_from_ranges,
    time_ns,
    writer_versions,
)
from swarmnav.sim.log.messages import (
    belief_update,
    chassis_radius_m,
    controller_json,
    event_log,
    json_schema,
    obstacle_entity,
    obstacle_template,
    run_metadata,
    scene_update,
    stamp,
    wheels_json,
    yaw_quaternion,
)
from swarmnav.sim.log.pacing import RealTimePacer
from swarmnav.sim.recording import ObstacleInfo, RunContext, StepFrame

# TOPICS and default_log_path live in sim.log.format; re-exported for existing callers.
__all__ = ["McapRecorder", "TOPICS", "default_log_path"]

ZSTD_LEVEL = 1  # chunk compression level (see start)


class _WriteFailureFilter(logging.Filter):
    """Drops foxglove's per-message "error logging message: McapError(...)" lines.

    Once a write to the file failed, foxglove logs one such warning for every
    further message; the recorder reports the failure itself, once, as an
    ``OSError`` naming the file.
    """

    def filter(self, record: logging.LogRecord) -> bool:
        return "McapError" not in record.getMessage()


_FOXGLOVE_SINK_LOGGER = logging.getLogger("foxglove.log_sink_set")
if not any(isinstance(f, _WriteFailureFilter) for f in _FOXGLOVE_SINK_LOGGER.filters):
    _FOXGLOVE_SINK_LOGGER.addFilter(_WriteFailureFilter())


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
            viewer can follow it (``None`` or 0: as fast as it goes), through a
            :class:`sim.log.pacing.RealTimePacer`.
        on_live: called with the server's URL once it listens (the caller prints it;
            the recorder never prints).
        overwrite: replace an existing file instead of refusing.

    Errors: ``start`` raises ``ConfigError`` for a live port it cannot serve
    (before the file exists) and ``OSError`` (with the file name) when the file
    cannot be created; any call raises ``OSError`` (with the file name and, e.g.,
    "No space left on device") once a write failed.  Everything written before
    the failure stays readable by ``swarmnav log recover``.
    """

    def __init__(
        self,
        path: str | Path,
        *,
        flush_interval_s: float = 1.0,
        live: bool = False,
        live_host: str = DEFAULT_LIVE_HOST,
        live_port: int = DEFAULT_LIVE_PORT,
        live_speed: float | None = 1.0,
        on_live: Callable[[str], None] | None = None,
        overwrite: bool = False,
    ):
        if not flush_interval_s > 0:
            raise ValueError("flush_interval_s must be positive")
        self.file_path = Path(path)
        self.flush_interval_s = float(flush_interval_s)
        self.live = live
        self.live_host = live_host
        self.live_port = live_port
        self.on_live = on_live
        self.overwrite = overwrite
        self.messages_written = 0
        self.flushes = 0
        self._pacer = RealTimePacer(live_speed) if live and live_speed else None
        self._server: LiveServer | None = None
        self._file: LogFile | None = None
        self._writer = None
        self._last_path: PosesInFrame | None = None
        self._next_flush_ns = 0
        self._last_ns = 0
        self._moving_infos: tuple[ObstacleInfo, ...] = ()
        self._json_channels: list[foxglove.Channel] = []
        self._navigator: SceneUpdateChannel | None = None  # made at the first belief with obstacles
        self._belief_drawn = False
        self._map: MapChannel | None = None

    # -- Recorder protocol -------------------------------------------------

    def start(self, context: RunContext) -> None:
        """Open the server (if live) and the file, write metadata, attachment and t=0 obstacles."""
        angles = np.asarray(context.sensor_angles_rad, dtype=float)
        if angles.size > 2 and not np.allclose(np.diff(angles), angles[1] - angles[0]):
            raise ValueError("LaserScan needs evenly spaced sensor angles")
        self._fox = foxglove.Context()
        if self.live:
            # Before the file: a busy port leaves nothing behind.
            self._server = LiveServer(self._fox, f"swarmnav {context.scenario_name}",
                                      host=self.live_host, port=self.live_port)
        try:
            self._file = LogFile(self.file_path, overwrite=self.overwrite)
        except OSError:
            self._stop_server()
            raise
        options = MCAPWriteOptions(
            compression=MCAPCompression.Zstd,
            # zstd level 1: in the closed loop it compresses a second of log in half the time of the
            # default level (3), to about the same size (dense-field-30: 289 vs 292 kB for 20 s).
            compression_level=ZSTD_LEVEL,
            profile=LOG_PROFILE,
            disable_seeking=True,
            compression_threads=0,  # the 2 cores belong to the simulation
        )
        self._writer = foxglove.open_mcap(self._file, context=self._fox, writer_options=options)
        # The per-step protobuf channels take bytes from a StepEncoder (sim.log.encoding): the SDK's
        # schemas and encoding, without building its message objects every step.
        self._tf, self._pose = (
            foxglove.Channel(topic, schema=message.get_schema(), message_encoding="protobuf", context=self._fox)
            for topic, message in (("/tf", FrameTransform), ("/robot/pose", PoseInFrame)))
        self._path = PosesInFrameChannel("/planner/path", context=self._fox)
        self._obstacles = foxglove.Channel("/obstacles", schema=SceneUpdate.get_schema(), message_encoding="protobuf",
                                           context=self._fox)
        self._scan = foxglove.Channel("/range/scan", schema=LaserScan.get_schema(), message_encoding="protobuf",
                                      context=self._fox)
        self._wheels, self._controller = self._json_channels = [
            foxglove.Channel(topic, schema=json_schema(schema), message_encoding="json", context=self._fox)
            for topic, schema in (("/wheels", WHEELS_SCHEMA), ("/controller", CONTROLLER_SCHEMA))
        ]
        self._events = LogChannel(EVENTS_TOPIC, context=self._fox)
        self._scene_channel = SceneUpdateChannel(SCENE_TOPIC, context=self._fox)
        self._guard(self._write_run_records, context)

        self._scan_start_rad = float(angles[0]) if angles.size else 0.0
        self._scan_end_rad = float(angles[-1]) if angles.size else 0.0
        self._beam_offset_m = float(context.sensor_offset_m)
        self._encoder = StepEncoder(WORLD_FRAME, BASE_FRAME,
                                    ((0.0, 0.0, float(context.sensor_height_m)), (0.0, 0.0, 0.0, 1.0)),
                                    self._scan_start_rad, self._scan_end_rad)  # end: inclusive
        self._moving_infos = tuple(o for o in context.obstacles if o.moving)
        static_entities = [obstacle_entity(o, o.position_m[0], o.position_m[1], 0).encode()
                           for o in context.obstacles if not o.moving]
        self._scene = SceneEncoder(static_entities, WORLD_FRAME,
                                   [(o.entity_id, obstacle_template(o)) for o in self._moving_infos])
        self._obstacles.base.log(self._scene_update(0, None), 0, None)
        self._scene_message = scene_update(context.arena_size_m, chassis_radius_m(context.mjcf_xml))
        self._scene_channel.log(self._scene_message, log_time=0)
        self.messages_written += 2
        self._next_flush_ns = time_ns(self.flush_interval_s)
        if self._pacer is not None:
            self._pacer.start(context)
        if self._server is not None and self.on_live is not None:
            self.on_live(self._server.url)
        self._raise_write_error()

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
            Pose(position=Vector3(x=float(x), y=float(y), z=0.01), orientation=yaw_quaternion(float(h)))
            for (x, y), h in zip(points[:, :2], headings)
        ]
        message = PosesInFrame(timestamp=stamp(t_ns), frame_id=WORLD_FRAME, poses=poses)
        self._path.log(message, log_time=t_ns)
        self._last_path = message
        self._after_write(t_ns, 1)

    def step(self, frame: StepFrame) -> None:
        """Log one control step on every per-step channel."""
        t_ns = time_ns(frame.time_s)
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
        late = self._server.late_topics() if self._server is not None else ()
        if self._moving_infos or "/obstacles" in late:
            self._obstacles.base.log(self._scene_update(t_ns, frame.moving_obstacles_m), t_ns, None)
            written += 1
        if SCENE_TOPIC in late:
            self._scene_channel.log(self._scene_message, log_time=t_ns)
            written += 1
        if "/planner/path" in late and self._last_path is not None:
            self._path.log(self._last_path, log_time=t_ns)
            written += 1
        written += self._log_belief(frame.belief, t_ns)
        self._after_write(t_ns, written)
        if self._pacer is not None:
            self._pacer.step(frame)

    def occupancy(self, time_s: float, grid: Any) -> None:
        """Log the sensed map on ``/map`` (:mod:`sim.log.map_channel`; the channel made at the first)."""
        t_ns = time_ns(time_s)
        if self._map is None:
            self._map = MapChannel(self._fox)
        self._map.log(t_ns, grid)
        self._after_write(t_ns, 1)

    def event(self, time_s: float, kind: str, details: dict[str, Any]) -> None:
        """Log a discrete event and flush, so it survives a crash right after."""
        t_ns = time_ns(time_s)
        self._events.log(event_log(t_ns, kind, details), log_time=t_ns)
        self._after_write(t_ns, 1)
        self._flush()

    def finish(self, summary: dict[str, Any]) -> None:
        """Write the outcome, close the file (indexed summary section) and the server.

        After a failed write nothing more is written: the file is closed as it is
        (and stays recoverable), and no second error is raised.
        """
        if self._writer is None:
            self._stop_server()
            return
        writer, log_file = self._writer, self._file
        self._writer = None
        try:
            if log_file.error is None:
                # Wall-clock figures would make two identical runs' logs differ: left out.
                outcome = {k: metadata_text(v) for k, v in summary.items() if not k.startswith("wall_")}
                self._guard(writer.write_metadata, "outcome", outcome)
                self._guard(writer.close)
            else:
                try:
                    writer.close()
                except RuntimeError:
                    pass  # the write error was reported when it happened
        finally:
            log_file.close()
            for channel in self._json_channels:
                # foxglove keeps JSON channels in a registry of its own; closing is its public API.
                channel.close()
            self._stop_server()

    # -- helpers -----------------------------------------------------------

    @property
    def live_port_bound(self) -> int | None:
        """The port the live server actually listens on (``live_port=0`` picks one)."""
        return None if self._server is None else self._server.port

    def _stop_server(self) -> None:
        if self._server is not None:
            self._server.stop()
            self._server = None

    def _raise_write_error(self) -> None:
        if self._file is not None and self._file.error is not None:
            raise self._file.error

    def _guard(self, call: Callable, *args: Any) -> Any:
        """Run a writer call; a failed write surfaces as the file's own OSError."""
        try:
            return call(*args)
        except RuntimeError:
            self._raise_write_error()
            raise

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
        writer.write_metadata("run", run_metadata(context))
        writer.write_metadata("versions", writer_versions(context.versions))
        writer.attach(
            log_time=0,
            create_time=0,
            name=MJCF_ATTACHMENT,
            media_type="application/xml",
            data=context.mjcf_xml.encode(),
        )

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

    def _after_write(self, t_ns: int, count: int) -> None:
        self.messages_written += count
        self._last_ns = max(self._last_ns, t_ns)
        if t_ns >= self._next_flush_ns:
            self._flush()
        elif self._file.error is not None:  # a chunk filled up and could not be written
            raise self._file.error

    def _flush(self) -> None:
        if self._writer is None:
            return
        self._guard(self._writer.flush)
        self._raise_write_error()
        self.flushes += 1
        step_ns = time_ns(self.flush_interval_s)
        self._next_flush_ns = (self._last_ns // step_ns + 1) * step_ns
