"""Recognising the papers' own instances, for the continuous planners' ``mode = "auto"``.

The continuous planners run each paper's algorithm exactly as written on the paper's own
scenarios and the robust options everywhere else (:mod:`planners.continuous`).  A planner
sees only a :class:`planners.problem.Problem`, so "the paper's own scenario" is recognised
by its geometry: the start, the goal and the discs (centres and radii, not inflated, so
any clearance matches) of one of the bundled scenarios in :data:`PAPER_SCENARIOS`.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from swarmnav.planners.problem import Problem

#: The bundled scenarios that reproduce the papers' instances: Abdulla & Hadi (2025)
#: scenarios 1-3 and Kamil et al. (2020) paths 1-3.
PAPER_SCENARIOS = ("gwo-scenario-1", "gwo-scenario-2", "gwo-scenario-3",
                   "adl-abc-path-1", "adl-abc-path-2", "adl-abc-path-3")


def fingerprint(problem: Problem) -> tuple[float, ...]:
    """Start, goal and the sorted discs (x, y, radius) of a problem, rounded to 0.1 mm."""
    discs = np.column_stack([problem.disc_centres_m, problem.disc_radii_m]).reshape(-1, 3)
    discs = discs[np.lexsort(discs.T[::-1])] if discs.size else discs
    values = np.concatenate([problem.start.xy, problem.goal.xy, discs.ravel()])
    return tuple(np.round(values, 4).tolist())


@lru_cache(maxsize=1)
def paper_fingerprints() -> dict[tuple[float, ...], str]:
    """Fingerprint -> name of each of :data:`PAPER_SCENARIOS` (read once per process)."""
    from swarmnav.models.scenario import load_scenario
    from swarmnav.planners.problem import scenario_problem

    return {fingerprint(scenario_problem(load_scenario(name))): name for name in PAPER_SCENARIOS}


def paper_instance(problem: Problem) -> str | None:
    """The name of the paper scenario ``problem`` is, or None."""
    return paper_fingerprints().get(fingerprint(problem))
