"""Decoded messages of a ``ros2`` log into the rows a :class:`swarmnav.log.reader.RunLog` is made of.

The reader (:mod:`swarmnav.log.reader`) decodes each CDR message with ``mcap-ros2-support``'s
decoder and hands it here with its topic; :class:`Ros2Rows` appends the numbers to the
same rows the ``swarmnav`` profile's messages fill, so everything after the reader
(``plot``, ``replay``, ``log info``) reads both profiles alike.

The base pose is ``map`` -> ``odom`` (``/tf_static``, or ``/tf`` when the run estimates
odometry) composed with ``odom`` -> ``base_link`` (``/tf``); with the identity ``map`` ->
``odom`` it is ``odom`` -> ``base_link`` itself, bit for bit.  Scans: +inf (nothing in range,
REP 117) becomes NaN, the ``swarmnav`` profile's convention; ranges are float32 in a
LaserScan.  The active waypoint is not in a ``ros2`` log: ``waypoint_index`` is -1.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from swarmnav.log.columns import Rows
from swarmnav.log.format import BASE_FRAME, MAP_FRAME, ODOM_FRAME, ROS2_EVENTS_TOPIC


def _multiply(a: tuple, b: tuple) -> tuple[float, float, float, float]:
    """Hamilton product of quaternions (w, x, y, z)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw)


def _rotate(q: tuple, v: tuple) -> tuple[float, float, float]:
    w, x, y, z = _multiply(_multiply(q, (0.0, *v)), (q[0], -q[1], -q[2], -q[3]))
    return x, y, z


class Ros2Rows:
    """Appends decoded ``ros2`` messages to a decoder's rows (``tf``, ``ranges``, ``wheels``, ...)."""

    def __init__(self, rows: Any):
        self.rows = rows
        self._map_odom: tuple | None = None  # (xyz, wxyz); None: identity
        self._measured = Rows(3)  # t, left, right
        self._command = Rows(3)

    def add(self, topic: str, t: float, d: Any) -> None:
        rows = self.rows
        if topic in ("/tf", "/tf_static"):
            for transform in d.transforms:
                self._transform(t, transform)
        elif topic == "/scan":
            if rows.scan_span_rad is None:
                rows.scan_span_rad = (float(d.angle_min), float(d.angle_max))
                rows.ranges = Rows(len(d.ranges))
            rows.scan_time_s.append((t,))
            rows.ranges.append([math.nan if math.isinf(r) else r for r in d.ranges])
        elif topic == "/joint_states":
            self._measured.append((t, *d.velocity[:2]))
        elif topic == "/wheels/command":
            self._command.append((t, *d.velocity[:2]))
        elif topic == "/cmd_vel":
            rows.controller.append((t, d.linear.x, d.angular.z, -1))
        elif topic == "/plan":
            rows.paths.append((t, np.array([(p.pose.position.x, p.pose.position.y) for p in d.poses],
                                            dtype=float).reshape(-1, 2)))
        elif topic == "/obstacles":
            for marker in d.markers:
                track, last = rows.tracks.setdefault(marker.ns, (Rows(3), [None]))
                if last[0] == t:
                    continue
                last[0] = t
                track.append((t, marker.pose.position.x, marker.pose.position.y))
        elif topic == ROS2_EVENTS_TOPIC:  # decoded by swarmnav.log.reader.event_decoder: (kind, details)
            kind, details = d
            rows.events.append((t, kind, details))

    def _transform(self, t: float, stamped: Any) -> None:
        parent, child = stamped.header.frame_id, stamped.child_frame_id
        tr, rot = stamped.transform.translation, stamped.transform.rotation
        xyz, wxyz = (tr.x, tr.y, tr.z), (rot.w, rot.x, rot.y, rot.z)
        if (parent, child) == (MAP_FRAME, ODOM_FRAME):
            identity = xyz == (0.0, 0.0, 0.0) and wxyz == (1.0, 0.0, 0.0, 0.0)
            self._map_odom = None if identity else (xyz, wxyz)
        elif (parent, child) == (ODOM_FRAME, BASE_FRAME):
            if self._map_odom is not None:
                offset, turn = self._map_odom
                xyz = tuple(o + r for o, r in zip(offset, _rotate(turn, xyz)))
                wxyz = _multiply(turn, wxyz)
            self.rows.tf.append((t, *xyz, *wxyz))

    def finish(self) -> None:
        """Pair the measured and commanded wheel speeds step by step into the wheel rows."""
        measured, command = self._measured.array(), self._command.array()
        n = min(len(measured), len(command))
        for m, c in zip(measured[:n], command[:n]):
            self.rows.wheels.append((m[0], c[1], c[2], m[1], m[2]))
