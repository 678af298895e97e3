"""``mmas``: the MAX-MIN Ant System of Stützle & Hoos (2000) on the grid.

The baseline Hasan, Abdullah & Saleh (2023) improve on (their Sect. 2 and ref. [20]): a
colony of ants, on the grid colony base (:class:`planners.ant_colony.GridColonyPlanner`) and
the one optimisation loop (:class:`planners.swarm.SwarmPlanner`), with the trail limits of
:mod:`planners.max_min_trails`.

* Transition rule (Stützle & Hoos 2000 Eq. 1; Hasan et al. 2023 Eq. 1): an ant at cell ``i``
  moves to an allowed neighbour ``j`` with probability proportional to ``tau_j^alpha eta_ij^beta``
  (roulette wheel); defaults ``alpha = 1``, ``beta = 2`` (their TSP settings).
* Update (Eq. 6; Hasan et al. Eq. 2): ``tau <- rho tau + 1 / f(s_best)`` on the cells of one
  ant's tour only: the iteration-best ant (``deposit = "iteration_best"``, their default) or the
  best so far (``"best_so_far"``); ``rho = 0.98`` is the trail *persistence*.
* Limits (Sect. 3.3, Eqs. 7 and 11): every trail is clamped to ``[tau_min, tau_max]`` after every
  update; ``tau_max = 1 / ((1 - rho) f(s_gb))`` follows the best so far, ``tau_min`` comes from
  ``p_best = 0.05``.
* Initialisation (Sect. 3.4): every trail starts at ``tau_max`` (before the first update the
  trails are uniform, so the first colony walks on the heuristic alone).

Readings for a start-goal grid problem (our choices, as the paper is about the TSP):

* pheromone sits on cells and ``eta_ij = 1 / (d_ij + d_jg)`` (the inverse of the estimated rest
  of the tour through ``j``), as for ``aco`` (:mod:`planners.ant_system`);
* ``f(s)`` is the tour length in cells; ``n`` of Eq. (11) is the best tour's number of moves (the
  decisions of one solution) and ``avg`` half the mean number of legal moves of a free cell
  (Stützle & Hoos take ``avg = n / 2`` for the TSP: half of the choices at a decision point);
* an ant never re-enters a cell; in a dead end it steps back one cell; only ants that reach
  the goal count; if no ant of an iteration arrives, the trails only evaporate (and stay
  clamped);
* neither the pheromone-trail smoothing nor the local search of Stützle & Hoos is applied.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from swarmnav.models.parameters import Range, param
from swarmnav.planners.ant_colony import GridColonyPlanner, deposit
from swarmnav.planners.colony_walk import ColonyWalk
from swarmnav.planners.map_arc_cost import map_arc_cost
from swarmnav.planners.max_min_trails import P_BEST, TrailLimits, trail_limits
from swarmnav.planners.problem import Problem
from swarmnav.planners.swarm import SwarmState

DEPOSITS = ("iteration_best", "best_so_far")


@dataclass
class MaxMinColonyPlanner(GridColonyPlanner):
    """MAX-MIN Ant System (Stützle & Hoos 2000) on the grid (see the module docstring).

    Args:
        ants: colony size m (50, as ``aco`` and ``iaco``; at most 10,000).
        iterations: iterations (100).
        alpha, beta: weights of pheromone and heuristic in Eq. (1) (1 and 2).
        rho: trail persistence of Eq. (6) (0.98; the evaporation is ``1 - rho``).
        p_best: Eq. (11)'s probability of building the best tour once converged (0.05).
        deposit: which one ant deposits, ``"iteration_best"`` or ``"best_so_far"``.

    ``max_steps`` (0: eight times rows + cols, at most half the cells), ``cell_m``, ``shortcut`` and
    ``max_evaluations`` are the grid colonies' (:class:`planners.ant_colony.GridColonyPlanner`).
    """

    name: ClassVar[str] = "mmas"
    supports: ClassVar[frozenset[str]] = frozenset({"discs", "boxes"})
    rho: float = 0.98
    beta: float = 2.0
    p_best: float = param(P_BEST, Range(0, 1, low_open=True, high_open=True))
    deposit: str = param("iteration_best", choices=DEPOSITS)

    def init_trails(self, state: SwarmState, problem: Problem, start: tuple[int, int], goal: tuple[int, int]) -> None:
        data = state.data
        free = ~problem.grid.occupied.ravel()
        degree = data["legal"][free].sum(axis=1)
        # Before any tour the trails are uniform: tau_0 = tau_max whatever its value (Sect. 3.4).
        data.update({"eta_beta": np.power(self.goal_visibility(state), self.beta) * data["legal"],
                     "tau": np.where(free, 1.0, 0.0), "free": free,
                     "choices": max(float(degree.mean()) / 2.0, 1.5) if degree.size else 1.5,
                     "limits": None, "limit_history": [], "max_steps": self.default_max_steps(problem)})

    def keep_best(self, state: SwarmState, problem: Problem, tour: np.ndarray, length_cells: float) -> None:
        """Keep the iteration's best tour if it is shorter, in cells (``f(s_gb)`` of Eq. (7)), than the best so far."""
        data = state.data
        if length_cells < data["best_length_cells"]:
            data["best_length_cells"] = length_cells
            state.best_cost = length_cells * problem.grid.cell_m
            state.best_solution = tour

    def update(self, state: SwarmState, walk: ColonyWalk, arrived: np.ndarray, lengths: np.ndarray,
               iteration_best: tuple[np.ndarray, float] | None) -> None:
        """Eq. (6) then the limits: evaporate, one ant deposits ``1 / f``, clamp every free cell."""
        data = state.data
        tau, free = data["tau"], data["free"]
        best_tour = state.best_solution
        if best_tour is not None:
            limits = trail_limits(self.rho, data["best_length_cells"], max(len(best_tour) - 1, 1),
                                  data["choices"], self.p_best)
            if data["limits"] is None:
                tau[free] = limits.tau_max                                     # tau_0 = tau_max (Sect. 3.4)
            data["limits"] = limits
        tau *= self.rho
        source = iteration_best if self.deposit == "iteration_best" else (
            None if best_tour is None else (best_tour, data["best_length_cells"]))
        if source is not None:
            deposit(tau, source[0][1:], 1.0 / source[1])
        limits: TrailLimits | None = data["limits"]
        if limits is not None:
            limits.clamp(tau, free)
            data["limit_history"].append((limits.tau_min, limits.tau_max))

    def extra_stats(self, state: SwarmState, problem: Problem) -> dict[str, Any]:
        """The trail limits, and the best tour's total arc cost priced on the map as IMMAS's is
        (:mod:`planners.map_arc_cost`, for Hasan et al. (2023)'s cost comparison)."""
        data = state.data
        limits: TrailLimits | None = data["limits"]
        goal = divmod(int(data["goal"]), problem.grid.occupied.shape[1])
        extra = {"map_arc_cost": map_arc_cost(problem.grid.occupied, goal, data["graph"].cells(state.best_solution))}
        return extra if limits is None else {**extra, "tau_min": limits.tau_min, "tau_max": limits.tau_max}
