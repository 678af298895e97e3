"""``mmas``: the MAX-MIN Ant System of Stützle & Hoos (2000) on the grid.

The baseline Hasan, Abdullah & Saleh (2023) improve on (their Sect. 2 and ref. [20]): a
colony of ants, on the shared colony core (:mod:`planners.ant_colony`) and the one
optimisation loop (:class:`planners.swarm.SwarmPlanner`), with the trail limits of
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

from swarmnav.planners.ant_colony import STEP_LENGTHS, GridGraph, best_tour_result, deposit, walk_colony
from swarmnav.planners.errors import check_parameters
from swarmnav.planners.grid_graph import grid_endpoints, grid_problem
from swarmnav.planners.improved_ant_colony import MAX_ANTS, MAX_COLONY_CELLS
from swarmnav.planners.max_min_trails import P_BEST, TrailLimits, trail_limits
from swarmnav.planners.problem import Problem
from swarmnav.planners.swarm import SwarmPlanner, SwarmState

DEPOSITS = ("iteration_best", "best_so_far")


@dataclass
class MaxMinColonyPlanner(SwarmPlanner):
    """MAX-MIN Ant System (Stützle & Hoos 2000) on the grid (see the module docstring).

    Args:
        ants: colony size m (50, as ``aco`` and ``iaco``; at most 10,000).
        iterations: iterations (100).
        alpha, beta: weights of pheromone and heuristic in Eq. (1) (1 and 2).
        rho: trail persistence of Eq. (6) (0.98; the evaporation is ``1 - rho``).
        p_best: Eq. (11)'s probability of building the best tour once converged (0.05).
        deposit: which one ant deposits, ``"iteration_best"`` or ``"best_so_far"``.
        max_steps: NumPy steps after which an ant fails (0: eight times rows + cols, at most
            half the cells).
        cell_m: grid resolution; ``None`` keeps the problem's (at most 500,000 cells).
        shortcut: line-of-sight shortcut of the best tour.
        max_evaluations: optional cap on tours walked (0 or None: none).
    """

    name: ClassVar[str] = "mmas"
    supports: ClassVar[frozenset[str]] = frozenset({"discs", "boxes"})
    ants: int = 50
    iterations: int = 100
    alpha: float = 1.0
    beta: float = 2.0
    rho: float = 0.98
    p_best: float = P_BEST
    deposit: str = "iteration_best"
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
            ("rho", 0.0 <= self.rho < 1.0, "must lie in [0, 1) (the trail persistence)"),
            ("p_best", 0.0 < self.p_best < 1.0, "must lie in (0, 1)"),
            ("deposit", self.deposit in DEPOSITS, f"must be one of {', '.join(DEPOSITS)}"),
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
        rr, cc = np.divmod(np.arange(rows * cols), cols)
        d_goal = np.hypot(rr - goal[0], cc - goal[1])
        visibility = 1.0 / (STEP_LENGTHS[None, :] + d_goal[safe_table])
        free = ~grid.occupied.ravel()
        degree = legal[free].sum(axis=1)
        # Before any tour the trails are uniform: tau_0 = tau_max whatever its value (Sect. 3.4).
        state.data = {"graph": graph, "start": graph.index(start), "goal": graph.index(goal),
                      "eta_beta": np.power(visibility, self.beta) * legal, "safe_table": safe_table,
                      "tau": np.where(free, 1.0, 0.0), "free": free,
                      "choices": max(float(degree.mean()) / 2.0, 1.5) if degree.size else 1.5,
                      "limits": None, "limit_history": [], "last_lengths": np.zeros(0), "successes": 0,
                      "best_tour": None, "best_length_cells": np.inf,
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
        iteration_best = None
        if arrived.size:
            best = int(np.argmin(lengths))
            iteration_best = (walk.tour(arrived[best]).copy(), float(lengths[best]))
            if iteration_best[1] < data["best_length_cells"]:
                data["best_tour"], data["best_length_cells"] = iteration_best
                state.best_cost = iteration_best[1] * problem.grid.cell_m
                state.best_solution = iteration_best[0]
        self.update(data, iteration_best)

    def update(self, data: dict[str, Any], iteration_best: tuple[np.ndarray, float] | None) -> None:
        """Eq. (6) then the limits: evaporate, one ant deposits ``1 / f``, clamp every free cell."""
        tau, free = data["tau"], data["free"]
        if data["best_tour"] is not None:
            limits = trail_limits(self.rho, data["best_length_cells"], max(len(data["best_tour"]) - 1, 1),
                                  data["choices"], self.p_best)
            if data["limits"] is None:
                tau[free] = limits.tau_max                                     # tau_0 = tau_max (Sect. 3.4)
            data["limits"] = limits
        tau *= self.rho
        source = iteration_best if self.deposit == "iteration_best" else (
            None if data["best_tour"] is None else (data["best_tour"], data["best_length_cells"]))
        if source is not None:
            deposit(tau, source[0][1:], 1.0 / source[1])
        limits: TrailLimits | None = data["limits"]
        if limits is not None:
            limits.clamp(tau, free)
            data["limit_history"].append((limits.tau_min, limits.tau_max))

    def finish(self, state: SwarmState, problem: Problem,
               rng: np.random.Generator) -> tuple[np.ndarray, dict[str, Any]]:
        waypoints, extra = best_tour_result(state, problem, self.shortcut, "mmas")
        limits: TrailLimits | None = state.data["limits"]
        if limits is not None:
            extra.update({"tau_min": limits.tau_min, "tau_max": limits.tau_max})
        return waypoints, extra
