"""How a re-simulation compares with a log: the verdict of ``swarmnav replay --verify``.

:class:`TrajectoryCapture` records what the re-simulation did; :func:`compare_with_log`
compares it step by step with the log: every pose (position and quaternion), every
range scan (in the log's own convention, :func:`swarmnav.log.format.scan_from_ranges`),
the time stamps and the planned path.  All must be bitwise equal to pass.

A log that stops before its run did (killed, interrupted, recovered from a cut
file) is compared over the steps it holds: when they are all equal the verdict is
"prefix bitwise equal, the log ends at t = ...", a pass.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarmnav.log.columns import Rows
from swarmnav.log.format import ROS2_PROFILE, scan_from_ranges
from swarmnav.log.reader import RunLog, outcome_text
from swarmnav.sim.recording import RunContext, StepFrame

# Outcomes of a run that reached its natural end; any other log stops early.
FINISHED_OUTCOMES = ("goal_reached", "timeout", "collision", "stopped_on_collision", "left_arena")


@dataclass
class VerifyReport:
    """How a re-simulation compares with a log."""

    logged_steps: int
    simulated_steps: int
    compared_steps: int
    max_position_error_m: float
    max_quaternion_error: float
    worst_time_s: float | None
    first_difference_s: float | None
    poses_bitwise_equal: bool
    path_bitwise_equal: bool
    path_max_error_m: float
    ranges_bitwise_equal: bool
    max_range_error_m: float
    outcome_logged: str
    outcome_simulated: str
    log_is_prefix: bool
    log_end_s: float

    @property
    def bitwise_equal(self) -> bool:
        """Poses, time stamps, range scans and the path all equal over the logged steps."""
        return self.poses_bitwise_equal and self.ranges_bitwise_equal and self.path_bitwise_equal

    @property
    def passed(self) -> bool:
        same_length = self.logged_steps == self.simulated_steps
        return self.bitwise_equal and (same_length or (self.log_is_prefix and self.logged_steps
                                                       < self.simulated_steps))

    def verdict(self) -> str:
        if not self.passed:
            return "DIFFERENT"
        if self.logged_steps < self.simulated_steps:
            return f"prefix bitwise equal, the log ends at t = {self.log_end_s:.3f} s"
        return "bitwise equal"

    def lines(self) -> list[str]:
        lines = [
            f"verify: {self.verdict()}: {self.compared_steps} steps compared "
            f"(logged {self.logged_steps}, re-simulated {self.simulated_steps})",
            f"  max position deviation:   {self.max_position_error_m:.3e} m"
            + (f" at t={self.worst_time_s:.3f} s" if self.worst_time_s is not None else ""),
            f"  max quaternion deviation: {self.max_quaternion_error:.3e}",
            f"  range scans: {'bitwise equal' if self.ranges_bitwise_equal else 'differ'} "
            f"(max {self.max_range_error_m:.3e} m)",
            f"  planned path: {'bitwise equal' if self.path_bitwise_equal else 'differs'} "
            f"(max {self.path_max_error_m:.3e} m)",
            f"  outcome: logged {self.outcome_logged}, re-simulated {self.outcome_simulated}",
        ]
        if self.first_difference_s is not None:
            lines.append(f"  first difference at t={self.first_difference_s:.3f} s")
        return lines

    def as_dict(self) -> dict:
        out = dict(self.__dict__)
        out.update(bitwise_equal=self.bitwise_equal, passed=self.passed, verdict=self.verdict())
        return out


class TrajectoryCapture:
    """A Recorder that keeps the time, base pose and ranges of every step, as rows of numbers
    (:class:`swarmnav.log.columns.Rows`: a long run costs its numbers, not an object per step)."""

    def __init__(self) -> None:
        self._poses = Rows(8)  # t, x, y, z, qw, qx, qy, qz
        self._ranges = Rows()

    def start(self, context: RunContext) -> None:
        pass

    def path(self, time_s: float, waypoints_m: np.ndarray) -> None:
        pass

    def step(self, frame: StepFrame) -> None:
        row = np.empty(8)
        row[0] = frame.time_s
        row[1:4] = frame.position_m
        row[4:8] = frame.quaternion_wxyz
        self._poses.append(row)
        self._ranges.append(np.asarray(frame.range_m, dtype=float))

    def event(self, time_s: float, kind: str, details: dict) -> None:
        pass

    def finish(self, summary: dict) -> None:
        pass

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(T,) times, (T, 3) positions, (T, 4) quaternions."""
        poses = self._poses.array()
        return poses[:, 0].copy(), poses[:, 1:4].copy(), poses[:, 4:8].copy()

    def ranges(self) -> np.ndarray:
        """(T, K) ranges of every step."""
        return self._ranges.array()


def log_stops_early(log: RunLog) -> bool:
    """True when the log ends before its run did (no finishing outcome or event)."""
    if "recovery" in log.metadata:
        return True
    if log.outcome is not None:
        return str(log.outcome.get("outcome", "")) not in FINISHED_OUTCOMES
    return not any(kind in FINISHED_OUTCOMES for _, kind, _ in log.events)


def _range_deviation_m(simulated: np.ndarray, logged: np.ndarray) -> tuple[bool, float]:
    """(bitwise equal, largest deviation) of two (T, K) scans; NaN = nothing in range."""
    if simulated.shape != logged.shape:
        return False, math.inf
    if simulated.size == 0:
        return True, 0.0
    both_missed = np.isnan(simulated) & np.isnan(logged)
    deviation = np.where(both_missed, 0.0, np.abs(simulated - logged))
    return bool(np.array_equal(simulated, logged, equal_nan=True)), float(np.nanmax(
        np.where(np.isnan(deviation), np.inf, deviation)))


def compare_with_log(log: RunLog, capture: TrajectoryCapture, planned_waypoints_m: np.ndarray,
                     outcome_simulated: str) -> VerifyReport:
    """Compare a re-simulation (captured step by step) with the log, over the logged steps."""
    sim_t, sim_p, sim_q = capture.arrays()
    n = min(len(sim_t), len(log.time_s))
    dp = np.linalg.norm(sim_p[:n] - log.position_m[:n], axis=1)
    # q and -q are the same rotation.
    dq = np.minimum(np.linalg.norm(sim_q[:n] - log.quaternion_wxyz[:n], axis=1),
                    np.linalg.norm(sim_q[:n] + log.quaternion_wxyz[:n], axis=1))
    same = (np.all(sim_p[:n] == log.position_m[:n], axis=1)
            & np.all(sim_q[:n] == log.quaternion_wxyz[:n], axis=1)
            & (np.round(sim_t[:n] * 1e9) == np.round(log.time_s[:n] * 1e9)))
    differing = np.flatnonzero(~same)

    logged_path = log.paths[0][1] if log.paths else np.zeros((0, 2))
    replanned = np.asarray(planned_waypoints_m, dtype=float).reshape(-1, 2)
    path_equal = logged_path.shape == replanned.shape and np.array_equal(logged_path, replanned)
    path_error = (float(np.max(np.linalg.norm(logged_path - replanned, axis=1)))
                  if logged_path.shape == replanned.shape and len(replanned) else math.inf)

    offset_m = float(log.run_value("sensor_offset_m", 0.0))
    sim_ranges = capture.ranges().reshape(len(sim_t), -1)
    m = min(len(sim_ranges), len(log.range_m))
    simulated_scan = scan_from_ranges(sim_ranges[:m], offset_m)
    if log.raw.profile == ROS2_PROFILE:  # a LaserScan holds float32 ranges: compare what it can hold
        simulated_scan = simulated_scan.astype(np.float32).astype(float)
    ranges_equal, range_error = _range_deviation_m(simulated_scan, log.range_m[:m])

    worst = int(np.argmax(dp)) if n and dp.max() > 0 else None
    return VerifyReport(
        logged_steps=len(log.time_s), simulated_steps=len(sim_t), compared_steps=n,
        max_position_error_m=float(dp.max()) if n else 0.0,
        max_quaternion_error=float(dq.max()) if n else 0.0,
        worst_time_s=float(log.time_s[worst]) if worst is not None else None,
        first_difference_s=float(log.time_s[differing[0]]) if len(differing) else None,
        poses_bitwise_equal=len(differing) == 0 and n == len(log.time_s),
        path_bitwise_equal=bool(path_equal), path_max_error_m=path_error,
        ranges_bitwise_equal=ranges_equal and m == len(log.range_m), max_range_error_m=range_error,
        outcome_logged=outcome_text(log), outcome_simulated=outcome_simulated,
        log_is_prefix=log_stops_early(log), log_end_s=float(log.time_s[-1]) if len(log.time_s) else 0.0,
    )
