"""``aco``: the classic Ant System of Dorigo, Maniezzo & Colorni (1996) on the grid.

The plain ant colony, on the grid colony base (:class:`planners.ant_colony.GridColonyPlanner`)
and the one optimisation loop (:class:`planners.swarm.SwarmPlanner`).  It stands in for the
unnamed "traditional ACO" baselines of Gong et al. (2022) (IACO: its refs.
[19] and [24] are not given), so that IACO can be compared with a plain ant system
on the same maps.

* Transition rule (Dorigo et al. 1996, Eq. 1): ant ``k`` at cell ``i`` moves to an
  allowed (not yet visited) neighbour ``j`` with probability
  ``tau_j^alpha eta_ij^beta / sum_l tau_l^alpha eta_il^beta`` (roulette wheel).
* Pheromone update, ant-cycle version (Eqs. 2-4): after every ant has walked,
  ``tau <- (1 - rho) tau + sum_k delta_k`` with ``delta_k = Q / L_k`` on the cells of
  ant ``k``'s tour.
* Parameters: the paper's best ant-cycle values ``alpha = 1``, ``beta = 5``,
  ``rho = 0.5``, ``Q = 100``; ``tau_0`` a small constant (the paper's ``c``; ours 1).

Readings for a start-goal grid problem (our choices, as the paper is about the TSP):

* the visibility ``eta_ij = 1 / d_ij`` of the TSP becomes, by default
  (``heuristic = "goal"``), ``1 / (d_ij + d_jg)``: the inverse of the estimated
  length of the rest of the tour through ``j`` (``d_jg`` the straight distance from
  ``j`` to the goal, in cells); ``heuristic = "edge"`` keeps the literal ``1 / d_ij``
  (1 or ``1/sqrt 2`` on the grid, which hardly guides an ant);
* pheromone sits on cells, as in :mod:`planners.improved_ant_colony`;
* an ant never re-enters a cell (the tabu list); in a dead end it steps back one cell,
  and it fails after ``max_steps`` NumPy steps; only ants that reach the goal deposit;
* the returned path is the best tour of the run, shortcut by exact line of sight
  (the raw cells stay in ``stats.extra``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.models.parameters import above, param
from swarmnav.planners.ant_colony import GridColonyPlanner, deposit, evaporate
from swarmnav.planners.colony_walk import STEP_LENGTHS, ColonyWalk
from swarmnav.planners.problem import Problem
from swarmnav.planners.swarm import SwarmState

HEURISTICS = ("goal", "edge")


@dataclass
class AntSystemPlanner(GridColonyPlanner):
    """Ant System (Dorigo, Maniezzo & Colorni 1996), ant-cycle, on the grid (see the module docstring).

    Args:
        ants: colony size m (50, as IACO's comparison; at most 10,000).
        iterations: cycles (100).
        alpha, beta: weights of pheromone and visibility in Eq. (1) (1 and 5).
        rho: evaporation (0.5).
        q: deposit constant Q of Eq. (4) (100).
        initial_pheromone: ``tau_0`` on every free cell (1).
        heuristic: ``"goal"`` (``1 / (d_ij + d_jg)``) or ``"edge"`` (``1 / d_ij``).

    ``max_steps`` (0: eight times rows + cols, at most half the cells), ``cell_m``, ``shortcut`` and
    ``max_evaluations`` are the grid colonies' (:class:`planners.ant_colony.GridColonyPlanner`).
    """

    name: ClassVar[str] = "aco"
    supports: ClassVar[frozenset[str]] = frozenset({"discs", "boxes"})
    rho: float = 0.5
    beta: float = 5.0
    q: float = param(100.0, above(0, 1e12))
    initial_pheromone: float = param(1.0, above(0, 1e12))
    heuristic: str = param("goal", choices=HEURISTICS)

    def init_trails(self, state: SwarmState, problem: Problem, start: tuple[int, int], goal: tuple[int, int]) -> None:
        data = state.data
        if self.heuristic == "goal":
            visibility = self.goal_visibility(state)
        else:
            visibility = np.broadcast_to(1.0 / STEP_LENGTHS, data["legal"].shape)
        data.update({"eta_beta": np.power(visibility, self.beta) * data["legal"],
                     "tau": np.where(problem.grid.occupied.ravel(), 0.0, self.initial_pheromone),
                     "max_steps": self.default_max_steps(problem)})

    def update(self, state: SwarmState, walk: ColonyWalk, arrived: np.ndarray, lengths: np.ndarray,
               iteration_best: tuple[np.ndarray, float] | None) -> None:
        """Eqs. (2)-(4): evaporate, then every arrived ant ``k`` deposits ``Q / L_k`` on its cells."""
        tau = state.data["tau"]
        evaporate(tau, self.rho)                                                # Eq. (2)
        if arrived.size:
            tours = [walk.tour(a)[1:] for a in arrived]
            deposit(tau, np.concatenate(tours), np.repeat(self.q / lengths, [len(t) for t in tours]))  # Eqs. (3)-(4)
