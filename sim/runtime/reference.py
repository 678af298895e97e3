"""L*, the reference length of the SPL: the shortest path among a scenario's static obstacles.

What the robot knows in advance is the map: the scenario's problem with its
moving obstacles left out (:func:`static_problem`).  L* is the exact shortest
length on it (``optimal``'s ``optimum_length_m``, not its polygon's slightly
longer length), or Theta*'s path length on a map of boxes or among more than
:data:`planners.path_guess.MAX_TANGENT_DISCS` static discs (BARN's worlds: the tangent graph of 200-300
cylinders costs seconds a run).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from swarmnav.models.scenario import Scenario
from swarmnav.planners.errors import PlanningError
from swarmnav.planners.theta_star import ThetaStarPlanner
from swarmnav.planners.optimal import OptimalPlanner
from swarmnav.planners.path_guess import MAX_TANGENT_DISCS
from swarmnav.planners.problem import Problem, scenario_problem


def static_problem(scenario: Scenario) -> Problem:
    """The scenario's problem with its moving obstacles left out: what the robot knows in advance (the map)."""
    return scenario_problem(replace(scenario, obstacles=tuple(ob for ob in scenario.obstacles if not ob.moving)))


_REFERENCE_LENGTHS: dict[tuple, float | None] = {}


def _static_key(scenario: Scenario) -> tuple:
    """What L* depends on: the file and every field of the static geometry a caller may have replaced
    (the world seed moves only the moving obstacles, so it is not part of it)."""
    return (scenario.source_text or scenario.name, scenario.start, scenario.goal, scenario.robot_radius_m,
            scenario.clearance_m, scenario.walls, scenario.arena_width_m, scenario.arena_height_m,
            tuple(ob for ob in scenario.obstacles if not ob.moving), scenario.boxes)


def reference_length_m(scenario: Scenario) -> float | None:
    """L* for SPL (see the module docstring); None when there is no path among the static obstacles.

    Cached by the static geometry (:func:`_static_key`).
    """
    key = _static_key(scenario)
    if key not in _REFERENCE_LENGTHS:
        problem = static_problem(scenario)
        # the exact tangent graph costs seconds beyond MAX_TANGENT_DISCS static discs (a BARN world has 200-300)
        planner = (ThetaStarPlanner() if problem.boxes or problem.grid_override is not None
                   or len(problem.obstacles) > MAX_TANGENT_DISCS else OptimalPlanner())
        try:
            stats = planner.plan(problem, np.random.default_rng(0)).stats
            _REFERENCE_LENGTHS[key] = float(stats.extra.get("optimum_length_m", stats.length_m))
        except PlanningError:
            _REFERENCE_LENGTHS[key] = None
    return _REFERENCE_LENGTHS[key]
