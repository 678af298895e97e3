"""``swarmnav log recover``: rewrite whatever can be read of a log as a complete MCAP file."""

from __future__ import annotations

import os
from pathlib import Path

from mcap.records import Message
from mcap.writer import CompressionType, Writer

from swarmnav.models.contained_files import check_output_target
from swarmnav.models.errors import ConfigError
from swarmnav.log.records import RawLog, read_records


def recover_log(source: str | Path, target: str | Path) -> RawLog:
    """Rewrite every complete record of ``source`` as a complete, indexed MCAP file.

    The target gets the same schemas, channels, messages (with their times and
    sequence numbers), metadata and attachments, plus a ``recovery`` metadata
    record saying what was lost.

    Returns:
        The :class:`RawLog` read from ``source``.

    Raises:
        LogError: ``source`` is not a readable MCAP file.
        ConfigError: ``target`` is ``source``.
        OSError: ``target`` cannot be written (with its file name).
    """
    if not str(target).strip() or Path(target).name in ("", ".", ".."):
        raise ConfigError("OUT", "must name a file", str(target))
    check_output_target(target, "OUT", folder_ok=False)  # never replace a device or a FIFO with the copy
    target = Path(target)
    if target.resolve() == Path(source).resolve():
        raise ConfigError("OUT", "is the source file: write the recovered copy elsewhere", str(target))
    target.parent.mkdir(parents=True, exist_ok=True)
    partial = target.with_name(target.name + ".part")  # renamed when complete: no half file at OUT
    try:
        with partial.open("wb") as stream:
            raw = _copy(source, stream)
        os.replace(partial, target)
    except OSError as error:
        partial.unlink(missing_ok=True)
        if error.filename == str(partial):  # name the file the user gave
            raise type(error)(error.errno, error.strerror, str(target)) from None
        raise
    except BaseException:
        partial.unlink(missing_ok=True)
        raise
    return raw


def _copy(source: str | Path, stream) -> RawLog:
    """Stream ``source``'s messages into an MCAP writer on ``stream``, then its metadata and attachments."""
    writer = Writer(stream, compression=CompressionType.ZSTD)
    copier = _Copier(writer)
    raw = read_records(source, on_message=copier.message)  # streamed: memory is one chunk
    copier.start(raw)
    for cid in sorted(raw.channels):
        copier.channel(raw, cid)  # channels that carried no message are kept too
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
            "messages_recovered": str(copier.messages),
            "last_time_ns": str(raw.last_time_ns),
            "problem": raw.problem or "",
        },
    )
    writer.finish()
    return raw


class _Copier:
    """Copies each message into the writer as it is read, registering its schema and channel first."""

    def __init__(self, writer: Writer):
        self.writer = writer
        self.started = False
        self.messages = 0
        self._schemas: dict[int, int] = {}
        self._channels: dict[int, int] = {}

    def start(self, raw: RawLog) -> None:
        if not self.started:
            self.writer.start(profile=raw.profile, library=raw.library or "swarmnav log recover")
            self.started = True

    def channel(self, raw: RawLog, cid: int) -> int | None:
        if cid in self._channels:
            return self._channels[cid]
        channel = raw.channels.get(cid)
        if channel is None:
            return None  # a message whose channel record was lost cannot be indexed
        self.start(raw)
        schema = raw.schemas.get(channel.schema_id)
        if schema is not None and channel.schema_id not in self._schemas:
            self._schemas[channel.schema_id] = self.writer.register_schema(
                name=schema.name, encoding=schema.encoding, data=schema.data)
        self._channels[cid] = self.writer.register_channel(
            topic=channel.topic, message_encoding=channel.message_encoding,
            schema_id=self._schemas.get(channel.schema_id, 0), metadata=dict(channel.metadata))
        return self._channels[cid]

    def message(self, raw: RawLog, m: Message) -> None:
        channel_id = self.channel(raw, m.channel_id)
        if channel_id is None:
            return
        self.writer.add_message(channel_id=channel_id, log_time=m.log_time, data=m.data,
                                publish_time=m.publish_time, sequence=m.sequence)
        self.messages += 1
