"""What is free, for OMPL's planners (:mod:`planners.sampling_ompl`): swarmnav decides, exactly.

A state is valid when the point clears every inflated disc and box, a motion when the straight
segment does: both by the exact segment-disc and segment-box distances (:mod:`models.geometry`,
``Problem.segment_clearances_m``) at the problem's inflation, never by OMPL's discretised motion
checking, so every returned path passes ``Problem.is_collision_free``.  The checks are counted and
held to the budget (:class:`CollisionChecks`).  OMPL itself is imported on first use
(:func:`ompl_modules`), which also silences its console.
"""

from __future__ import annotations

import functools
import time
from typing import Any

import numpy as np

from swarmnav.models.geometry import segment_disc_distance
from swarmnav.planners.problem import Problem

#: A state or segment counts as free when its gap to the inflated obstacles is at least this
#: (the same touching tolerance as ``check_endpoints``; ``is_collision_free`` allows 1e-6).
TOUCH_M = 1e-9


@functools.cache
def ompl_modules() -> tuple[Any, Any, Any]:
    """Import OMPL's ``base``, ``geometric`` and ``util`` on first use and silence its console, once."""
    import ompl.base as ob
    import ompl.geometric as og
    import ompl.util as ou
    ou.setLogLevel(ou.LOG_NONE)
    return ob, og, ou


class CollisionChecks:
    """The exact checks OMPL calls, counted and held to the budget.

    Discs are measured one by one on plain floats (:func:`models.geometry.segment_disc_distance`,
    a NumPy call per segment would cost tens of microseconds), boxes (grid maps) by
    :meth:`Problem.segment_clearances_m`, culled to the boxes near the segment.
    """

    def __init__(self, problem: Problem, max_checks: float, deadline_s: float):
        self.problem = problem
        self.discs = [(float(c[0]), float(c[1]), float(r))
                      for c, r in zip(problem.disc_centres_m, problem.inflated_radii_m)]
        self.max_checks = max_checks
        self.deadline_s = deadline_s
        self.made = 0
        self.refused = 0

    @property
    def spent(self) -> bool:
        return self.made >= self.max_checks or time.perf_counter() >= self.deadline_s

    def free(self, ax: float, ay: float, bx: float, by: float) -> bool:
        """Whether the segment keeps at least the inflation from every obstacle (counted; refused, so
        reported blocked, once the budget is spent)."""
        if self.made >= self.max_checks:
            self.refused += 1
            return False
        self.made += 1
        for cx, cy, radius_m in self.discs:
            if segment_disc_distance(ax, ay, bx, by, cx, cy) - radius_m < -TOUCH_M:
                return False
        if self.problem.boxes:
            gap = self.problem.segment_clearances_m(np.array((ax, ay)), np.array((bx, by)), cull_beyond_m=0.0)
            return bool(gap[0] >= -TOUCH_M)
        return True

    def state_valid(self, state) -> bool:
        x, y = state[0], state[1]
        return self.free(x, y, x, y)

    def motion_valid(self, s1, s2) -> bool:
        return self.free(s1[0], s1[1], s2[0], s2[1])


@functools.cache
def motion_validator_type() -> type:
    """OMPL's ``MotionValidator`` answered by :class:`CollisionChecks` (built after the lazy import)."""
    ob, _, _ = ompl_modules()

    class ExactMotionValidator(ob.MotionValidator):
        def __init__(self, si, checks: CollisionChecks):
            super().__init__(si)
            self.checks = checks

        def checkMotion(self, s1, s2) -> bool:  # noqa: N802 - OMPL's name
            return self.checks.motion_valid(s1, s2)

    return ExactMotionValidator
