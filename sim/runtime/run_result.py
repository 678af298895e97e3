"""What one closed-loop run gives: the outcome, the trajectory and the navigation metrics."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np


#: Every way a run ends: the goal reached; the time limit; a collision that stopped the run
#: (``stop_on_collision``); the robot's centre beyond an arena edge by more than its radius, or a given path
#: (``run --waypoints``) with a waypoint outside the arena (``left_arena``).
OUTCOMES = ("goal_reached", "timeout", "collision", "left_arena")


@dataclass
class RunResult:
    """What happened in one closed-loop run (arrays have one row per control step)."""

    reached: bool
    outcome: str  # "goal_reached" | "timeout" | "collision" | "left_arena" (see OUTCOMES)
    collisions: int
    first_collision_s: float | None
    sim_time_s: float
    wall_time_s: float
    path_length_m: float
    min_clearance_m: float
    steps: int
    times_s: np.ndarray = field(repr=False)
    poses: np.ndarray = field(repr=False)  # (T, 3) x, y, heading
    wheel_command_rad_s: np.ndarray = field(repr=False)  # (T, 2)
    collision_points_m: np.ndarray = field(repr=False)  # (C, 2) base position at each collision start
    # Navigation metrics (Le et al. 2022's dynamic runs; see summary()).
    time_in_danger_s: float = 0.0
    stopped_s: float = 0.0
    replans: int = 0
    replan_wall_s: float = 0.0
    safety_triggers: int = 0
    reference_length_m: float | None = None  # L*: the shortest path among the static obstacles
    navigator_wall_s: float = 0.0  # wall time spent in navigator.step (not in summary(): benchmarks read it)
    # Where the first collision began (time_s, x_m, y_m of the base, the obstacle geom's name, the robot geom's).
    first_contact: dict[str, Any] | None = None
    # Among agents (orca / social_force obstacles) only: discomfort_frequency, min_separation_m,
    # path_irregularity_rad_m (sim.crowd_stepping.crowd_metrics); None without agents (and not in the summary).
    crowd: dict[str, float] | None = None
    # With knowledge.pose = "odometry": {"pose_error_m": final, "max_pose_error_m": largest} (truth vs odometry).
    odometry: dict[str, float] | None = None

    @property
    def success(self) -> bool:
        """Reached the goal before the time limit with no collision, never having left the arena (nor driven
        a given path that leaves it: outcome ``left_arena``)."""
        return self.reached and self.collisions == 0 and self.outcome == "goal_reached"

    @property
    def spl(self) -> float | None:
        """Success weighted by path length (Anderson et al. 2018, Eq. 1 for one episode): S L* / max(L, L*).

        A start within the goal's tolerance, with L = L* = 0, has 1 (the paper leaves 0/0 undefined).
        """
        if self.reference_length_m is None:
            return None
        if not self.success:
            return 0.0
        longest_m = max(self.path_length_m, self.reference_length_m)
        return self.reference_length_m / longest_m if longest_m > 0.0 else 1.0

    def summary(self) -> dict[str, Any]:
        return {"reached": self.reached, "outcome": self.outcome, "collisions": self.collisions,
                "first_collision_s": self.first_collision_s, "first_contact": self.first_contact,
                "sim_time_s": round(self.sim_time_s, 6),
                "wall_time_s": round(self.wall_time_s, 4), "path_length_m": self.path_length_m,
                # None when the scene has no obstacle (JSON has no infinity).
                "min_clearance_m": self.min_clearance_m if math.isfinite(self.min_clearance_m) else None,
                "success": self.success, "time_to_goal_s": round(self.sim_time_s, 6) if self.reached else None,
                "spl": self.spl, "time_in_danger_s": round(self.time_in_danger_s, 6), "replans": self.replans,
                "replan_wall_s": round(self.replan_wall_s, 4), "stopped_s": round(self.stopped_s, 6),
                "safety_triggers": self.safety_triggers, **(self.crowd or {}), **(self.odometry or {})}

    def log_summary(self) -> dict[str, Any]:
        """:meth:`summary` without wall-clock figures other than ``wall_*`` (which the log writer drops)."""
        return {k: v for k, v in self.summary().items() if k != "replan_wall_s"}
