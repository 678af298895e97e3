"""``aco``: the classic Ant System of Dorigo, Maniezzo & Colorni (1996) on the grid.

The plain ant colony, on the shared colony core (:mod:`planners.ant_colony`) and the
one optimisation loop (:class:`planners.swarm.SwarmPlanner`).  It stands in for the
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
from typing import Any, ClassVar

import numpy as np

from swarmnav.models.parameters import Range, above, within
from swarmnav.planners.ant_colony import STEP_LENGTHS, GridGraph, best_tour_result, deposit, evaporate, walk_colony
from swarmnav.planners.errors import check_parameters
from swarmnav.planners.grid_graph import grid_endpoints, grid_problem
from swarmnav.planners.improved_ant_colony import MAX_ANTS, MAX_COLONY_CELLS
from swarmnav.planners.problem import Problem
from swarmnav.planners.swarm import SwarmPlanner, SwarmState

HEURISTICS = ("goal", "edge")


@dataclass
class AntSystemPlanner(SwarmPlanner):
    """Ant System (Dorigo, Maniezzo & Colorni 1996), ant-cycle, on the grid (see the module docstring).

    Args:
        ants: colony size m (50, as IACO's comparison; at most 10,000).
        iterations: cycles (100).
        alpha, beta: weights of pheromone and visibility in Eq. (1) (1 and 5).
        rho: evaporation (0.5).
        q: deposit constant Q of Eq. (4) (100).
        initial_pheromone: ``tau_0`` on every free cell (1).
        heuristic: ``"goal"`` (``1 / (d_ij + d_jg)``) or ``"edge"`` (``1 / d_ij``).
        max_steps: NumPy steps after which an ant fails (0: eight times rows + cols, at most
            half the cells).
        cell_m: grid resolution; ``None`` keeps the problem's (at most 500,000 cells).
        shortcut: line-of-sight shortcut of the best tour.
        max_evaluations: optional cap on tours walked (0 or None: none).
    """

    name: ClassVar[str] = "aco"
    parameter_ranges: ClassVar[dict[str, Range]] = {
        "ants": within(1, MAX_ANTS), "iterations": within(1, 1_000_000), "alpha": within(0, 100),
        "beta": within(0, 100), "rho": within(0, 1), "q": above(0, 1e12), "initial_pheromone": above(0, 1e12),
        "max_steps": within(0, 100_000_000), "cell_m": within(1e-6, 100), "max_evaluations": within(0, 1e9)}  # models.parameters: checked on build
    supports: ClassVar[frozenset[str]] = frozenset({"discs", "boxes"})
    ants: int = 50
    iterations: int = 100
    alpha: float = 1.0
    beta: float = 5.0
    rho: float = 0.5
    q: float = 100.0
    initial_pheromone: float = 1.0
    heuristic: str = "goal"
    max_steps: int = 0
    cell_m: float | None = None
    shortcut: bool = True
    max_evaluations: int | None = None

    def __post_init__(self) -> None:
        check_parameters(self, (
            ("ants", 1 <= self.ants <= MAX_ANTS, f"must lie in [1, {MAX_ANTS:,}]"),
            ("iterations", self.iterations >= 1, "must be at least 1"),
            ("alpha", self.alpha >= 0, "must not be negative"),
            ("beta", self.beta >= 0, "must not be negative"),
            ("rho", 0.0 <= self.rho < 1.0, "must lie in [0, 1)"),
            ("q", self.q > 0, "must be positive"),
            ("initial_pheromone", self.initial_pheromone > 0, "must be positive"),
            ("heuristic", self.heuristic in HEURISTICS, f"must be one of {', '.join(HEURISTICS)}"),
            ("max_steps", self.max_steps >= 0, "must not be negative"),
            ("cell_m", self.cell_m is None or self.cell_m > 0, "must be positive"),
            ("max_evaluations", self.max_evaluations is None or self.max_evaluations >= 0,
             "must not be negative"),
        ))

    def prepare(self, problem: Problem) -> Problem:
        return grid_problem(problem, self.cell_m, MAX_COLONY_CELLS)

    def init_state(self, state: SwarmState, problem: Problem, rng: np.random.Generator) -> None:
        grid = problem.grid
        start, goal = grid_endpoints(problem, grid)
        graph = GridGraph.of(grid)
        rows, cols = grid.shape
        legal = graph.table >= 0
        safe_table = np.where(legal, graph.table, 0)
        if self.heuristic == "goal":
            rr, cc = np.divmod(np.arange(rows * cols), cols)
            d_goal = np.hypot(rr - goal[0], cc - goal[1])
            visibility = 1.0 / (STEP_LENGTHS[None, :] + d_goal[safe_table])
        else:
            visibility = np.broadcast_to(1.0 / STEP_LENGTHS, legal.shape)
        state.data = {"graph": graph, "start": graph.index(start), "goal": graph.index(goal),
                      "eta_beta": np.power(visibility, self.beta) * legal, "safe_table": safe_table,
                      "tau": np.where(grid.occupied.ravel(), 0.0, self.initial_pheromone),
                      "last_lengths": np.zeros(0), "successes": 0,
                      "max_steps": self.max_steps or min(rows * cols // 2, 8 * (rows + cols))}

    def step(self, state: SwarmState, problem: Problem, rng: np.random.Generator, iteration: int) -> None:
        data = state.data
        tau = data["tau"]
        cell_weights = np.power(tau, self.alpha)[data["safe_table"]]          # Eq. (1)'s numerator
        cell_weights *= data["eta_beta"]
        ants = int(min(self.ants, state.evaluations_left))                     # a tour is one evaluation
        walk = walk_colony(data["graph"], data["start"], data["goal"], ants, cell_weights, None, rng,
                           data["max_steps"])
        state.evaluations += ants
        arrived = np.flatnonzero(walk.reached)
        lengths = walk.length_cells[arrived]
        data["last_lengths"] = lengths
        data["successes"] += arrived.size
        evaporate(tau, self.rho)                                                # Eq. (2)
        if arrived.size:
            tours = [walk.tour(a)[1:] for a in arrived]
            deposit(tau, np.concatenate(tours), np.repeat(self.q / lengths, [len(t) for t in tours]))  # Eqs. (3)-(4)
            best = int(np.argmin(lengths))
            cost_m = float(lengths[best]) * problem.grid.cell_m
            if cost_m < state.best_cost:
                state.best_cost = cost_m
                state.best_solution = walk.tour(arrived[best]).copy()

    def finish(self, state: SwarmState, problem: Problem,
               rng: np.random.Generator) -> tuple[np.ndarray, dict[str, Any]]:
        return best_tour_result(state, problem, self.shortcut, "aco")
