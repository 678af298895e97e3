"""Reading run logs back: a run log decoded into NumPy arrays.

Only this module, :mod:`swarmnav.log.records` and the writer know MCAP.  Everything
else (replay, plot, ``log info``) gets a :class:`RunLog` of NumPy arrays.  The
records are read by :func:`swarmnav.log.records.read_records`, which survives a file
cut off anywhere, and streamed into arrays as they are read (:class:`_Decoder`),
so memory follows the arrays, not the file.  ``plot``, ``log info`` and ``replay``
read a truncated file as far as it goes, with a warning line
(:func:`truncation_advice`); with ``allow_truncated=False`` it is an error.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np
from mcap.records import Channel, Message
from google.protobuf.message import DecodeError
from mcap_protobuf.decoder import DecoderFactory
from mcap_ros2.decoder import DecoderFactory as Ros2DecoderFactory

from swarmnav.log.format import (
    CHANNELS,
    EVENTS_TOPIC,
    LEGACY_CHANNELS,
    LOG_PROFILE,
    MJCF_ATTACHMENT,
    ROS2_CHANNELS,
    ROS2_PROFILE,
    TOPICS,
    event_from_text,
    events_topic,
    metadata_value,
)
from swarmnav.log.columns import Rows
from swarmnav.log.records import LogError, RawLog, RawLogView, read_records
from swarmnav.log.ros2_reader import Ros2Rows
from swarmnav.log.run_metadata import checked_run_metadata


# -- decoding into arrays ------------------------------------------------------


@dataclass
class RunLog(RawLogView):
    """A run log decoded into arrays (times in seconds of simulation).

    Attributes:
        time_s, position_m, quaternion_wxyz, heading_rad: the base pose from ``/tf``.
        scan_time_s, scan_angles_rad, range_m: ``/range/scan``; ranges are from
            base_link's origin, NaN where a beam saw nothing.
        wheel_time_s, wheel_command_rad_s, wheel_measured_rad_s: ``/wheels``, (N, 2) left/right.
        controller_time_s, linear_m_s, angular_rad_s, waypoint_index: ``/controller``.
        paths: ``(time_s, waypoints (P, 2))`` per ``/planner/path`` message.
        obstacles: static description per obstacle from the ``run`` metadata.
        obstacle_tracks: entity id -> (times (T,), xy (T, 2)) from ``/obstacles``.
        events: ``(time_s, kind, details)``.
        outcome: the runner's summary (None when the run did not finish).
    """

    raw: RawLog
    metadata: dict[str, dict[str, str]]
    mjcf_xml: str | None
    counts: dict[str, int]
    schema_names: dict[str, str]
    time_s: np.ndarray
    position_m: np.ndarray
    quaternion_wxyz: np.ndarray
    heading_rad: np.ndarray
    scan_time_s: np.ndarray
    scan_angles_rad: np.ndarray
    range_m: np.ndarray
    wheel_time_s: np.ndarray
    wheel_command_rad_s: np.ndarray
    wheel_measured_rad_s: np.ndarray
    controller_time_s: np.ndarray
    linear_m_s: np.ndarray
    angular_rad_s: np.ndarray
    waypoint_index: np.ndarray
    paths: list[tuple[float, np.ndarray]]
    obstacles: list[dict[str, Any]]
    obstacle_tracks: dict[str, tuple[np.ndarray, np.ndarray]]
    events: list[tuple[float, str, dict[str, Any]]]
    outcome: dict[str, Any] | None
    run: dict[str, Any] = field(default_factory=dict)  # the ``run`` record, checked (sim/log/run_metadata.py)

    def run_value(self, key: str, default: Any = None) -> Any:
        """A value of the ``run`` metadata record, JSON-decoded and checked when the log was read."""
        return self.run.get(key, default)


def _decoder_for(raw: RawLog, channel: Channel, protobuf: DecoderFactory) -> Callable[[bytes], Any]:
    if channel.message_encoding == "json":
        return json.loads
    factory = Ros2DecoderFactory() if channel.message_encoding == "cdr" else protobuf
    try:
        decoder = factory.decoder_for(channel.message_encoding, raw.schemas.get(channel.schema_id))
    except Exception as error:  # a schema text mcap_ros2 cannot parse
        raise LogError(raw.path, f"cannot decode channel {channel.topic} ({type(error).__name__}: {error})") from None
    if decoder is None:
        raise LogError(raw.path, f"cannot decode channel {channel.topic} ({channel.message_encoding})")
    return decoder


def event_decoder(raw: RawLog, channel: Channel,
                  protobuf: DecoderFactory | None = None) -> Callable[[bytes], tuple[str, dict[str, Any]]]:
    """Bytes of an ``/events`` message to (kind, details): a ``foxglove.Log`` whose message is
    :func:`swarmnav.log.format.event_text`, or the JSON ``swarmnav.Event`` of older logs."""
    decode = _decoder_for(raw, channel, protobuf or DecoderFactory())
    if channel.message_encoding == "json":
        def legacy(data: bytes) -> tuple[str, dict[str, Any]]:
            event = decode(data)
            return str(event.get("kind", "?")), event.get("details", {})
        return legacy
    if channel.message_encoding == "cdr":
        return lambda data: event_from_text(decode(data).msg)
    return lambda data: event_from_text(decode(data).message)


def channel_table(raw: RawLog) -> dict[str, tuple[str, str]]:
    """topic -> (message encoding, schema name) of the log's profile (``ros2`` or ``swarmnav``)."""
    return ROS2_CHANNELS if raw.profile == ROS2_PROFILE else CHANNELS


def _check_channel(raw: RawLog, channel: Channel) -> None:
    expected = channel_table(raw).get(channel.topic)
    if expected is None:
        return  # channels of other topics are left alone
    schema = raw.schemas.get(channel.schema_id)
    found = (channel.message_encoding, schema.name if schema is not None else "")
    if found != expected and found != LEGACY_CHANNELS.get(channel.topic):
        raise LogError(raw.path, f"not a swarmnav run log: channel {channel.topic} carries "
                                 f"{found[1] or 'no schema'} ({found[0]}), expected {expected[1]} "
                                 f"({expected[0]})")


def check_channels(raw: RawLog) -> None:
    """Every channel on a swarmnav topic carries the schema and encoding the writer uses.

    Raises:
        LogError: a channel does not (another tool's file), or the file has no ``/tf``
            channel and is not a swarmnav log at all.
    """
    for channel in raw.channels.values():
        _check_channel(raw, channel)
    if "/tf" not in {c.topic for c in raw.channels.values()} and raw.profile != LOG_PROFILE:
        raise LogError(raw.path, "not a swarmnav run log (no /tf channel)")


class _Decoder:
    """Turns each message, as it is read, into rows of numbers (:class:`swarmnav.log.columns.Rows`).

    Nothing decoded is kept as a message object: memory is the numbers of the
    arrays a :class:`RunLog` holds, for a log of any length.
    """

    def __init__(self) -> None:
        self._protobuf = DecoderFactory()
        self._decoders: dict[int, tuple[str, Callable[[bytes], Any]] | None] = {}
        self.tf = Rows(8)  # t, x, y, z, qw, qx, qy, qz
        self.scan_time_s = Rows(1)
        self.ranges = Rows()
        self.scan_span_rad: tuple[float, float] | None = None
        self.wheels = Rows(5)  # t, command left/right, measured left/right
        self.controller = Rows(4)  # t, v, omega, waypoint index
        self.paths: list[tuple[float, np.ndarray]] = []
        self.tracks: dict[str, tuple[Rows, list]] = {}  # id -> ((t, x, y) rows, [last time])
        self.events: list[tuple[float, str, dict[str, Any]]] = []
        self._ros2 = Ros2Rows(self)

    def __call__(self, raw: RawLog, message: Message) -> None:
        channel_id = message.channel_id
        if channel_id not in self._decoders:
            channel = raw.channels.get(channel_id)
            if channel is None or channel.topic not in channel_table(raw):
                self._decoders[channel_id] = None
            else:
                _check_channel(raw, channel)
                decode = (event_decoder(raw, channel, self._protobuf) if channel.topic == events_topic(raw.profile)
                          else _decoder_for(raw, channel, self._protobuf))
                ros2 = channel.message_encoding == "cdr"
                self._decoders[channel_id] = (channel.topic, decode, self._ros2.add if ros2 else self._add)
        entry = self._decoders[channel_id]
        if entry is None:
            return
        topic, decoder, add = entry
        try:
            add(topic, message.log_time * 1e-9, decoder(message.data))
        except (DecodeError, ValueError, KeyError, TypeError, AttributeError, IndexError) as error:
            raise LogError(raw.path, f"a message cannot be decoded ({type(error).__name__}: {error})") from None

    def _add(self, topic: str, t: float, d: Any) -> None:
        if topic == "/tf":
            self.tf.append((t, d.translation.x, d.translation.y, d.translation.z,
                            d.rotation.w, d.rotation.x, d.rotation.y, d.rotation.z))
        elif topic == "/range/scan":
            if self.scan_span_rad is None:
                self.scan_span_rad = (d.start_angle, d.end_angle)
                self.ranges = Rows(len(d.ranges))
            self.scan_time_s.append((t,))
            self.ranges.append(d.ranges)
        elif topic == "/wheels":
            self.wheels.append((t, d["command_left_rad_s"], d["command_right_rad_s"],
                                d["measured_left_rad_s"], d["measured_right_rad_s"]))
        elif topic == "/controller":
            self.controller.append((t, d["linear_m_s"], d["angular_rad_s"], d["waypoint_index"]))
        elif topic == "/planner/path":
            self.paths.append((t, np.array([(p.position.x, p.position.y) for p in d.poses],
                                           dtype=float).reshape(-1, 2)))
        elif topic == "/obstacles":
            for entity in d.entities:
                primitives = entity.cylinders or entity.cubes
                if not primitives:
                    continue
                position = primitives[0].pose.position
                rows, last = self.tracks.setdefault(entity.id, (Rows(3), [None]))
                if last[0] == t:
                    continue
                last[0] = t
                rows.append((t, position.x, position.y))
        elif topic == EVENTS_TOPIC:
            kind, details = d
            self.events.append((t, kind, details))

    def run_log(self, raw: RawLog) -> RunLog:
        self._ros2.finish()
        tf = self.tf.array()
        quaternion_wxyz = tf[:, 4:8]
        w, x, y, z = quaternion_wxyz.T
        beams = self.ranges.width or 0
        start, end = self.scan_span_rad or (0.0, 0.0)
        wheels, controller = self.wheels.array(), self.controller.array()
        outcome = None
        if "outcome" in raw.metadata:
            outcome = {k: metadata_value(v) for k, v in raw.metadata["outcome"].items()}
        attachment = raw.attachments.get(MJCF_ATTACHMENT)
        run = checked_run_metadata(str(raw.path), raw.metadata.get("run", {}))
        try:
            mjcf_xml = attachment.data.decode() if attachment is not None else None
        except UnicodeDecodeError as exc:
            raise LogError(raw.path, f"its scene.xml is not UTF-8 text (byte {exc.start})") from None
        return RunLog(
            raw=raw,
            metadata=raw.metadata,
            mjcf_xml=mjcf_xml,
            counts=raw.counts(),
            schema_names={c.topic: raw.schemas[c.schema_id].name if c.schema_id in raw.schemas else ""
                          for c in raw.channels.values()},
            time_s=tf[:, 0].copy(),
            position_m=tf[:, 1:4].copy(),
            quaternion_wxyz=quaternion_wxyz.copy(),
            heading_rad=np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)),
            scan_time_s=self.scan_time_s.array()[:, 0],
            scan_angles_rad=np.linspace(start, end, beams) if self.scan_span_rad else np.zeros(0),
            range_m=self.ranges.array() if beams else np.zeros((0, 0)),
            wheel_time_s=wheels[:, 0].copy(),
            wheel_command_rad_s=wheels[:, 1:3].copy(),
            wheel_measured_rad_s=wheels[:, 3:5].copy(),
            controller_time_s=controller[:, 0].copy(),
            linear_m_s=controller[:, 1].copy(),
            angular_rad_s=controller[:, 2].copy(),
            waypoint_index=controller[:, 3].astype(int),
            paths=self.paths,
            obstacles=run.get("obstacles", []),
            obstacle_tracks={k: (rows.array()[:, 0].copy(), rows.array()[:, 1:3].copy())
                             for k, (rows, _) in self.tracks.items()},
            events=self.events,
            outcome=outcome,
            run=run,
        )


def read_log(path: str | Path, *, allow_truncated: bool = False) -> RunLog:
    """Read and decode a run log, streaming its messages into arrays (memory: the arrays, not the file).

    Args:
        path: the ``.mcap`` file.
        allow_truncated: accept a file without footer (what a killed run leaves);
            otherwise such a file is a :class:`LogError` that points to ``log recover``.

    Raises:
        LogError: not an MCAP file, not a swarmnav log, or truncated (unless allowed).
    """
    decoder = _Decoder()
    raw = read_records(path, on_message=decoder)
    if not raw.complete and not allow_truncated:
        raise LogError(path, truncation_advice(raw))
    check_channels(raw)
    check_has_steps(raw, len(decoder.tf))
    return decoder.run_log(raw)


def check_has_steps(raw: RawLog, steps: int) -> None:
    """The one truncation rule of every reader (``log info``, ``plot``, ``replay --video``, ``replay --verify``):
    a log is read as far as it goes, and one that holds no step at all (no ``/tf`` message: cut before its
    first step) is refused, the same one line for all of them.

    Raises:
        LogError: no step, naming what the file holds.
    """
    if steps == 0:
        raise LogError(raw.path, f"holds no step (no /tf message): nothing to show or replay ({raw.recovery_line()})")


def truncation_advice(raw: RawLog) -> str:
    """What was recovered of a file without footer, and how to get an indexed copy."""
    return f"{raw.recovery_line()}; run 'swarmnav log recover {raw.path} OUT' for an indexed copy"


def outcome_text(log: RunLog) -> str:
    """The outcome of a run: from the summary, or from the events of a cut-off log."""
    if log.outcome is not None:
        for key in ("outcome", "status", "result"):
            if key in log.outcome:
                return str(log.outcome[key])
    kinds = [kind for _, kind, _ in log.events]
    for kind in ("goal_reached", "timeout", "left_arena"):
        if kind in kinds:
            return kind
    return "none: the run did not finish (no outcome recorded)"
