"""Hold a run to a multiple of real time, so a live viewer can follow it.

:class:`RealTimePacer` is a :class:`sim.recording.Recorder`: at every step it
sleeps until the wall clock has caught up with ``time_s / speed``.  Only the
pacing reads the wall clock; nothing of it reaches a log.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from swarmnav.sim.recording import RunContext, StepFrame


class RealTimePacer:
    """Sleeps in ``step`` so that simulated time advances at ``speed`` x real time.

    Args:
        speed: simulated seconds per wall-clock second (must be positive).
    """

    def __init__(self, speed: float = 1.0):
        if not speed > 0:
            raise ValueError(f"pacing speed must be positive, got {speed}")
        self.speed = float(speed)
        self._wall_start_s = time.perf_counter()

    def start(self, context: RunContext) -> None:
        self._wall_start_s = time.perf_counter()

    def path(self, time_s: float, waypoints_m: np.ndarray) -> None:
        pass

    def step(self, frame: StepFrame) -> None:
        ahead_s = frame.time_s / self.speed - (time.perf_counter() - self._wall_start_s)
        if ahead_s > 0:
            time.sleep(ahead_s)

    def event(self, time_s: float, kind: str, details: dict[str, Any]) -> None:
        pass

    def finish(self, summary: dict[str, Any]) -> None:
        pass
