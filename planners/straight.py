"""The straight-line baseline: start to goal, whatever lies between."""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.planners.problem import Path, Problem, check_endpoints


@dataclass
class StraightPlanner:
    """Returns the segment start -> goal.  It does not avoid obstacles:
    ``collision_free`` in the CLI tells whether that segment happens to be clear."""

    name: ClassVar[str] = "straight"
    supports: ClassVar[frozenset[str]] = frozenset({"discs", "boxes"})

    def plan(self, problem: Problem, rng: np.random.Generator) -> Path:
        t0 = time.perf_counter()
        check_endpoints(problem)
        return Path.from_waypoints(np.vstack([problem.start.xy, problem.goal.xy]),
                                   time.perf_counter() - t0)
