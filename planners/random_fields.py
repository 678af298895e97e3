"""Random disc fields (:mod:`swarmnav.models.disc_fields`) as planning problems, for the planner
tests and benchmarks that plan on them without a scenario file."""

from __future__ import annotations

import math

from swarmnav.models.disc_fields import (ARENA_M, CLEARANCE_M, GOAL_XY_M, ROBOT_RADIUS_M, START_HEADING_DEG,
                                         START_XY_M, draw_disc_field)
from swarmnav.models.world import Pose2D, Rect
from swarmnav.planners.problem import Problem


def random_disc_field(count: int, seed: int) -> Problem:
    """The problem of field ``(count, seed)``: its discs, start, goal, robot and clearance."""
    return Problem(Pose2D(*START_XY_M, math.radians(START_HEADING_DEG)), Pose2D(*GOAL_XY_M, 0.0), Rect(0.0, 0.0, ARENA_M, ARENA_M),
                   draw_disc_field(count, seed), robot_radius_m=ROBOT_RADIUS_M, clearance_m=CLEARANCE_M)
