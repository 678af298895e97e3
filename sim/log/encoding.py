"""The per-step protobuf messages of a run log, encoded from templates.

``/tf`` (``foxglove.FrameTransform``), ``/robot/pose`` (``foxglove.PoseInFrame``)
and ``/range/scan`` (``foxglove.LaserScan``) are written every control step.
Building the SDK's message objects and letting it encode them costs more than
the encoding itself, so :class:`StepEncoder` writes the protobuf wire format
directly: the constant parts (frame ids, the scan's pose and angles) once per
run, and per step only the time stamp varints and the doubles, with
:mod:`struct`.  The bytes are the SDK's own (prost's proto3 rules: fields in
number order, a zero (or negative zero) double, a zero integer and an empty
string or repeated field left out, a message field written even when empty);
``tests/test_log_encoding.py`` compares them with ``encode()`` of the SDK's
messages on random values, zeros, NaN and infinities included.
"""

from __future__ import annotations

import struct

_DOUBLE = struct.Struct("<d")
_WIRE_VARINT, _WIRE_DOUBLE, _WIRE_LENGTH = 0, 1, 2
# Vector3 (x, y, z) and Quaternion (x, y, z, w) with no zero component: tag byte + double each.
_VECTOR3_FULL = struct.Struct("<BdBdBd")
_QUATERNION_FULL = struct.Struct("<BdBdBdBd")
_FULL_TAGS = (0x09, 0x11, 0x19, 0x21)  # fields 1..4, wire type 1 (64-bit)


def varint(value: int) -> bytes:
    """Protobuf base-128 varint; a negative value as its 64-bit two's complement (int64)."""
    if 0 <= value < 0x80:
        return bytes((value,))
    value &= (1 << 64) - 1
    out = bytearray()
    while value > 0x7F:
        out.append((value & 0x7F) | 0x80)
        value >>= 7
    out.append(value)
    return bytes(out)


def tag(field: int, wire_type: int) -> bytes:
    return varint(field << 3 | wire_type)


def length_delimited(field: int, body: bytes) -> bytes:
    """A string, bytes, packed or message field: tag, length, body (written even when empty)."""
    return tag(field, _WIRE_LENGTH) + varint(len(body)) + body


def doubles(values) -> bytes:
    """Fields 1, 2, ... of doubles, each left out when zero (proto3)."""
    return b"".join(tag(number, _WIRE_DOUBLE) + _DOUBLE.pack(v)
                    for number, v in enumerate(values, start=1) if v != 0.0)


def vector3(x: float, y: float, z: float) -> bytes:
    """A ``foxglove.Vector3`` message body."""
    if x != 0.0 and y != 0.0 and z != 0.0:
        return _VECTOR3_FULL.pack(0x09, x, 0x11, y, 0x19, z)
    return doubles((x, y, z))


def quaternion(x: float, y: float, z: float, w: float) -> bytes:
    """A ``foxglove.Quaternion`` message body."""
    if x != 0.0 and y != 0.0 and z != 0.0 and w != 0.0:
        return _QUATERNION_FULL.pack(0x09, x, 0x11, y, 0x19, z, 0x21, w)
    return doubles((x, y, z, w))


# Cached fields: a control rate repeats a few dozen nanos values every second, and seconds count slowly.
_NANOS_FIELDS: dict[int, bytes] = {}
_SECONDS_FIELDS: dict[int, bytes] = {}
_CACHE_LIMIT = 4096


def _cached_field(cache: dict[int, bytes], key: bytes, value: int) -> bytes:
    field = cache.get(value)
    if field is None:
        field = key + varint(value) if value else b""
        if len(cache) < _CACHE_LIMIT:
            cache[value] = field
    return field


def timestamp_field(t_ns: int) -> bytes:
    """Field 1 (``timestamp``, a ``google.protobuf.Timestamp``) of simulation time ``t_ns``."""
    seconds, nanos = divmod(t_ns, 1_000_000_000)
    body = _cached_field(_SECONDS_FIELDS, b"\x08", seconds) + _cached_field(_NANOS_FIELDS, b"\x10", nanos)
    return b"\x0a" + bytes((len(body),)) + body  # at most 1 + 10 + 1 + 5 bytes: a one-byte length


def string_field(field: int, text: str) -> bytes:
    return length_delimited(field, text.encode()) if text else b""


def double_field(field: int, value: float) -> bytes:
    return tag(field, _WIRE_DOUBLE) + _DOUBLE.pack(value) if value != 0.0 else b""


def pose(position: tuple[float, float, float], orientation: tuple[float, float, float, float]) -> bytes:
    """A ``foxglove.Pose`` message body."""
    return length_delimited(1, vector3(*position)) + length_delimited(2, quaternion(*orientation))


class StepEncoder:
    """The three per-step protobuf messages of one run.

    Args:
        world_frame, base_frame: the frame ids.
        scan_pose: the scan origin in ``base_frame``: position (x, y, z) and orientation
            (x, y, z, w, the protobuf order).
        scan_start_rad, scan_end_rad: the scan's first and last beam angles.
    """

    def __init__(self, world_frame: str, base_frame: str,
                 scan_pose: tuple[tuple[float, float, float], tuple[float, float, float, float]],
                 scan_start_rad: float, scan_end_rad: float):
        self._tf_frames = string_field(2, world_frame) + string_field(3, base_frame)
        self._pose_frame = string_field(2, world_frame)
        self._scan_head = (string_field(2, base_frame) + length_delimited(3, pose(*scan_pose))
                           + double_field(4, scan_start_rad) + double_field(5, scan_end_rad))
        self._ranges: dict[int, tuple[bytes, struct.Struct]] = {}  # beam count -> field head, packer

    def transform(self, stamp: bytes, position: tuple[float, float, float],
                  orientation: tuple[float, float, float, float]) -> tuple[bytes, bytes]:
        """``/tf`` (world -> base) and ``/robot/pose`` bodies; ``stamp`` from :func:`timestamp_field`,
        ``orientation`` in protobuf order (x, y, z, w)."""
        translation = vector3(*position)
        rotation = quaternion(*orientation)
        # Each body is at most 4 * 9 bytes: one-byte lengths.
        translation_length, rotation_length = bytes((len(translation),)), bytes((len(rotation),))
        pose_length = bytes((len(translation) + len(rotation) + 4,))
        return (b"".join((stamp, self._tf_frames, b"\x22", translation_length, translation,
                          b"\x2a", rotation_length, rotation)),
                b"".join((stamp, self._pose_frame, b"\x1a", pose_length, b"\x0a", translation_length, translation,
                          b"\x12", rotation_length, rotation)))

    def scan(self, stamp: bytes, ranges: list[float]) -> bytes:
        """``/range/scan`` body for the ranges (LaserScan convention: NaN for nothing in range)."""
        if not ranges:
            return stamp + self._scan_head
        packer = self._ranges.get(len(ranges))
        if packer is None:
            packer = self._ranges[len(ranges)] = (length_delimited(6, bytes(8 * len(ranges)))[:-8 * len(ranges)],
                                                  struct.Struct(f"<{len(ranges)}d"))
        field_head, doubles_struct = packer
        return b"".join((stamp, self._scan_head, field_head, doubles_struct.pack(*ranges)))


# SceneEntity's primitive lists (foxglove.SceneEntity field numbers).
_PRIMITIVE_FIELDS = {"cubes": 8, "cylinders": 10}
_IDENTITY_ORIENTATION = length_delimited(2, quaternion(0.0, 0.0, 0.0, 1.0))


class SceneEncoder:
    """``/obstacles`` (a ``foxglove.SceneUpdate``) bodies: the static entities encoded once, each
    moving one per step from its position.

    Args:
        static_entities: the encoded static ``SceneEntity`` messages, in order.
        frame_id: the moving entities' frame.
        moving: per moving obstacle, its entity id and :func:`swarmnav.log.messages.obstacle_template`.
    """

    def __init__(self, static_entities: list[bytes], frame_id: str,
                 moving: list[tuple[str, tuple[str, float, bytes]]]):
        self._static = b"".join(length_delimited(2, entity) for entity in static_entities)
        self._moving = [(string_field(2, frame_id) + string_field(3, entity_id), tag(_PRIMITIVE_FIELDS[kind], _WIRE_LENGTH),
                         z_m, tail) for entity_id, (kind, z_m, tail) in moving]

    def update(self, stamp: bytes, moving_xy_m: list[list[float]]) -> bytes:
        """The update with the moving obstacles at ``moving_xy_m`` (one (x, y) per moving obstacle);
        ``stamp`` (:func:`timestamp_field`) is their entities' time stamp."""
        parts = [self._static]
        for (ids, primitive_tag, z_m, tail), (x_m, y_m) in zip(self._moving, moving_xy_m):
            position = vector3(x_m, y_m, z_m)
            pose = b"\x0a" + bytes((len(position),)) + position + _IDENTITY_ORIENTATION
            primitive = b"\x0a" + bytes((len(pose),)) + pose + tail
            entity = b"".join((stamp, ids, primitive_tag, varint(len(primitive)), primitive))
            parts.append(b"\x12" + varint(len(entity)) + entity)
        return b"".join(parts)
