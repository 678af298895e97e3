"""The one optimisation loop shared by every swarm planner (after mealpy's base
class, without its grab-bag of operators).

A swarm planner supplies:

* ``init_state(state, problem, rng)``: fill in the fresh state (build and evaluate
  the first population, or the colony's tables);
* ``step(state, problem, rng, iteration)``: advance one iteration, updating the
  best and ``state.evaluations`` for what it evaluated;
* ``finish(state, problem, rng) -> (waypoints, extra_stats)``: turn the best into
  waypoints, or raise :class:`planners.errors.NoPathFound`;

and may supply ``prepare(problem)`` (e.g. a grid planner's own ``cell_m``),
``iteration_limit(problem)`` (an iteration count that depends on the problem)
and a *repair* stage, ``needs_repair(state, problem)`` and
``repair_step(state, problem, rng, round_index)``, run after the iterations for
at most ``repair_limit()`` rounds while the best is not collision-free.

The loop owns everything else: timing, the iteration budget, the best-cost
history with the evaluations spent by each of its entries, and the
**evaluation budget**, which holds everywhere.
``max_evaluations`` (0 or None: none) is carried by the state; a step evaluates
at most :attr:`SwarmState.evaluations_left` candidates (the continuous planners
evaluate the first ones of a batch and give the rest an infinite cost, the ant
colonies send out fewer ants), and the loop stops, search or repair, once
nothing is left.  If the run then has no feasible path and the budget is what
stopped it, the loop raises :class:`planners.errors.BudgetExceeded` instead of
``NoPathFound``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from swarmnav.planners.errors import BudgetExceeded, NoPathFound
from swarmnav.planners.problem import Path, Problem, check_endpoints


@dataclass
class SwarmState:
    """Mutable state of one swarm run.

    Attributes:
        max_evaluations: the evaluation budget (None: none).
        best_solution: the best candidate found so far, in the planner's encoding.
        best_cost: its cost (lower is better).
        evaluations: objective evaluations (candidates scored, tours walked,
            moves made) spent so far.
        population: the current candidates, where the algorithm keeps a population
            (for PSO the personal bests); ``finish`` falls back on them.
        costs: their costs.
        done: set by ``step`` when the run is complete before the iteration limit
            (e.g. the robot reached the goal); the loop then stops.
        data: the algorithm's own arrays (pheromone, counters, ...).
    """

    max_evaluations: int | None = None
    best_solution: Any = None
    best_cost: float = math.inf
    evaluations: int = 0
    population: np.ndarray | None = None
    costs: np.ndarray | None = None
    done: bool = False
    data: dict[str, Any] = field(default_factory=dict)

    @property
    def evaluations_left(self) -> float:
        """Evaluations the budget still allows (``inf`` without a budget)."""
        if self.max_evaluations is None:
            return math.inf
        return max(self.max_evaluations - self.evaluations, 0)

    @property
    def exhausted(self) -> bool:
        """The budget is spent."""
        return self.evaluations_left <= 0

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
    """Base class owning the loop: initialise, step, track the best, repair, stop.

    Subclasses are dataclasses whose fields are the user-settable parameters and
    must define ``iterations`` (int) and may define ``max_evaluations``
    (int or None; 0 or None means no evaluation budget).
    """

    iterations: int
    max_evaluations: int | None = None
    #: The state class this planner's hooks expect.
    state_type: ClassVar[type[SwarmState]] = SwarmState

    # --------------------------------------------------------- hooks to supply
    def init_state(self, state: SwarmState, problem: Problem, rng: np.random.Generator) -> None:
        raise NotImplementedError

    def step(self, state: SwarmState, problem: Problem, rng: np.random.Generator, iteration: int) -> None:
        raise NotImplementedError

    def finish(self, state: SwarmState, problem: Problem,
               rng: np.random.Generator) -> tuple[np.ndarray, dict[str, Any]]:
        raise NotImplementedError

    # ------------------------------------------------------- optional hooks
    def prepare(self, problem: Problem) -> Problem:
        """The problem the run works on (default: the one given)."""
        return problem

    def iteration_limit(self, problem: Problem) -> int:
        """Iterations of the search (default: ``iterations``)."""
        return self.iterations

    def repair_limit(self) -> int:
        """Most repair rounds after the search (default: none)."""
        return 0

    def needs_repair(self, state: SwarmState, problem: Problem) -> bool:
        """Whether the best so far still needs repairing."""
        return False

    def repair_step(self, state: SwarmState, problem: Problem, rng: np.random.Generator,
                    round_index: int) -> None:
        raise NotImplementedError

    # ----------------------------------------------------------------- loop
    def plan(self, problem: Problem, rng: np.random.Generator) -> Path:
        return self.run_search(problem, rng, self.state_type(max_evaluations=self.max_evaluations or None))

    def run_search(self, problem: Problem, rng: np.random.Generator, state: SwarmState) -> Path:
        """The loop of :meth:`plan` on a state made by the caller (a subclass may put its run's
        settings in it first)."""
        t0 = time.perf_counter()
        problem = self.prepare(problem)
        check_endpoints(problem)
        self.init_state(state, problem, rng)
        history = [state.best_cost]
        spent = [state.evaluations]  # cumulative evaluations at each entry of ``history``
        elapsed = [time.perf_counter() - t0]  # wall seconds at each entry of ``history``
        done = 0
        converged_at = 0
        for iteration in range(self.iteration_limit(problem)):
            if state.done or state.exhausted:
                break
            self.step(state, problem, rng, iteration)
            if state.best_cost < history[-1]:
                converged_at = iteration + 1
            history.append(state.best_cost)
            spent.append(state.evaluations)
            elapsed.append(time.perf_counter() - t0)
            done = iteration + 1
        repairs = 0
        while repairs < self.repair_limit() and not state.exhausted and self.needs_repair(state, problem):
            self.repair_step(state, problem, rng, repairs)
            repairs += 1
        try:
            waypoints, extra = self.finish(state, problem, rng)
        except NoPathFound as exc:
            if state.exhausted:
                raise BudgetExceeded(f"{exc} (the budget of {state.max_evaluations} evaluations is spent)") from exc
            raise
        # The iteration (1-based) after which the best cost no longer improved.
        extra.setdefault("convergence_iteration", converged_at)
        if self.repair_limit():
            extra.setdefault("repair_rounds", repairs)
        return Path.from_waypoints(waypoints, time.perf_counter() - t0, iterations=done,
                                   evaluations=state.evaluations,
                                   cost_history=tuple(float(c) for c in history),
                                   evaluation_history=tuple(int(e) for e in spent),
                                   time_history=tuple(elapsed), extra=extra)
