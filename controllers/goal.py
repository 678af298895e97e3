"""The goal checker (nav2's ``GoalChecker``): the one place that knows the goal tolerance."""

from __future__ import annotations

import math
from dataclasses import dataclass

from swarmnav.models.world import Pose2D


@dataclass(frozen=True)
class GoalChecker:
    """Goal reached when the base is within ``tolerance_m`` of the goal position."""

    x_m: float
    y_m: float
    tolerance_m: float

    def reached(self, pose: Pose2D) -> bool:
        return math.hypot(pose.x_m - self.x_m, pose.y_m - self.y_m) <= self.tolerance_m
