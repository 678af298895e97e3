"""The ant-colony base shared by the colony planners, as :mod:`planners.continuous` is for the continuous ones.

* :class:`AntColonyPlanner`: what every colony has, its parameters and their checks: ``ants`` ants
  walk in each of ``iterations`` iterations, the transition rule weighs pheromone by ``alpha``
  (Eq. (1) of Dorigo, Maniezzo & Colorni 1996 and of Stützle & Hoos 2000; Eq. (1) of Gong et al.
  2022; Eq. (3) of Habib et al. 2021), the update by ``rho``, the best tour is shortcut by line of
  sight (``shortcut``), and a tour walked is one evaluation of the budget (``max_evaluations``).
  ``maco`` (:mod:`planners.waiter_ant_colony`) builds on it over random nodes.
* :class:`GridColonyPlanner`: a colony on the inflated occupancy grid (``aco``, ``mmas``, ``iaco``):
  the heuristic weight ``beta``, the ants' ``max_steps``, the grid's ``cell_m``, and the iteration
  itself: fold the paper's transition rule into weight tables, walk the colony
  (:func:`planners.colony_walk.walk_colony`), keep the best tour, apply the paper's update; the
  best tour's waypoints and the statistics every colony reports at the end.
* :func:`roulette`, :func:`evaporate` and :func:`deposit`: the roulette-wheel choice and the
  pheromone update ``tau <- (1 - rho) tau + sum(delta)``, shared by every colony and by ``immas``.

Each paper's planner keeps only what its paper defines (its transition weights, its update, its
own parameters), and all run through :class:`planners.swarm.SwarmPlanner`, the one optimisation loop.
``immas`` (Hasan et al. 2023, :mod:`planners.improved_max_min_ant_system`) is not on this base: its
Algorithm 3 moves one robot once, cell by cell, over a pheromone field propagated from the goal (no
colony, no ants, no per-iteration update), so it shares :func:`roulette` and the MAX-MIN limits
(:mod:`planners.max_min_trails`) only.  Its ``iterations`` (moves; 0: the cells) and ``rho`` (in (0, 1])
mean other things than here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from swarmnav.models.errors import ConfigError
from swarmnav.models.parameters import Range, param, within
from swarmnav.models.scenario_limits import MAX_COLONY_WALK_CELLS
from swarmnav.planners.colony_walk import STEP_LENGTHS, ColonyWalk, GridGraph, walk_colony
from swarmnav.planners.errors import NoPathFound, check_parameters
from swarmnav.planners.grid_graph import cell_clearance_m, cells_to_waypoints, count_bends, grid_endpoints, grid_problem
from swarmnav.planners.grid_shortcut import exact_shortcut
from swarmnav.planners.problem import Problem
from swarmnav.planners.swarm import SwarmPlanner, SwarmState

#: Most ants: on the grid each keeps a visited mask of the whole grid.
MAX_ANTS = 10_000
#: Most cells a grid colony's grid may have: the colony's tables take about 600 bytes a cell.
MAX_COLONY_CELLS = 500_000



def roulette(weights: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Draw one column per row with probability proportional to its weight.

    Args:
        weights: (A, K) non-negative weights, one row per ant (0 = not allowed).
        rng: the run's generator; exactly ``A`` uniforms are drawn.

    Returns:
        (choice (A,) column indices, ok (A,) bool: False where a row has no positive weight;
        its choice is then meaningless).
    """
    w = np.asarray(weights, dtype=float)
    cumulative = w.cumsum(axis=1)
    total = cumulative[:, -1]
    ok = total > 0.0
    draw = rng.random(w.shape[0]) * total
    choice = (cumulative <= draw[:, None]).sum(axis=1)
    np.minimum(choice, w.shape[1] - 1, out=choice)
    return choice, ok


def evaporate(tau: np.ndarray, rho: float) -> None:
    """In place: ``tau <- (1 - rho) * tau`` (the evaporation half of the ACO update)."""
    tau *= 1.0 - rho


def deposit(tau: np.ndarray, indices: np.ndarray, amounts: np.ndarray | float) -> None:
    """In place: add ``amounts`` at ``indices`` (repeated indices accumulate)."""
    np.add.at(tau, np.asarray(indices, dtype=np.int64), amounts)


@dataclass
class AntColonyPlanner(SwarmPlanner):
    """The parameters every ant colony shares, each declared with its range on its field (subclasses add their paper's).

    Attributes:
        ants: colony size m (at most :data:`MAX_ANTS`, 10,000).
        iterations: colony iterations (at least 1).
        alpha: weight of the pheromone in the transition rule.
        rho: the update's rate: the evaporation of ``tau <- (1 - rho) tau + delta`` (the MAX-MIN
            Ant System's persistence, see :mod:`planners.max_min_ant_system`); in [0, 1).
        shortcut: line-of-sight shortcut of the best tour (the raw tour stays in ``stats.extra``).
        max_evaluations: optional cap on tours walked (0 or None: none); one ant's tour is one
            evaluation, so a budgeted iteration sends out only the ants the budget has left.
    """

    # Each parameter's range or choices on its field (models.parameters.param; a subclass that changes a
    # default keeps the range): the reader checks them when the planner is built.
    name: ClassVar[str]
    ants: int = param(50, within(1, MAX_ANTS))
    iterations: int = param(100, within(1, 1_000_000))
    alpha: float = param(1.0, within(0, 100))
    rho: float = param(0.5, Range(0, 1, high_open=True))
    shortcut: bool = True
    max_evaluations: int | None = param(None, within(0, 1e9))

    def colony_size(self, state: SwarmState) -> int:
        """The ants of this iteration: ``ants``, or fewer when the budget has less left (a tour is
        one evaluation)."""
        return int(min(self.ants, state.evaluations_left))


@dataclass
class GridColonyPlanner(AntColonyPlanner):
    """An ant colony on the inflated occupancy grid: the loop of one iteration and the run's end.

    A subclass supplies its paper's pheromone and heuristic (:meth:`init_trails`), the weights
    its ants walk on (:meth:`move_weights`; by default the classic transition rule
    ``tau_j^alpha eta_ij^beta`` with a fixed ``eta^beta`` table) and its update (:meth:`update`).

    Readings shared by the grid colonies (the papers' are about graphs, or give no grid details):
    pheromone sits on cells (the move into cell j reads ``tau_j``); an ant never re-enters a cell
    (its tabu list), in a dead end it steps back one cell (the dead end stays tabu), and it fails
    after ``max_steps`` NumPy steps; only ants that reach the goal count.

    Attributes:
        beta: weight of the heuristic in the transition rule.
        max_steps: NumPy steps after which an ant fails (0: the planner's default).
        cell_m: grid resolution; ``None`` keeps the problem's.  The grid may have at most
            :data:`MAX_COLONY_CELLS` (500,000) cells.
    """

    beta: float = param(5.0, within(0, 100))
    max_steps: int = param(0, within(0, 100_000_000))
    cell_m: float | None = param(None, within(1e-6, 100))

    def __post_init__(self) -> None:
        # The one rule between two parameters (each one's own range is on its field).
        check_parameters(self, (
            ("max_steps", self.ants * self.max_steps <= MAX_COLONY_WALK_CELLS,
             f"ants x max_steps is {self.ants * self.max_steps:,} tour cells, at most {MAX_COLONY_WALK_CELLS:,} "
             "(MAX_COLONY_WALK_CELLS: an iteration's tours are drawn up front)"),
        ))

    # ------------------------------------------------------------ the paper's parts
    def init_trails(self, state: SwarmState, problem: Problem, start: tuple[int, int], goal: tuple[int, int]) -> None:
        """Add the paper's initial pheromone ``state.data["tau"]`` (0 on occupied cells) and its
        heuristic tables to ``state.data``."""
        raise NotImplementedError

    def move_weights(self, state: SwarmState, problem: Problem,
                     iteration: int) -> tuple[np.ndarray, np.ndarray | None, int, float]:
        """What the ants of this iteration walk on: (cell weights (N, 8), turn weights (9, 8) or None,
        their ``max_steps``, the tour length in cells beyond which an ant stops).

        By default Dorigo et al. (1996) Eq. (1)'s numerator ``tau_j^alpha eta_ij^beta``, with the
        fixed ``data["eta_beta"]`` and ``data["max_steps"]``, and no length limit.
        """
        data = state.data
        cell_weights = np.power(data["tau"], self.alpha)[data["safe_table"]]          # Eq. (1)'s numerator
        cell_weights *= data["eta_beta"]
        return cell_weights, None, data["max_steps"], np.inf

    def update(self, state: SwarmState, walk: ColonyWalk, arrived: np.ndarray, lengths: np.ndarray,
               iteration_best: tuple[np.ndarray, float] | None) -> None:
        """The paper's pheromone update after the walk (``arrived``: the ants that reached the goal,
        ``lengths`` their tours' in cells, ``iteration_best`` the best of them (tour, length) or None)."""
        raise NotImplementedError

    def extra_stats(self, state: SwarmState, problem: Problem) -> dict[str, Any]:
        """The paper's own statistics, added to the shared ones of :meth:`finish`."""
        return {}

    # -------------------------------------------------------------- shared parts
    def prepare(self, problem: Problem) -> Problem:
        return grid_problem(problem, self.cell_m, MAX_COLONY_CELLS)

    def default_max_steps(self, problem: Problem) -> int:
        """``max_steps``, or when 0 eight times rows + cols, at most half the cells."""
        rows, cols = problem.grid.shape
        return self.max_steps or min(rows * cols // 2, 8 * (rows + cols))

    def goal_visibility(self, state: SwarmState) -> np.ndarray:
        """(N, 8) ``1 / (d_ij + d_jg)`` of every move (``d_jg`` the straight distance from ``j`` to the
        goal, in cells): the inverse of the estimated length of the rest of the tour through ``j``."""
        data = state.data
        return 1.0 / (STEP_LENGTHS[None, :] + data["d_goal"][data["safe_table"]])

    def init_state(self, state: SwarmState, problem: Problem, rng: np.random.Generator) -> None:
        grid = problem.grid
        start, goal = grid_endpoints(problem, grid)
        graph = GridGraph.of(grid)
        rows, cols = grid.shape
        legal = graph.table >= 0
        rr, cc = np.divmod(np.arange(rows * cols), cols)
        state.data = {"graph": graph, "start": graph.index(start), "goal": graph.index(goal), "legal": legal,
                      "safe_table": np.where(legal, graph.table, 0), "d_goal": np.hypot(rr - goal[0], cc - goal[1]),
                      "last_lengths": np.zeros(0), "successes": 0, "best_length_cells": math.inf}
        self.init_trails(state, problem, start, goal)

    def step(self, state: SwarmState, problem: Problem, rng: np.random.Generator, iteration: int) -> None:
        """One iteration: the colony walks on :meth:`move_weights`, the best tour is kept
        (:meth:`keep_best`), then the paper's :meth:`update`."""
        data = state.data
        cell_weights, turn_weights, max_steps, max_length = self.move_weights(state, problem, iteration)
        ants = self.colony_size(state)
        if ants * max_steps > MAX_COLONY_WALK_CELLS:  # a default max_steps on a large grid: before allocating
            raise ConfigError("planner.params.max_steps", f"{ants:,} ants x {max_steps:,} steps is "
                              f"{ants * max_steps:,} tour cells, at most {MAX_COLONY_WALK_CELLS:,} "
                              "(MAX_COLONY_WALK_CELLS): give fewer ants or a smaller max_steps")
        walk = walk_colony(data["graph"], data["start"], data["goal"], ants, cell_weights, turn_weights, rng,
                           max_steps, max_length=max_length)
        state.evaluations += ants
        arrived = np.flatnonzero(walk.reached)
        lengths = walk.length_cells[arrived]
        data["last_lengths"] = lengths
        data["successes"] += arrived.size
        iteration_best = None
        if arrived.size:
            best = int(np.argmin(lengths))
            iteration_best = (walk.tour(arrived[best]).copy(), float(lengths[best]))
            self.keep_best(state, problem, *iteration_best)
        self.update(state, walk, arrived, lengths, iteration_best)

    def keep_best(self, state: SwarmState, problem: Problem, tour: np.ndarray, length_cells: float) -> None:
        """Keep the iteration's best tour if it is shorter, in metres, than the best so far."""
        cost_m = length_cells * problem.grid.cell_m
        if cost_m < state.best_cost:
            state.best_cost, state.best_solution = cost_m, tour
            state.data["best_length_cells"] = length_cells

    def finish(self, state: SwarmState, problem: Problem,
               rng: np.random.Generator) -> tuple[np.ndarray, dict[str, Any]]:
        """The best tour as waypoints (shortcut or not) and the statistics every colony reports (raw
        cells and length, the last iteration's tour lengths, bends), then the paper's own.

        Raises:
            NoPathFound: no ant reached the goal.
        """
        data = state.data
        if state.best_solution is None:
            raise NoPathFound(f"{self.name}: no ant of {state.evaluations} reached the goal")
        grid = problem.grid
        cells = [(int(r), int(c)) for r, c in data["graph"].cells(state.best_solution)]
        raw = cells_to_waypoints(problem, grid, cells)
        waypoints = exact_shortcut(problem, raw) if self.shortcut else raw
        lengths_m = data["last_lengths"] * grid.cell_m
        clearance = cell_clearance_m(grid)
        idx = np.array(cells)
        extra = {
            "moves": len(cells) - 1,
            "mean_cell_clearance_m": float(np.mean(clearance[idx[:, 0], idx[:, 1]])),
            "raw_cells": [list(c) for c in cells],
            "raw_length_m": state.best_cost,
            "mean_length_m": float(np.mean(lengths_m)) if lengths_m.size else math.nan,
            "std_length_m": float(np.std(lengths_m)) if lengths_m.size else math.nan,
            "bends": count_bends(cells),
            "successful_tours": int(data["successes"]),
        }
        extra.update(self.extra_stats(state, problem))
        return waypoints, extra
