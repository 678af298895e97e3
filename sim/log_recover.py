"""``swarmnav log recover``: rewrite whatever can be read of a log as a complete MCAP file."""

from __future__ import annotations

from pathlib import Path

from mcap.writer import CompressionType, Writer

from swarmnav.models.errors import ConfigError
from swarmnav.sim.mcap_records import RawLog, read_records


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
    raw = read_records(source)
    target = Path(target)
    if target.resolve() == Path(source).resolve():
        raise ConfigError("OUT", "is the source file: write the recovered copy elsewhere", str(target))
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
            if m.channel_id not in channel_ids:
                continue  # a message whose channel record was lost cannot be indexed
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
