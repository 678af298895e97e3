"""Artificial Bee Colony over spline via-points: ``abc`` and ``adl_abc`` (Kamil et al. 2020).

The paper's instances (Kamil et al. 2020, Tables 1-4) report paths for a 0.5 m robot, but as printed no path
exists for it (``optimal`` exits 3: case A's discs close the arena, case B's discs 7, 3, 2 and 12 chain from its
bottom edge to its top, and case B path 3's start lies on disc 12). swarmnav bundles the printed instances and
feasible variants that state what they change (``models/studies/adl-abc-feasible/``,
``models/studies/adl-abc-case-b-feasible/``); case B path 3 exists only as a feasible variant.

Karaboga's ABC as Kamil et al. (2020) Algorithm 1 gives it (also Abdulla & Hadi (2025) Sect. 4.1):

* ``population`` food sources ``SN``, placed by Eq. (6) ``x = x_min + rand (x_max - x_min)``;
* employed bees: every source ``i`` tries ``v_ij = x_ij + phi (x_ij - x_kj)``
  (Eq. (7); the extraction's ``v_ij + ...`` is read as ``x_ij + ...``) for one
  random coordinate ``j``, a random partner ``k != i`` and ``phi`` in [-1, 1];
  greedy selection keeps the better, and a failure adds 1 to the source's
  counter (a success resets it to 0);
* onlooker bees: ``SN`` onlookers choose sources with probability
  ``p_i = fit_i / sum fit`` (Eq. (9)) with ``fit = 1 / (1 + f)`` (Eq. (8), ``f``
  the cost :class:`planners.path_cost.PathObjective`, which is never negative)
  and try Eq. (7) around them, again greedily;
* scout bees (Sect. 4 IV, Step 8): "The employed bees which cannot improve self-solution
  through the limit consider worst.  The worst food source is abandoned": of the sources
  whose counter has reached the limit, the worst one (highest cost; ties: the lowest index)
  is abandoned and replaced by a random one, Eq. (6) - one scout a cycle at most, as in
  Karaboga's ABC (whose code takes the source with the largest counter; "worst" read as the
  highest cost is our reading of the paper's word).  ``scouts = "all"`` (a named option, not the paper's) abandons every
  exhausted source, as mealpy's ``OriginalABC`` does.

One iteration costs ``2 SN`` evaluations plus one per scout (``pop_size`` = food sources =
employed = onlookers).

Settings (Kamil et al. 2020 Sect. 6): SN = 100, limit = 5, 3 via-points, "maximum number of
iteration equal to 1000.  MCN = 100": ``iterations`` defaults to 1000 and ``mcn`` (the cycle
count of the adaptive limit, Eqs. (10)-(12)) to 100.  Abdulla & Hadi (2025) run their ABC
for 100 iterations with the population of their GWO; their study sets that.

Vectorisation: the employed bees all move at once (each touches only its own
source).  The onlookers also act at once, on a snapshot of the sources: a source
chosen by several onlookers keeps the best of their candidates if it beats it,
and its counter grows by the number of onlookers that failed to improve it
(reset to 0 when one of them improves it).  Sequential onlookers would see each
other's improvements within the phase; the difference is a matter of order, not
of the algorithm.

``adl_abc`` (Kamil et al. 2020 Sect. 5) replaces the fixed limit by the adaptive limit of
Eqs. (10)-(12), see :func:`adaptive_limit`, with the failure counter per
solution described in the paper's text.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.models.parameters import param, within
from swarmnav.planners.continuous import ContinuousPlanner
from swarmnav.planners.exact_check import ContinuousState
from swarmnav.planners.path_cost import inverse_fitness
from swarmnav.models.errors import ConfigError
from swarmnav.planners.problem import Problem

SCOUT_RULES = ("worst", "all")


def adaptive_limit(iteration: int, mcn: int, dimensions: int, limit: float) -> float:
    """The ADL-ABC abandonment limit after ``iteration`` cycles, Kamil et al. (2020) Eqs. (10)-(12).

    * Eq. (10): ``MAXLIM = MCN / D``;
    * Eq. (11): ``MINLIM = LIMIT / D``, with ``LIMIT`` the fixed limit of the
      plain ABC (the paper then substitutes Karaboga's default ``LIMIT = SN D``
      to get ``MINLIM = SN``; we keep the general form so the user's ``limit``
      counts);
    * Eq. (12): ``LIMIT(t) = MAXLIM - fix((MAXLIM - MINLIM) / MCN * t)``, a
      linear fall from ``MAXLIM`` at ``t = 0`` to ``MINLIM`` at ``t = MCN``,
      held at ``MINLIM`` afterwards.

    The extraction of Eq. (12) reads ``MAXLIM - fix(MAXLIM - MINLIM / MCN) * t``.
    Taken literally the limit turns negative after a few cycles; with ``fix``
    around the rate alone, ``fix((MAXLIM - MINLIM) / MCN)`` is 0 for the paper's
    own numbers (MCN = 100, D = 6) and the limit would never adapt.  So ``fix``
    is taken around the whole decrement.

    Args:
        iteration: cycles completed, ``t`` (counted from 1 by the planner).
        mcn: ``MCN``, the cycle count over which the limit falls.
        dimensions: ``D``, the number of decision variables.
        limit: the plain ABC's fixed limit.

    Returns:
        The limit a source's failure counter is compared with.
    """
    max_limit = mcn / dimensions                                   # Eq. (10)
    min_limit = limit / dimensions                                 # Eq. (11)
    if iteration >= mcn:
        return min_limit
    return max_limit - math.trunc((max_limit - min_limit) / mcn * iteration)   # Eq. (12)


@dataclass
class BeeColonyPlanner(ContinuousPlanner):
    """``abc``: Karaboga's Artificial Bee Colony (see the module docstring).

    Attributes:
        population: food sources ``SN`` (Kamil et al. 2020: 100).
        iterations: cycles of the loop (Kamil et al. 2020: "maximum number of iteration equal to 1000").
        limit: failures before a source is abandoned (Kamil et al. 2020: 5).
        scouts: ``"worst"`` (the paper's: the worst exhausted source only) or ``"all"``.
        adaptive_limit: use ADL-ABC's limit, Eqs. (10)-(12), instead of ``limit``.
        mcn: ``MCN`` of Eqs. (10)-(12) (Kamil et al. 2020: 100); only with ``adaptive_limit``.
    """

    name: ClassVar[str] = "abc"

    population: int = 100
    iterations: int = 1000
    limit: float = param(5.0, within(0, 1e9))
    scouts: str = "worst"
    adaptive_limit: bool = False
    mcn: int = param(100, within(1, 1_000_000))

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.limit <= 0:
            raise ConfigError("planner.params.limit", f"must be positive, got {self.limit!r}")
        if self.scouts not in SCOUT_RULES:
            raise ConfigError("planner.params.scouts", f"must be one of {', '.join(SCOUT_RULES)}, got {self.scouts!r}")
        if self.mcn < 1:
            raise ConfigError("planner.params.mcn", f"must be at least 1, got {self.mcn!r}")

    def current_limit(self, iteration: int, dimensions: int) -> float:
        """The abandonment limit in force during cycle ``iteration`` (0-based)."""
        if self.adaptive_limit:
            return adaptive_limit(iteration + 1, self.mcn, dimensions, self.limit)
        return float(self.limit)

    def init_swarm(self, state: ContinuousState, rng: np.random.Generator) -> None:
        sources = self.initial_solutions(state, self.population, rng)              # Eq. (6)
        state.population = sources
        state.costs = self.evaluate(state, sources)
        state.data["failures"] = np.zeros(self.population, dtype=np.int64)

    def _neighbours(self, sources: np.ndarray, chosen: np.ndarray, rng: np.random.Generator,
                    state: ContinuousState) -> np.ndarray:
        """Eq. (7) around ``sources[chosen]``: one coordinate moved relative to a random partner."""
        count, dims = chosen.size, sources.shape[1]
        # partner k != chosen: draw from the other SN - 1 sources
        partner = rng.integers(0, sources.shape[0] - 1, size=count)
        partner = partner + (partner >= chosen)
        coordinate = rng.integers(0, dims, size=count)
        phi = rng.uniform(-1.0, 1.0, size=count)
        rows = np.arange(count)
        candidates = sources[chosen].copy()
        x = candidates[rows, coordinate]
        candidates[rows, coordinate] = x + phi * (x - sources[partner, coordinate])
        return np.clip(candidates, state.lower, state.upper)

    def step(self, state: ContinuousState, problem: Problem, rng: np.random.Generator,
             iteration: int) -> None:
        sources = state.population
        costs = state.costs
        failures = state.data["failures"]
        count = sources.shape[0]

        # Employed bees: one trial per source, greedy selection (Eq. (7)).
        everyone = np.arange(count)
        trial = self._neighbours(sources, everyone, rng, state)
        trial_costs = self.evaluate(state, trial)
        better = trial_costs < costs
        sources[better] = trial[better]
        costs[better] = trial_costs[better]
        failures[better] = 0
        failures[~better] += 1

        # Onlooker bees: roulette over fitness (Eqs. (8)-(9)), then Eq. (7).
        fitness = inverse_fitness(costs, 1.0)                                     # Eq. (8), f >= 0
        chosen = rng.choice(count, size=count, p=fitness / fitness.sum())         # Eq. (9)
        trial = self._neighbours(sources, chosen, rng, state)
        trial_costs = self.evaluate(state, trial)
        visits = np.bincount(chosen, minlength=count)
        # best onlooker candidate per source: sort by (source, cost), take the first of each source
        order = np.lexsort((trial_costs, chosen))
        first = order[np.r_[True, chosen[order][1:] != chosen[order][:-1]]]
        target = chosen[first]
        improved = trial_costs[first] < costs[target]
        won = target[improved]
        sources[won] = trial[first[improved]]
        costs[won] = trial_costs[first[improved]]
        failures += visits
        failures[won] = 0

        # Scout bees: abandon the worst source that reached the limit (or every one), Eq. (6).
        limit = self.current_limit(iteration, sources.shape[1])
        abandoned = np.flatnonzero(failures >= limit)
        if abandoned.size and self.scouts == "worst":
            abandoned = abandoned[[int(np.argmax(costs[abandoned]))]]
        if abandoned.size:
            fresh = self.random_solutions(state, abandoned.size, rng)
            sources[abandoned] = fresh
            costs[abandoned] = self.evaluate(state, fresh)
            failures[abandoned] = 0


@dataclass
class AdaptiveLimitBeeColonyPlanner(BeeColonyPlanner):
    """``adl_abc``: ABC with the adaptive limit of Kamil et al. (2020) Eqs. (10)-(12).

    The same class as ``abc`` with ``adaptive_limit`` on by default.
    """

    name: ClassVar[str] = "adl_abc"

    adaptive_limit: bool = True
