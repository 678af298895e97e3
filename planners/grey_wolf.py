"""Grey Wolf Optimisation over spline via-points (Abdulla & Hadi 2025, Eqs. (15)-(25)).

After Mirjalili, Mirjalili and Lewis (2014), as Abdulla & Hadi (2025) gives it: the three
best wolves found so far, alpha, beta and delta, lead; every wolf moves to the
mean of three positions, one drawn towards each leader:

* ``A = 2 a r1 - a`` (Eq. 17) and ``C = 2 r2`` (Eq. 18), drawn per wolf, per
  leader and per coordinate, with ``a`` falling linearly from 2 to 0 over the
  iterations;
* ``D_l = |C_l * x_l - x|`` (Eqs. 19-21) and ``x_l' = x_l - A_l * D_l`` (Eqs. 22-24)
  for the leaders ``l`` = alpha, beta, delta;
* ``x(t+1) = (x_1' + x_2' + x_3') / 3`` (Eq. 25; the extraction reads ``/ 2``,
  which would not average the three moves, so we take Mirjalili's ``/ 3``).

``a`` falls over the run: ``a = 2 - 2 f`` with ``f`` the share of the run done
(:attr:`planners.swarm.SwarmState.run_fraction`: iterations / ``iterations``, or, under an
evaluation or time budget, the share of the budget spent), so that a budgeted run ends
with ``a`` near 0 as the paper's 100 iterations do.

Deviations from Abdulla & Hadi (2025), each our reading:

* Sect. 3, Eqs. (6)-(8): the paper's objective is ``w1 F1 + w2 F2`` with no obstacle term
  and no values of ``w1``, ``w2``; we add Kamil et al.'s (2020) penalty Eqs. (3)-(5) (the
  same group's ABC paper; without an obstacle term nothing keeps a path out of a disc) with
  paper mode's weight 1000 and 2 cm margin (:mod:`planners.run_settings`: with weight 1 the
  best wolf cuts a disc on gwo-scenario-1 and -3 for every seed tried) and default to
  ``w1 = 1``, ``w2 = 0`` (the length its Sect. 6 compares);
* Sect. 6: "a population size of 0.5" is read as 50 wolves;
* Eq. (25) divides by 3, not by the extraction's 2 (see above).

Choices where the paper is silent: a new position is clipped to the search box;
the pack moves without greedy selection (Mirjalili's original; mealpy's
``OriginalGWO`` keeps a wolf's old position when the new one is worse); the
leaders are the three best distinct evaluations so far (they persist across
iterations, as in Mirjalili's reference code).  Each iteration costs
``population`` evaluations.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.planners.continuous import ContinuousPlanner
from swarmnav.planners.exact_check import ContinuousState
from swarmnav.planners.problem import Problem


@dataclass
class GreyWolfPlanner(ContinuousPlanner):
    """``gwo``: Grey Wolf Optimisation of the via-points (see the module docstring).

    Attributes:
        population: wolves in the pack (50; Abdulla & Hadi 2025's "population size of 0.5"
            is garbled in the extraction).
        iterations: Abdulla & Hadi (2025) uses 100.
    """

    name: ClassVar[str] = "gwo"

    population: int = 50
    iterations: int = 100

    def init_swarm(self, state: ContinuousState, rng: np.random.Generator) -> None:
        wolves = self.initial_solutions(state, self.population, rng)
        costs = self.evaluate(state, wolves)
        state.population = wolves
        state.costs = costs
        self._update_leaders(state, wolves, costs)

    @staticmethod
    def _update_leaders(state: ContinuousState, wolves: np.ndarray, costs: np.ndarray) -> None:
        """Keep the three best positions seen so far as alpha, beta, delta."""
        if "leaders" in state.data:
            wolves = np.vstack([state.data["leaders"], wolves])
            costs = np.concatenate([state.data["leader_costs"], costs])
        order = np.argsort(costs, kind="stable")[:3]
        state.data["leaders"] = wolves[order].copy()
        state.data["leader_costs"] = costs[order].copy()

    def step(self, state: ContinuousState, problem: Problem, rng: np.random.Generator,
             iteration: int) -> None:
        wolves = state.population
        leaders = state.data["leaders"]                              # (3, D)
        a = 2.0 - 2.0 * state.run_fraction
        shape = (3,) + wolves.shape                                  # (3, P, D)
        big_a = 2.0 * a * rng.random(shape) - a                      # Eq. (17)
        big_c = 2.0 * rng.random(shape)                              # Eq. (18)
        distance = np.abs(big_c * leaders[:, None, :] - wolves[None, :, :])   # Eqs. (19)-(21)
        moves = leaders[:, None, :] - big_a * distance               # Eqs. (22)-(24)
        wolves = np.clip(moves.mean(axis=0), state.lower, state.upper)  # Eq. (25)
        costs = self.evaluate(state, wolves)
        state.population = wolves
        state.costs = costs
        self._update_leaders(state, wolves, costs)
