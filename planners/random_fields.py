"""Random disc fields: the planning problems the continuous planners' robust mode is measured on
beyond the bundled scenes (``swarmnav bench planners`` and the planner tests).

A field is a 10 x 10 m arena, start (0.5, 0.5), goal (9.5, 9.5), a robot of radius 0.15 m
with 0.05 m clearance, and ``count`` discs of radius 0.15-0.5 m with centres uniform in
[1, 9] x [1, 9], drawn one by one and redrawn while one would overlap another (a gap of at
least 0.1 m between footprints); a disc is never within its inflated radius of the start
or the goal.  The same ``(count, seed)`` always gives the same field.
"""

from __future__ import annotations

import numpy as np

from swarmnav.models.world import Disc, Pose2D, Rect
from swarmnav.planners.problem import Problem

ARENA_M = 10.0
ROBOT_RADIUS_M = 0.15
CLEARANCE_M = 0.05


def random_disc_field(count: int, seed: int) -> Problem:
    """The field of ``count`` discs drawn with ``numpy.random.default_rng(seed)``."""
    rng = np.random.default_rng(seed)
    start, goal = np.array([0.5, 0.5]), np.array([ARENA_M - 0.5, ARENA_M - 0.5])
    centres: list[np.ndarray] = []
    radii: list[float] = []
    for _ in range(100 * count):
        if len(centres) == count:
            break
        centre = rng.uniform(1.0, ARENA_M - 1.0, 2)
        radius = float(rng.uniform(0.15, 0.5))
        reach = radius + ROBOT_RADIUS_M + CLEARANCE_M
        if min(np.hypot(*(centre - start)), np.hypot(*(centre - goal))) <= reach:
            continue
        if any(np.hypot(*(centre - c)) < radius + r + 0.1 for c, r in zip(centres, radii)):
            continue
        centres.append(centre)
        radii.append(radius)
    obstacles = tuple(Disc(float(c[0]), float(c[1]), r) for c, r in zip(centres, radii))
    return Problem(Pose2D(*start, 0.0), Pose2D(*goal, 0.0), Rect(0.0, 0.0, ARENA_M, ARENA_M), obstacles,
                   robot_radius_m=ROBOT_RADIUS_M, clearance_m=CLEARANCE_M)
