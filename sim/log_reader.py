"""Reading run logs back: a run log decoded into NumPy arrays.

Only this module, :mod:`sim.mcap_records` and the writer know MCAP.  Everything
else (replay, plot, ``log info``) gets a :class:`RunLog` of NumPy arrays.  The
records are read by :func:`sim.mcap_records.read_records`, which survives a file
cut off anywhere; a truncated file is an error here unless the caller accepts
one (``plot`` does, ``log info`` and ``replay`` point to ``log recover``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np
from mcap.records import Channel
from google.protobuf.message import DecodeError
from mcap_protobuf.decoder import DecoderFactory

from swarmnav.sim.log_format import CHANNELS, LOG_PROFILE, MJCF_ATTACHMENT, TOPICS
from swarmnav.sim.mcap_records import LogError, RawLog, read_records


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
    if channel.message_encoding == "json":
        return json.loads
    decoder = protobuf.decoder_for(channel.message_encoding, raw.schemas.get(channel.schema_id))
    if decoder is None:
        raise LogError(raw.path, f"cannot decode channel {channel.topic} ({channel.message_encoding})")
    return decoder


def check_channels(raw: RawLog) -> None:
    """Every channel on a swarmnav topic carries the schema and encoding the writer uses.

    Raises:
        LogError: a channel does not (another tool's file), or the file has no ``/tf``
            channel and is not a swarmnav log at all.
    """
    for channel in raw.channels.values():
        expected = CHANNELS.get(channel.topic)
        if expected is None:
            continue  # channels of other topics are left alone
        schema = raw.schemas.get(channel.schema_id)
        found = (channel.message_encoding, schema.name if schema is not None else "")
        if found != expected:
            raise LogError(raw.path, f"not a swarmnav run log: channel {channel.topic} carries "
                                     f"{found[1] or 'no schema'} ({found[0]}), expected {expected[1]} "
                                     f"({expected[0]})")
    if "/tf" not in {c.topic for c in raw.channels.values()} and raw.profile != LOG_PROFILE:
        raise LogError(raw.path, "not a swarmnav run log (no /tf channel)")


def decode(raw: RawLog) -> RunLog:
    """Decode a :class:`RawLog` of a swarmnav run into arrays.

    Raises:
        LogError: a channel or a message is not what a swarmnav log holds.
    """
    check_channels(raw)
    try:
        return _decode(raw)
    except (DecodeError, ValueError, KeyError, TypeError, AttributeError, IndexError) as error:
        raise LogError(raw.path, f"a message cannot be decoded ({type(error).__name__}: {error})") from None


def _decode(raw: RawLog) -> RunLog:
    protobuf = DecoderFactory()
    decoders = {cid: _decoder_for(raw, c, protobuf) for cid, c in raw.channels.items() if c.topic in CHANNELS}
    by_topic: dict[str, list[tuple[float, Any]]] = {topic: [] for topic in TOPICS}
    for m in raw.messages:
        decoder = decoders.get(m.channel_id)
        if decoder is not None:
            by_topic[raw.channels[m.channel_id].topic].append((m.log_time * 1e-9, decoder(m.data)))

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
