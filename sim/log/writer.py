"""The run log: a Recorder that writes an MCAP file Foxglove opens as is.

One :class:`McapRecorder` per run.  It owns one ``foxglove.Context``; the MCAP
file and, with ``live=True``, a loopback WebSocket server for Foxglove
(:mod:`swarmnav.log.live_view`) are both sinks of that context, so they see exactly the
same messages.  The channels, time stamps and names are in :mod:`swarmnav.log.format`.

``log_format`` picks the channels, the file's one seam between formats: ``swarmnav``
(:class:`swarmnav.log.swarmnav_channels.SwarmnavChannels`, Foxglove's protobuf schemas, the
default) or ``ros2`` (:class:`swarmnav.log.ros2_channels.Ros2Channels`, CDR messages of the
standard ROS 2 types, MCAP profile ``ros2``).  Everything else here (the file, the
metadata, the attachment, flushing, the live view, pacing) is the same for both.

Metadata records: ``scenario`` (name, TOML text), ``planner`` and ``navigator`` (name, JSON params),
``run`` (seed, world seed, time steps, sensor layout, obstacles), ``versions`` and, from
``finish``, ``outcome`` (the runner's summary).  Values are plain text where they are
strings (Foxglove shows ``goal_reached``, not ``"goal_reached"``) and JSON where they are
numbers, booleans, lists or objects (:func:`swarmnav.log.format.metadata_text`).  Attachment:
``scene.xml``, the compiled MJCF.  Everything needed to re-simulate is in the file.

The writer is the foxglove SDK with ``disable_seeking=True``, so the file is
written strictly front to back and a killed process never leaves a
half-rewritten chunk header behind.  It writes into a :class:`swarmnav.log.file.LogFile`,
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
from foxglove.mcap import MCAPCompression, MCAPWriteOptions

from swarmnav.log.live_view import DEFAULT_LIVE_HOST, DEFAULT_LIVE_PORT, LiveServer
from swarmnav.log.file import LogFile
from swarmnav.log.format import (
    LOG_FORMATS,
    MJCF_ATTACHMENT,
    TOPICS,
    default_log_path,
    dumps,
    metadata_text,
    time_ns,
    writer_versions,
)
from swarmnav.log.messages import run_metadata
from swarmnav.log.pacing import RealTimePacer
from swarmnav.log.ros2_channels import Ros2Channels
from swarmnav.log.swarmnav_channels import SwarmnavChannels
from swarmnav.sim.recording import RunContext, StepFrame

# TOPICS and default_log_path live in swarmnav.log.format; re-exported for existing callers.
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
            :class:`swarmnav.log.pacing.RealTimePacer`.
        on_live: called with the server's URL once it listens (the caller prints it;
            the recorder never prints).
        overwrite: replace an existing file instead of refusing.
        log_format: ``swarmnav`` or ``ros2`` (:data:`swarmnav.log.format.LOG_FORMATS`).

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
        log_format: str = "swarmnav",
    ):
        if not flush_interval_s > 0:
            raise ValueError("flush_interval_s must be positive")
        if log_format not in LOG_FORMATS:
            raise ValueError(f"log_format must be one of {', '.join(LOG_FORMATS)}, not {log_format!r}")
        self.log_format = log_format
        self._channels = Ros2Channels() if log_format == "ros2" else SwarmnavChannels()
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
        self._next_flush_ns = 0
        self._last_ns = 0

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
            profile=self._channels.profile,
            disable_seeking=True,
            compression_threads=0,  # the 2 cores belong to the simulation
        )
        self._writer = foxglove.open_mcap(self._file, context=self._fox, writer_options=options)
        self._channels.open(self._fox, context)
        self._guard(self._write_run_records, context)
        self.messages_written += self._channels.begin(context)
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
        self._after_write(t_ns, self._channels.path(t_ns, points))

    def step(self, frame: StepFrame) -> None:
        """Log one control step on every per-step channel."""
        t_ns = time_ns(frame.time_s)
        late = self._server.late_topics() if self._server is not None else ()
        self._after_write(t_ns, self._channels.step(frame, t_ns, late))
        if self._pacer is not None:
            self._pacer.step(frame)

    def occupancy(self, time_s: float, grid: Any) -> None:
        """Log the sensed map on ``/map`` (a ``foxglove.Grid``, or a ``nav_msgs/OccupancyGrid`` in a ros2 log)."""
        t_ns = time_ns(time_s)
        self._after_write(t_ns, self._channels.occupancy(t_ns, grid))

    def event(self, time_s: float, kind: str, details: dict[str, Any]) -> None:
        """Log a discrete event and flush, so it survives a crash right after."""
        t_ns = time_ns(time_s)
        self._after_write(t_ns, self._channels.event(t_ns, kind, details))
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
            self._channels.close()
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
        writer.write_metadata("versions", {**writer_versions(context.versions), **self._channels.versions()})
        writer.attach(
            log_time=0,
            create_time=0,
            name=MJCF_ATTACHMENT,
            media_type="application/xml",
            data=context.mjcf_xml.encode(),
        )

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
