"""Reading the records of an MCAP file that may be cut off anywhere.

A log written by a process that was killed has no summary section, and a copied,
downloaded or disk-full file may end at any byte, so the default
``mcap.reader.make_reader`` cannot be used.  :func:`read_records` walks the
top-level records by their heads (opcode, u64 length) and parses each complete
one with ``mcap``'s record classes (chunk CRCs checked).  Every complete chunk,
that is everything up to the writer's last flush, is kept, and :class:`RawLog`
says how much that was and why the rest could not be read.

Memory is bounded by one chunk, not by the file: with ``on_message`` each message
is handed over as it is read and not kept (``plot``, ``replay``, ``log recover``
stream a log of any length this way); only counts and the last time stamp are.
"""

from __future__ import annotations

import io
import os
import stat
import struct
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO, Callable

from mcap.data_stream import ReadDataStream
from mcap.exceptions import McapError
from mcap.opcode import Opcode
from mcap.records import Attachment, Channel, Chunk, Footer, Header, Message, Metadata, Schema
from mcap.stream_reader import get_chunk_data_stream

from swarmnav.models.errors import ConfigError

MAGIC = b"\x89MCAP0\r\n"
_RECORD_HEAD = struct.Struct("<BQ")
_MESSAGE_HEAD = struct.Struct("<HIQQ")  # channel id, sequence, log time, publish time


class LogError(ConfigError):
    """A file that is not a readable run log (bad input: the CLI exits with 2)."""

    def __init__(self, path: str | Path, problem: str):
        super().__init__("LOG", problem, str(path))


@dataclass
class RawLog:
    """The records of an MCAP file, as far as they could be read.

    Attributes:
        complete: True when the footer and the closing magic were read (the file
            was closed properly).
        bytes_read: bytes up to the end of the last record read intact.
        file_bytes: size of the file.
        problem: why reading stopped early (None when complete).
        messages: every complete message, in file order (empty when they were streamed to a callback).
        message_count, channel_counts, last_time_ns: what was read, streamed or kept.
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
    message_count: int = 0
    channel_counts: dict[int, int] = field(default_factory=dict)
    last_time_ns: int = 0

    def topic_of(self, message: Message) -> str:
        return self.channels[message.channel_id].topic

    def counts(self) -> dict[str, int]:
        """Messages per topic, in channel order."""
        per_channel = {cid: 0 for cid in self.channels}
        for cid, count in self.channel_counts.items():
            per_channel[cid] = per_channel.get(cid, 0) + count
        return {self.channels[cid].topic if cid in self.channels else f"channel {cid}": n
                for cid, n in per_channel.items()}

    def last_time_s(self) -> float:
        return self.last_time_ns * 1e-9

    def recovery_line(self) -> str:
        """One sentence on how much of a damaged file could be read."""
        if self.complete:
            return f"complete: {self.message_count} messages"
        return (
            f"truncated ({self.problem}): recovered {self.message_count} messages up to "
            f"t={self.last_time_s():.3f} s from {self.bytes_read} of {self.file_bytes} bytes"
        )


class RawLogView:
    """What a log read either way (:class:`~swarmnav.log.reader.RunLog`, the streamed
    :class:`~swarmnav.log.summary.LogSummary`) says from its :class:`RawLog` alone."""

    raw: RawLog
    metadata: dict[str, dict[str, str]]  # the run's metadata (a field of RunLog, read from ``raw`` by LogSummary)

    @property
    def complete(self) -> bool:
        return self.raw.complete

    @property
    def scenario_name(self) -> str:
        return self.metadata.get("scenario", {}).get("name", "?")

    @property
    def duration_s(self) -> float:
        return self.raw.last_time_s()


def open_regular(path: Path) -> BinaryIO:
    """Open a regular file for reading; anything else is a one-line LogError."""
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        raise LogError(path, "no such file") from None
    except OSError as error:
        raise LogError(path, error.strerror or str(error)) from None
    if stat.S_ISDIR(mode):
        raise LogError(path, "is a directory, not an MCAP file")
    if not stat.S_ISREG(mode):
        raise LogError(path, "not a regular file (an MCAP log is a file)")
    try:
        return path.open("rb")
    except OSError as error:
        raise LogError(path, error.strerror or str(error)) from None


def _describe(error: Exception) -> str:
    text = str(error).strip().splitlines()[0] if str(error).strip() else ""
    name = type(error).__name__
    return f"{name}: {text}" if text else name


def _check_magic(stream: BinaryIO, path: Path, size: int) -> None:
    magic = stream.read(len(MAGIC))
    if magic != MAGIC:
        if not magic:
            raise LogError(path, "empty file (0 bytes), not an MCAP log")
        if MAGIC.startswith(magic):
            raise LogError(path, f"truncated: the file ends inside the MCAP magic bytes ({size} bytes)")
        raise LogError(path, "not an MCAP file (bad magic bytes)")


def _message(body: memoryview) -> Message:
    channel_id, sequence, log_time, publish_time = _MESSAGE_HEAD.unpack_from(body)
    return Message(channel_id=channel_id, sequence=sequence, log_time=log_time, publish_time=publish_time,
                   data=bytes(body[_MESSAGE_HEAD.size:]))


def _chunk_records(chunk: Chunk) -> list:
    """The records of a chunk, decompressed and checked against its CRC.

    Messages (nearly all of a log) are unpacked here with one ``struct`` call each;
    mcap's per-field reader takes ~10x longer.  Schemas and channels use mcap's classes.
    """
    stream, size = get_chunk_data_stream(chunk, validate_crc=True)  # mcap decompresses and checks
    data = stream.read(size)
    if len(data) != size:
        raise McapError(f"chunk holds {len(data)} bytes, its header says {size}")
    view = memoryview(data)
    records: list = []
    position = 0
    while position < len(view):
        opcode, length = _RECORD_HEAD.unpack_from(view, position)
        start = position + _RECORD_HEAD.size
        position = start + length
        if position > len(view):
            raise McapError("a record runs past the end of its chunk")
        if opcode == Opcode.MESSAGE:
            records.append(_message(view[start:position]))
        elif opcode in (Opcode.SCHEMA, Opcode.CHANNEL):
            records.append(_KEPT[opcode].read(ReadDataStream(io.BytesIO(view[start:position]))))
    return records


def _parse(opcode: int, body: bytes) -> list:
    """The records in one top-level record's body (a chunk holds many)."""
    if opcode == Opcode.MESSAGE:
        return [_message(memoryview(body))]
    record = _KEPT[opcode].read(ReadDataStream(io.BytesIO(body)))
    return _chunk_records(record) if opcode == Opcode.CHUNK else [record]


OnMessage = Callable[[RawLog, Message], None]


def _keep(raw: RawLog, record, on_message: OnMessage | None) -> None:
    if isinstance(record, Message):
        raw.message_count += 1
        raw.channel_counts[record.channel_id] = raw.channel_counts.get(record.channel_id, 0) + 1
        raw.last_time_ns = max(raw.last_time_ns, record.log_time)
        if on_message is None:
            raw.messages.append(record)
        else:
            on_message(raw, record)
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


def read_records(path: str | Path, on_message: OnMessage | None = None) -> RawLog:
    """Read every intact record of an MCAP file, tolerating a cut at any byte.

    Args:
        on_message: called with each message as it is read (its channel is in ``raw.channels`` by
            then); the messages are then not kept.  None: kept in ``raw.messages``.

    Walks the top-level records by their (opcode, length) heads; a record that
    does not fit in the file, or whose contents do not parse (CRC, zstd), ends the
    read, and everything before it is kept.  Index and summary records are
    skipped: everything they say is in the data section.

    Raises:
        LogError: the file does not exist, is not a regular file, is empty, is not
            MCAP at all, or is cut before its first record.
    """
    path = Path(path)
    with open_regular(path) as stream:
        size = os.fstat(stream.fileno()).st_size
        raw = RawLog(path=path, file_bytes=size)
        _check_magic(stream, path, size)
        position = len(MAGIC)
        problem: str | None = "no footer: the writer was not closed"
        while position < size:
            head = stream.read(_RECORD_HEAD.size)
            if len(head) < _RECORD_HEAD.size:
                problem = f"file ends inside a record header at byte {position}"
                break
            opcode, length = _RECORD_HEAD.unpack(head)
            end = position + _RECORD_HEAD.size + length
            if end > size:
                problem = f"file ends inside a record at byte {position} ({size - position} of {end - position} bytes)"
                break
            if opcode in _KEPT:
                try:
                    records = _parse(opcode, stream.read(length))
                except _CORRUPT as error:
                    problem = f"corrupt record at byte {position} ({_describe(error)})"
                    break
                for record in records:
                    _keep(raw, record, on_message)
            else:
                stream.seek(end)
            position = raw.bytes_read = end
            if opcode == Opcode.FOOTER:
                tail = stream.read(len(MAGIC) + 1)
                if tail == MAGIC:
                    problem = None
                elif MAGIC.startswith(tail):
                    problem = "file ends inside the closing magic bytes"
                else:
                    problem = "bad closing magic bytes after the footer"
                break
        if raw.bytes_read == 0:
            raise LogError(path, f"truncated before the first record ({problem})")
        raw.complete = problem is None
        raw.problem = problem
    return raw


_KEPT = {Opcode.HEADER: Header, Opcode.SCHEMA: Schema, Opcode.CHANNEL: Channel, Opcode.MESSAGE: Message,
         Opcode.CHUNK: Chunk, Opcode.METADATA: Metadata, Opcode.ATTACHMENT: Attachment, Opcode.FOOTER: Footer}
# What a complete record with damaged contents raises while it is parsed or decompressed:
# mcap's and struct's errors, and whatever the decompressors raise (zstandard.ZstdError,
# lz4's RuntimeError), so any Exception; the record's bytes are the only input here.
_CORRUPT = Exception
