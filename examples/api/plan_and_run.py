"""An example script of swarmnav's Python API, type-checked by ``mypy --strict`` in the tests
(tests/test_api_types.py): plan, run, a given path, a study, and a planner of one's own.

    python examples/api/plan_and_run.py
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path as FilePath
from typing import ClassVar

import numpy as np

import swarmnav
from swarmnav import ConfigError, NoPathFound, Path, PlanningError, Problem, RunOutcome, Scenario


@swarmnav.register_planner
@dataclass
class StraightThenGiveUp:
    """The straight line when it is clear, else no path: the planner seam in a few lines."""

    name: ClassVar[str] = "straight_then_give_up"
    supports: ClassVar[frozenset[str]] = frozenset({"discs", "boxes"})

    def plan(self, problem: Problem, rng: np.random.Generator) -> Path:
        line = np.vstack([problem.start.xy, problem.goal.xy])
        if not problem.is_collision_free(line):
            raise NoPathFound("the straight line is blocked")
        return Path.from_waypoints(line, 0.0, evaluations=1)


def main(out: str | os.PathLike[str] = "studies/api-example") -> None:
    scenario: Scenario = swarmnav.load_scenario("gwo-scenario-1")
    planned = swarmnav.plan(scenario, planner="astar", seed=0)
    print(f"astar: {planned.length_m:.3f} m, {len(planned.waypoints)} waypoints")
    outcome: RunOutcome = swarmnav.run(FilePath("gwo-scenario-3"), planner="astar", seed=1)
    print(outcome.outcome, outcome.success, outcome.to_dict()["spl"])
    given = swarmnav.run("gwo-scenario-1", waypoints=[[0.0, 0.0], [0.0, -3.0], [10.0, 10.0]])
    print(f"a path through (0, -3): {given.outcome}")
    try:
        swarmnav.plan("gwo-scenario-1", planner="straight_then_give_up")
    except PlanningError as exc:
        print(f"no path: {exc}")
    try:
        swarmnav.plan("gwo-scenario-1", planner="no-such-planner")
    except ConfigError as exc:
        print(f"bad input: {exc.field}: {exc.problem}")
    summary = swarmnav.run_study({"name": "api-example", "scenarios": ["gwo-scenario-3"], "seeds": 2,
                                  "planners": [{"name": "astar"}, {"name": "theta_star"}]}, out, workers=2)
    print(summary["outcomes"])


if __name__ == "__main__":
    main()
