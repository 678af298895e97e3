"""Reading run logs back: a stream reader that survives truncation, decoding, recovery.

Only this module and :mod:`sim.mcap_log` know MCAP.  Everything else (replay, plot,
``log info``) gets a :class:`RunLog` of NumPy arrays.

A log written by a process that was killed has no summary section, so the default
``mcap.reader.make_reader`` rejects it.  :func:`read_records` walks the file front
to back with ``mcap``'s ``StreamReader`` (chunk CRCs checked) and stops at the
first record that is cut off or corrupt; every chunk before it, that is everything
up to the writer's last flush, is kept, and :class:`RawLog` says how much that was.
:func:`recover_log` writes those records to a new, indexed MCAP file.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np
from mcap.exceptions import InvalidMagic, McapError
from mcap.records import Attachment, Channel, Footer, Header, Message, Metadata, Schema
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, Writer
from mcap_protobuf.decoder import DecoderFactory

from swarmnav.models.errors import ConfigError
from swarmnav.sim.mcap_log import MJCF_ATTACHMENT, TOPICS


class LogError(ConfigError):
    """A file that is not a readable run log (bad input: the CLI exits with 2)."""

    def __init__(self, path: str | Path, problem: str):
        super().__init__("LOG", problem, str(path))


@dataclass
class RawLog:
    """The records of an MCAP file, as far as they could be read.

    Attributes:
        complete: True when the footer was reached (the file was closed properly).
        bytes_read: bytes up to the end of the last record read intact.
        file_bytes: size of the file.
        problem: why reading stopped early (None when complete).
        messages: ``(channel_id, log_time_ns, publish_time_ns, sequence, data)`` in file order.
    """

    path: Path
    profile: str = ""
    library: str = ""
    schemas: dict[int, Schema] = field(default_factory=dict)
    channels: dict[int, Channel] = field(default_factory=dict)
    messages: list[Message] = field(default_factory=list)
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    attachments: dict[str, Attachment] = field(default_factory=dict)
    complete: bool = False
    bytes_read: int = 0
    file_bytes: int = 0
    problem: str | None = None

    def topic_of(self, message: Message) -> str:
        return self.channels[message.channel_id].topic

    def counts(self) -> dict[str, int]:
        """Messages per topic, in channel order."""
        per_channel = {cid: 0 for cid in self.channels}
        for message in self.messages:
            per_channel[message.channel_id] += 1
        return {self.channels[cid].topic: n for cid, n in per_channel.items()}

    def last_time_s(self) -> float:
        return max((m.log_time for m in self.messages), default=0) * 1e-9

    def recovery_line(self) -> str:
        """One sentence on how much of a damaged file could be read."""
        if self.complete:
            return f"complete: {len(self.messages)} messages"
        return (
            f"truncated ({self.problem}): recovered {len(self.messages)} messages up to "
            f"t={self.last_time_s():.3f} s from {self.bytes_read} of {self.file_bytes} bytes"
        )


def read_records(path: str | Path) -> RawLog:
    """Read every intact record of an MCAP file, tolerating a cut-off end.

    Raises:
        LogError: the file does not exist, is empty, or is not MCAP at all.
    """
    path = Path(path)
    if not path.is_file():
        raise LogError(path, "no such file")
    raw = RawLog(path=path, file_bytes=path.stat().st_size)
    with path.open("rb") as stream:
        records = StreamReader(stream, validate_crcs=True).records
        try:
            for record in records:
                raw.bytes_read = stream.tell()
                if isinstance(record, Message):
                    raw.messages.append(record)
                elif isinstance(record, Channel):
                    raw.channels.setdefault(record.id, record)
                elif isinstance(record, Schema):
                    raw.schemas.setdefault(record.id, record)
                elif isinstance(record, Metadata):
                    raw.metadata[record.name] = dict(record.metadata)
                elif isinstance(record, Attachment):
                    raw.attachments[record.name] = record
                elif isinstance(record, Header):
                    raw.profile, raw.library = record.profile, record.library
                elif isinstance(record, Footer):
                    raw.complete = True
        except InvalidMagic as error:
            raise LogError(path, "not an MCAP file (bad magic bytes)") from error
        except (McapError, ValueError, EOFError, OSError, ArithmeticError, UnicodeDecodeError) as error:
            # zstd / struct / CRC errors from a torn last chunk all end up here.
            if raw.bytes_read == 0 and not raw.messages and not raw.channels:
                raise LogError(path, f"not a readable MCAP file ({_describe(error)})") from error
            raw.problem = _describe(error)
            if raw.bytes_read == raw.file_bytes and type(error).__name__ == "EndOfFile":
                raw.problem = None  # it ends cleanly after a record: just never closed
        if not raw.complete and raw.problem is None:
            raw.problem = "no footer: the writer was not closed"
    return raw


def _describe(error: Exception) -> str:
    text = str(error).strip().splitlines()[0] if str(error).strip() else ""
    name = type(error).__name__
    if name == "EndOfFile":
        return "file ends inside a record"
    return f"{name}: {text}" if text else name


def recover_log(source: str | Path, target: str | Path) -> RawLog:
    """Rewrite whatever can be read of ``source`` as a complete, indexed MCAP file.

    The target gets the same schemas, channels, messages (with their times and
    sequence numbers), metadata and attachments, plus a ``recovery`` metadata
    record saying what was lost.

    Returns:
        The :class:`RawLog` read from ``source``.
    """
    raw = read_records(source)
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    with target.open("wb") as stream:
        writer = Writer(stream, compression=CompressionType.ZSTD)
        writer.start(profile=raw.profile, library=raw.library or "swarmnav log recover")
        schema_ids = {
            sid: writer.register_schema(name=s.name, encoding=s.encoding, data=s.data)
            for sid, s in sorted(raw.schemas.items())
        }
        channel_ids = {
            cid: writer.register_channel(
                topic=c.topic,
                message_encoding=c.message_encoding,
                schema_id=schema_ids.get(c.schema_id, 0),
                metadata=dict(c.metadata),
            )
            for cid, c in sorted(raw.channels.items())
        }
        for m in raw.messages:
            writer.add_message(
                channel_id=channel_ids[m.channel_id],
                log_time=m.log_time,
                data=m.data,
                publish_time=m.publish_time,
                sequence=m.sequence,
            )
        for name, values in raw.metadata.items():
            writer.add_metadata(name, values)
        for a in raw.attachments.values():
            writer.add_attachment(
                create_time=a.create_time, log_time=a.log_time, name=a.name,
                media_type=a.media_type, data=a.data,
            )
        writer.add_metadata(
            "recovery",
            {
                "source": str(Path(source)),
                "source_complete": str(raw.complete).lower(),
                "source_bytes": str(raw.file_bytes),
                "bytes_recovered": str(raw.bytes_read),
                "messages_recovered": str(len(raw.messages)),
                "last_time_ns": str(max((m.log_time for m in raw.messages), default=0)),
                "problem": raw.problem or "",
            },
        )
        writer.finish()
    return raw


# -- decoding into arrays ------------------------------------------------------


@dataclass
class RunLog:
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

    @property
    def complete(self) -> bool:
        return self.raw.complete

    @property
    def scenario_name(self) -> str:
        return self.metadata.get("scenario", {}).get("name", "?")

    @property
    def duration_s(self) -> float:
        return self.raw.last_time_s()

    def run_value(self, key: str, default: Any = None) -> Any:
        """A value of the ``run`` metadata record, JSON-decoded."""
        text = self.metadata.get("run", {}).get(key)
        return default if text is None else json.loads(text)


def _decoder_for(raw: RawLog, channel: Channel, protobuf: DecoderFactory) -> Callable[[bytes], Any]:
    schema = raw.schemas.get(channel.schema_id)
    if channel.message_encoding == "json":
        return json.loads
    decoder = protobuf.decoder_for(channel.message_encoding, schema)
    if decoder is None:
        raise LogError(raw.path, f"cannot decode channel {channel.topic} ({channel.message_encoding})")
    return decoder


def decode(raw: RawLog) -> RunLog:
    """Decode a :class:`RawLog` of a swarmnav run into arrays."""
    protobuf = DecoderFactory()
    decoders = {cid: _decoder_for(raw, c, protobuf) for cid, c in raw.channels.items()}
    by_topic: dict[str, list[tuple[float, Any]]] = {topic: [] for topic in TOPICS}
    for m in raw.messages:
        topic = raw.channels[m.channel_id].topic
        by_topic.setdefault(topic, []).append((m.log_time * 1e-9, decoders[m.channel_id](m.data)))

    tf = by_topic["/tf"]
    time_s = np.array([t for t, _ in tf], dtype=float)
    position_m = np.array(
        [(d.translation.x, d.translation.y, d.translation.z) for _, d in tf], dtype=float
    ).reshape(-1, 3)
    quaternion_wxyz = np.array(
        [(d.rotation.w, d.rotation.x, d.rotation.y, d.rotation.z) for _, d in tf], dtype=float
    ).reshape(-1, 4)
    w, x, y, z = quaternion_wxyz.T
    heading_rad = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))

    scans = by_topic["/range/scan"]
    beams = len(scans[0][1].ranges) if scans else 0
    range_m = np.array([list(d.ranges) for _, d in scans], dtype=float).reshape(-1, beams)
    if scans:
        first = scans[0][1]
        scan_angles_rad = np.linspace(first.start_angle, first.end_angle, beams)
    else:
        scan_angles_rad = np.zeros(0)

    wheels = by_topic["/wheels"]
    wheel_command = np.array(
        [(d["command_left_rad_s"], d["command_right_rad_s"]) for _, d in wheels], dtype=float
    ).reshape(-1, 2)
    wheel_measured = np.array(
        [(d["measured_left_rad_s"], d["measured_right_rad_s"]) for _, d in wheels], dtype=float
    ).reshape(-1, 2)

    controller = by_topic["/controller"]
    paths = [
        (t, np.array([(p.position.x, p.position.y) for p in d.poses], dtype=float).reshape(-1, 2))
        for t, d in by_topic["/planner/path"]
    ]
    tracks: dict[str, tuple[list[float], list[tuple[float, float]]]] = {}
    for t, update in by_topic["/obstacles"]:
        for entity in update.entities:
            primitives = list(entity.cylinders) or list(entity.cubes)
            if not primitives:
                continue
            position = primitives[0].pose.position
            times, xy = tracks.setdefault(entity.id, ([], []))
            if times and times[-1] == t:
                continue
            times.append(t)
            xy.append((position.x, position.y))
    events = [(t, d.get("kind", "?"), d.get("details", {})) for t, d in by_topic["/events"]]

    outcome = None
    if "outcome" in raw.metadata:
        outcome = {k: _loads_or_text(v) for k, v in raw.metadata["outcome"].items()}
    obstacles = json.loads(raw.metadata.get("run", {}).get("obstacles", "[]"))
    attachment = raw.attachments.get(MJCF_ATTACHMENT)
    return RunLog(
        raw=raw,
        metadata=raw.metadata,
        mjcf_xml=attachment.data.decode() if attachment is not None else None,
        counts=raw.counts(),
        schema_names={
            c.topic: raw.schemas[c.schema_id].name if c.schema_id in raw.schemas else ""
            for c in raw.channels.values()
        },
        time_s=time_s,
        position_m=position_m,
        quaternion_wxyz=quaternion_wxyz,
        heading_rad=heading_rad,
        scan_time_s=np.array([t for t, _ in scans], dtype=float),
        scan_angles_rad=scan_angles_rad,
        range_m=range_m,
        wheel_time_s=np.array([t for t, _ in wheels], dtype=float),
        wheel_command_rad_s=wheel_command,
        wheel_measured_rad_s=wheel_measured,
        controller_time_s=np.array([t for t, _ in controller], dtype=float),
        linear_m_s=np.array([d["linear_m_s"] for _, d in controller], dtype=float),
        angular_rad_s=np.array([d["angular_rad_s"] for _, d in controller], dtype=float),
        waypoint_index=np.array([d["waypoint_index"] for _, d in controller], dtype=int),
        paths=paths,
        obstacles=obstacles,
        obstacle_tracks={
            k: (np.array(ts, dtype=float), np.array(xy, dtype=float).reshape(-1, 2))
            for k, (ts, xy) in tracks.items()
        },
        events=events,
        outcome=outcome,
    )


def _loads_or_text(text: str) -> Any:
    try:
        return json.loads(text)
    except ValueError:
        return text


def read_log(path: str | Path, *, allow_truncated: bool = False) -> RunLog:
    """Read and decode a run log.

    Args:
        path: the ``.mcap`` file.
        allow_truncated: accept a file without footer (what a killed run leaves);
            otherwise such a file is a :class:`LogError` that points to ``log recover``.

    Raises:
        LogError: not an MCAP file, not a swarmnav log, or truncated (unless allowed).
    """
    raw = read_records(path)
    if not raw.complete and not allow_truncated:
        raise LogError(
            path,
            f"{raw.recovery_line()}; run 'swarmnav log recover {path} OUT' for an indexed copy",
        )
    if "/tf" not in {c.topic for c in raw.channels.values()}:
        raise LogError(path, "not a swarmnav run log (no /tf channel)")
    return decode(raw)


def outcome_text(log: RunLog) -> str:
    """The outcome of a run: from the summary, or from the events of a cut-off log."""
    if log.outcome is not None:
        for key in ("outcome", "status", "result"):
            if key in log.outcome:
                return str(log.outcome[key])
    kinds = [kind for _, kind, _ in log.events]
    for kind in ("goal_reached", "timeout"):
        if kind in kinds:
            return kind
    return "none: the run did not finish (no outcome recorded)"


def describe(log: RunLog) -> list[str]:
    """Lines for ``swarmnav log info``."""
    planner = log.metadata.get("planner", {})
    lines = [
        f"log:        {log.raw.path}",
        f"scenario:   {log.scenario_name}",
        f"planner:    {planner.get('name', '?')} {planner.get('params', '')}",
        f"seed:       {log.metadata.get('run', {}).get('seed', '?')}",
        f"duration:   {log.duration_s:.3f} s (simulation)",
        f"outcome:    {outcome_text(log)}",
        f"file:       {log.raw.recovery_line()}",
    ]
    recovery = log.metadata.get("recovery")
    if recovery:
        lines.append(f"recovered:  from {recovery.get('source')} ({recovery.get('problem') or 'complete'}); "
                     f"{recovery.get('messages_recovered')} messages kept")
    collisions = sum(1 for _, kind, _ in log.events if kind == "collision_begin")
    lines.append(f"collisions: {collisions}")
    versions = log.metadata.get("versions", {})
    if versions:
        lines.append("versions:   " + ", ".join(f"{k} {v}" for k, v in sorted(versions.items())))
    lines.append("channels:")
    width = max((len(t) for t in log.counts), default=0)
    for topic, count in log.counts.items():
        lines.append(f"  {topic:<{width}}  {count:>7}  {log.schema_names.get(topic, '')}")
    if log.outcome:
        lines.append("summary:")
        for key, value in log.outcome.items():
            if isinstance(value, float) and math.isfinite(value):
                value = f"{value:.6g}"
            lines.append(f"  {key}: {value}")
    return lines
