"""Small recorders: several at once, and an in-memory trajectory for checks.

``swarmnav run --out log.mcap --video run.mp4 --live`` needs the MCAP log, the
video and the live view fed by the one runner loop: :class:`RecorderGroup` fans
every call out.  :class:`TrajectoryCapture` keeps the poses of a run in memory,
which is what ``replay --verify`` compares against a log.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sim.recording import Recorder, RunContext, StepFrame


class RecorderGroup:
    """Forwards every Recorder call to each member, in order.

    ``finish`` reaches every member even when an earlier one raises (the first
    error is re-raised afterwards), so one broken sink cannot leave another's
    file unclosed.
    """

    def __init__(self, *recorders: Recorder):
        self.recorders = tuple(r for r in recorders if r is not None)

    def start(self, context: RunContext) -> None:
        for r in self.recorders:
            r.start(context)

    def path(self, time_s: float, waypoints_m: np.ndarray) -> None:
        for r in self.recorders:
            r.path(time_s, waypoints_m)

    def step(self, frame: StepFrame) -> None:
        for r in self.recorders:
            r.step(frame)

    def event(self, time_s: float, kind: str, details: dict[str, Any]) -> None:
        for r in self.recorders:
            r.event(time_s, kind, details)

    def finish(self, summary: dict[str, Any]) -> None:
        first_error: BaseException | None = None
        for r in self.recorders:
            try:
                r.finish(summary)
            except BaseException as error:  # noqa: BLE001 - re-raised below
                first_error = first_error or error
        if first_error is not None:
            raise first_error


class TrajectoryCapture:
    """Keeps time, position and orientation of every step, and the planned paths."""

    def __init__(self) -> None:
        self.times_s: list[float] = []
        self.positions_m: list[np.ndarray] = []
        self.quaternions_wxyz: list[np.ndarray] = []
        self.paths: list[tuple[float, np.ndarray]] = []
        self.events: list[tuple[float, str, dict[str, Any]]] = []
        self.summary: dict[str, Any] | None = None

    def start(self, context: RunContext) -> None:
        pass

    def path(self, time_s: float, waypoints_m: np.ndarray) -> None:
        self.paths.append((time_s, np.array(waypoints_m, dtype=float)))

    def step(self, frame: StepFrame) -> None:
        self.times_s.append(frame.time_s)
        self.positions_m.append(np.array(frame.position_m, dtype=float))
        self.quaternions_wxyz.append(np.array(frame.quaternion_wxyz, dtype=float))

    def event(self, time_s: float, kind: str, details: dict[str, Any]) -> None:
        self.events.append((time_s, kind, dict(details)))

    def finish(self, summary: dict[str, Any]) -> None:
        self.summary = dict(summary)

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(T,) times, (T, 3) positions, (T, 4) quaternions."""
        return (np.array(self.times_s, dtype=float),
                np.array(self.positions_m, dtype=float).reshape(-1, 3),
                np.array(self.quaternions_wxyz, dtype=float).reshape(-1, 4))
