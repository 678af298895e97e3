"""What the report needs of a scenario beyond its footprint at t = 0, recorded in ``study.json`` when the
study runs (so a copied results folder reports alike):

* ``optimum_m``: the exact shortest collision-free length among the discs at t = 0, inflated by the robot
  radius and the study's clearance (the ``optimal`` planner's tangent graph); None with ``optimum_note``
  saying why where there is none (boxes or a map: the tangent graph takes discs only; no path exists);
* ``disc_tracks``: each moving obstacle's centre over the run, ``[[t_s, x_m, y_m], ...]`` every
  ``TRACK_STEP_S`` up to the simulated-time limit (at most ``MAX_TRACK_POINTS`` points per obstacle), with
  its radius, for the path figure's time-coloured tracks.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import Scenario
from swarmnav.planners.errors import PlanningError
from swarmnav.planners.path_guess import MAX_TANGENT_DISCS
from swarmnav.planners.problem import scenario_problem
from swarmnav.planners.registry import make_planner

TRACK_STEP_S = 0.25
MAX_TRACK_POINTS = 600


def optimum(scenario: Scenario, clearance_m: float | None) -> tuple[float | None, str]:
    """(the exact optimum length in metres or None, where it comes from or why there is none)."""
    if scenario.map_grid is not None or scenario.boxes:
        return None, "no exact optimum: the tangent graph takes discs only (this scenario has boxes or a map)"
    static = sum(1 for o in scenario.obstacles if not o.moving)
    if static > MAX_TANGENT_DISCS:  # a BARN world (200-300 discs): 0.6 s of CPU each, 5 min for a 500-run suite
        return None, (f"no exact optimum computed: {static} static discs, more than {MAX_TANGENT_DISCS} "
                      "(the tangent graph's cost; SPL's L* is Theta*'s there)")
    problem = scenario_problem(scenario, clearance_m=clearance_m)
    try:
        path = make_planner("optimal", {}).plan(problem, np.random.default_rng(0))
    except (PlanningError, ConfigError) as exc:
        return None, f"no exact optimum: {exc}"
    return float(path.stats.extra["optimum_length_m"]), "the exact optimum (tangent graph among the discs at t = 0)"


def disc_tracks(scenario: Scenario, time_limit_s: float | None) -> list[dict[str, Any]]:
    """Each moving obstacle's centre over the run (see the module docstring)."""
    end_s = scenario.time_limit_s if time_limit_s is None else time_limit_s
    step_s = max(TRACK_STEP_S, end_s / (MAX_TRACK_POINTS - 1))
    times = np.arange(0.0, end_s + 1e-9, step_s)
    out = []
    for obstacle in scenario.obstacles:
        if obstacle.moving:
            xy = obstacle.trajectory().positions_at(times)
            out.append({"radius_m": obstacle.radius_m,
                        "t_x_y": np.round(np.column_stack([times, xy]), 4).tolist()})
    return out


def scenario_facts(scenario: Scenario, clearance_m: float | None, time_limit_s: float | None) -> dict[str, Any]:
    length_m, note = optimum(scenario, clearance_m)
    return {"optimum_m": length_m, "optimum_note": note, "disc_tracks": disc_tracks(scenario, time_limit_s)}
