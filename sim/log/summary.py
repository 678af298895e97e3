"""What a log holds, without reading its messages: ``swarmnav log info`` on a log of any length.

A complete MCAP file ends with a summary section: the schemas, the channels, a
statistics record (messages per channel, first and last time stamp) and indexes
of the metadata records and the chunks.  :func:`read_summary` answers from those,
and reads only the ``/events`` messages, through the chunk index (the chunks that
hold none are skipped), so a long log costs what its summary and events cost.
A damaged chunk inside a file whose summary is intact is therefore not noticed
here; ``plot``, ``replay`` and ``log recover``, which read every message, report it.

A file without a usable summary (cut off by a killed run, or written without one)
is walked record by record instead (:func:`swarmnav.log.records.read_records`),
decoding only its ``/events`` messages: what was recovered, with the file marked
incomplete so the caller can warn.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mcap.reader import SeekingReader
from mcap.records import Message

from swarmnav.log.format import events_topic, metadata_value
from swarmnav.log.reader import check_channels, check_has_steps, event_decoder
from swarmnav.log.records import LogError, RawLog, RawLogView, open_regular, read_records
from swarmnav.log.run_metadata import checked_run_metadata


@dataclass
class LogSummary(RawLogView):
    """The facts ``log info`` prints (the attributes :func:`swarmnav.cli.log.describe` reads)."""

    raw: RawLog  # schemas, channels, metadata, counts; no messages
    events: list[tuple[float, str, dict[str, Any]]]
    outcome: dict[str, Any] | None
    from_summary: bool  # True: answered from the summary section, no message but the events read

    @property
    def metadata(self) -> dict[str, dict[str, str]]:
        return self.raw.metadata

    @property
    def counts(self) -> dict[str, int]:
        return self.raw.counts()

    @property
    def schema_names(self) -> dict[str, str]:
        raw = self.raw
        return {c.topic: raw.schemas[c.schema_id].name if c.schema_id in raw.schemas else ""
                for c in raw.channels.values()}


class _Events:
    """Decodes ``/events`` messages (``foxglove.Log``, or the JSON of older logs) into event tuples."""

    def __init__(self, raw: RawLog):
        self.raw = raw
        self._decoders: dict[int, Any] = {}

    def __call__(self, message: Message) -> tuple[float, str, dict[str, Any]]:
        try:
            decode = self._decoders.get(message.channel_id)
            if decode is None:
                decode = self._decoders[message.channel_id] = event_decoder(
                    self.raw, self.raw.channels[message.channel_id])
            kind, details = decode(message.data)
            return message.log_time * 1e-9, kind, details
        except LogError:
            raise
        except Exception as error:  # protobuf's DecodeError, JSON's ValueError, a missing field
            raise LogError(self.raw.path, f"an event cannot be decoded ({type(error).__name__}: {error})") from None


def _outcome(raw: RawLog) -> dict[str, Any] | None:
    if "outcome" not in raw.metadata:
        return None
    return {key: metadata_value(text) for key, text in raw.metadata["outcome"].items()}


def _from_summary(path: Path) -> LogSummary | None:
    """The summary of a complete file with statistics, or None when it has none (or is cut)."""
    with open_regular(path) as stream:
        size = os.fstat(stream.fileno()).st_size
        try:
            reader = SeekingReader(stream, validate_crcs=True)
            summary = reader.get_summary()
            if summary is None or summary.statistics is None:
                return None
            header = reader.get_header()
            metadata = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        except Exception:  # no footer, a damaged summary: the caller walks the records instead
            return None
        statistics = summary.statistics
        raw = RawLog(path=path, profile=header.profile, library=header.library, schemas=dict(summary.schemas),
                     channels=dict(summary.channels), metadata=metadata, complete=True, bytes_read=size,
                     file_bytes=size, message_count=statistics.message_count,
                     channel_counts=dict(statistics.channel_message_counts),
                     last_time_ns=statistics.message_end_time if statistics.message_count else 0)
        check_channels(raw)
        events = []
        topic = events_topic(raw.profile)
        if any(c.topic == topic for c in raw.channels.values()):
            decode = _Events(raw)
            try:
                for _, _, message in reader.iter_messages(topics=[topic], log_time_order=True):
                    events.append(decode(message))
            except LogError:
                raise
            except Exception:  # an index that does not hold: walk the records instead
                return None
    return LogSummary(raw, events, _outcome(raw), from_summary=True)


def read_summary(path: str | Path) -> LogSummary:
    """What a log holds: from its summary section, else from its records (a truncated file).

    Raises:
        LogError: not a readable MCAP file or not a swarmnav log.
    """
    path = Path(path)
    found = _from_summary(path)
    summary = found if found is not None else from_records(path)
    checked_run_metadata(str(path), summary.raw.metadata.get("run", {}))  # as every other reader checks it
    check_has_steps(summary.raw, summary.counts.get("/tf", 0))  # the one truncation rule
    return summary


def from_records(path: str | Path) -> LogSummary:
    """What a log holds, walking its records (what :func:`read_summary` does for a file without summary)."""
    events: list[tuple[float, str, dict[str, Any]]] = []
    topics: dict[int, bool] = {}
    decoders: list[_Events] = []  # made at the first event, on the RawLog being read

    def keep_events(raw: RawLog, message: Message) -> None:
        if message.channel_id not in topics:
            channel = raw.channels.get(message.channel_id)
            topics[message.channel_id] = channel is not None and channel.topic == events_topic(raw.profile)
        if topics[message.channel_id]:
            if not decoders:
                decoders.append(_Events(raw))
            events.append(decoders[0](message))

    raw = read_records(Path(path), on_message=keep_events)
    check_channels(raw)
    return LogSummary(raw, events, _outcome(raw), from_summary=False)
