"""The one optimisation loop shared by every swarm planner (after mealpy's base
class, without its grab-bag of operators).

A swarm planner supplies three things:

* ``init_state(problem, rng) -> SwarmState``: build and evaluate the first population;
* ``step(state, problem, rng, iteration)``: advance the population one iteration,
  updating ``state.best_*`` and ``state.evaluations`` for what it evaluated;
* ``finish(state, problem) -> (waypoints, extra_stats)``: turn the best solution into
  waypoints (and repair or reject it; raise ``NoPathFound`` when infeasible).

The loop owns everything else: timing, the iteration / evaluation budget, the
best-cost history, and building the :class:`Path`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from swarmnav.planners.problem import Path, Problem, check_endpoints


@dataclass
class SwarmState:
    """Mutable state of one swarm run.

    Attributes:
        best_solution: the best candidate found so far, in the planner's encoding.
        best_cost: its cost (lower is better).
        evaluations: objective evaluations spent so far.
        data: the algorithm's own arrays (population, pheromone, counters, ...).
        done: set by ``step`` when the run is complete before the iteration limit
            (e.g. the ant reached the goal); the loop then stops.
    """

    best_solution: Any
    best_cost: float
    evaluations: int = 0
    data: dict[str, Any] = field(default_factory=dict)
    done: bool = False

    def offer(self, solutions: np.ndarray, costs: np.ndarray) -> None:
        """Keep the best of a batch if it beats the current best (ties keep the incumbent)."""
        costs = np.asarray(costs, dtype=float)
        if costs.size == 0:
            return
        i = int(np.argmin(costs))
        if costs[i] < self.best_cost:
            self.best_cost = float(costs[i])
            self.best_solution = np.array(solutions[i], copy=True)


class SwarmPlanner:
    """Base class owning the loop: initialise, step, track the best, stop.

    Subclasses are dataclasses whose fields are the user-settable parameters and
    must define ``iterations`` (int) and may define ``max_evaluations``
    (int or None; 0 or None means no evaluation budget).
    """

    iterations: int
    max_evaluations: int | None = None

    def init_state(self, problem: Problem, rng: np.random.Generator) -> SwarmState:
        raise NotImplementedError

    def step(self, state: SwarmState, problem: Problem, rng: np.random.Generator,
             iteration: int) -> None:
        raise NotImplementedError

    def finish(self, state: SwarmState, problem: Problem) -> tuple[np.ndarray, dict[str, Any]]:
        raise NotImplementedError

    def plan(self, problem: Problem, rng: np.random.Generator) -> Path:
        t0 = time.perf_counter()
        check_endpoints(problem)
        state = self.init_state(problem, rng)
        history = [state.best_cost]
        budget = self.max_evaluations or 0
        done = 0
        converged_at = 0
        for iteration in range(self.iterations):
            if budget and state.evaluations >= budget:
                break
            self.step(state, problem, rng, iteration)
            if state.best_cost < history[-1]:
                converged_at = iteration + 1
            history.append(state.best_cost)
            done = iteration + 1
            if state.done:
                break
        waypoints, extra = self.finish(state, problem)
        # The iteration (1-based) after which the best cost no longer improved.
        extra.setdefault("convergence_iteration", converged_at)
        return Path.from_waypoints(waypoints, time.perf_counter() - t0, iterations=done,
                                   evaluations=state.evaluations,
                                   cost_history=tuple(float(c) for c in history), extra=extra)
