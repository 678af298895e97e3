"""``random_detour``: the straight line, or else the shortest of random one-via-point detours that clears.

A deliberately small planner that shows the seam: ``plan(problem, rng) -> Path``, randomness only from
``rng``, the exact check of the problem, and swarmnav's typed errors.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.problem import Path, Problem, check_endpoints


@dataclass
class RandomDetourPlanner:
    """Straight line if clear, else the shortest clear start-via-goal detour of ``samples`` random vias."""

    name: ClassVar[str] = "random_detour"
    supports: ClassVar[frozenset[str]] = frozenset({"discs", "boxes"})
    samples: int = 2000

    def __post_init__(self) -> None:
        if not 1 <= self.samples <= 1_000_000:
            raise ValueError(f"samples must be in [1, 1000000], got {self.samples}")

    def plan(self, problem: Problem, rng: np.random.Generator) -> Path:
        started = time.perf_counter()
        check_endpoints(problem)
        start, goal = problem.start.xy, problem.goal.xy
        if problem.is_collision_free(np.vstack([start, goal])):
            return Path.from_waypoints(np.vstack([start, goal]), time.perf_counter() - started, evaluations=1)
        b = problem.bounds
        vias = np.column_stack([rng.uniform(b.x_min_m, b.x_max_m, self.samples),
                                rng.uniform(b.y_min_m, b.y_max_m, self.samples)])
        lengths = np.linalg.norm(vias - start, axis=1) + np.linalg.norm(goal - vias, axis=1)
        for k in np.argsort(lengths, kind="stable"):
            path = np.vstack([start, vias[k], goal])
            if problem.is_collision_free(path):
                return Path.from_waypoints(path, time.perf_counter() - started, evaluations=int(self.samples))
        raise NoPathFound(f"none of {self.samples} one-via-point detours is clear")
