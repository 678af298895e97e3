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

**Budgets** (:class:`Budget`, :func:`apply_budget`): a study compares planners at a stated
budget, the same for every planner.  ``Budget(evaluations=N)`` sets ``max_evaluations = N`` and
makes ``iterations`` large enough (N: every iteration evaluates at least once) that the budget,
not the iteration count, ends the search: the run spends exactly N evaluations unless its
algorithm ends on its own first (a walk that reached the goal, a stall rule).  Every
evaluation counts: the continuous planners' onlookers, scouts, repair and polish, an ant
colony's tours (one ant's tour evaluated is one evaluation).  ``Budget(time_s=T)`` ends the
search at the first iteration boundary after T seconds of wall time.  A schedule that runs
"over the iterations" (GWO's ``a``) follows :attr:`SwarmState.run_fraction`, the share of the
run spent by whichever limit ends it first.  Planners outside this loop may implement
``with_budget(budget)`` themselves; the others ignore budgets (:func:`apply_budget` says so).
"""

from __future__ import annotations

import math
import time
import dataclasses
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
        run_fraction: the share of the run done when the current step starts: the largest of
            iterations / iteration limit, evaluations / ``max_evaluations`` and wall time /
            the time budget (set by the loop).
    """

    max_evaluations: int | None = None
    best_solution: Any = None
    best_cost: float = math.inf
    evaluations: int = 0
    population: np.ndarray | None = None
    costs: np.ndarray | None = None
    done: bool = False
    data: dict[str, Any] = field(default_factory=dict)
    run_fraction: float = 0.0

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


@dataclass(frozen=True)
class Budget:
    """A study's budget for every planner: objective evaluations or wall time (one of them).

    Attributes:
        evaluations: objective evaluations (None: no such budget).
        time_s: wall time of the search in seconds (None: no such budget).
    """

    evaluations: int | None = None
    time_s: float | None = None

    def as_dict(self) -> dict[str, Any]:
        return {k: v for k, v in (("evaluations", self.evaluations), ("time_s", self.time_s)) if v is not None}


def apply_budget(planner: Any, budget: Budget | None) -> tuple[Any, bool]:
    """``planner`` under ``budget``, and whether it honours budgets (a planner without
    ``with_budget``, e.g. an exact one, is returned as it is, with False)."""
    if budget is None:
        return planner, False
    with_budget = getattr(planner, "with_budget", None)
    if with_budget is None:
        return planner, False
    return with_budget(budget), True


class SwarmPlanner:
    """Base class owning the loop: initialise, step, track the best, repair, stop.

    Subclasses are dataclasses whose fields are the user-settable parameters and
    must define ``iterations`` (int) and may define ``max_evaluations``
    (int or None; 0 or None means no evaluation budget).
    """

    iterations: int
    max_evaluations: int | None = None
    #: Wall-time budget of the search (set by :meth:`with_budget`; not a parameter).
    time_budget_s: float | None = None
    #: The state class this planner's hooks expect.
    state_type: ClassVar[type[SwarmState]] = SwarmState

    def with_budget(self, budget: Budget) -> "SwarmPlanner":
        """A copy of this planner that runs until ``budget`` is spent (see the module docstring)."""
        if budget.evaluations is not None:
            return dataclasses.replace(self, max_evaluations=int(budget.evaluations),
                                       iterations=max(int(budget.evaluations), 1))
        planner = dataclasses.replace(self, max_evaluations=None, iterations=2**31 - 1)
        planner.time_budget_s = float(budget.time_s)
        return planner

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

    def repair_limit(self, state: SwarmState) -> int:
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
        limit = self.iteration_limit(problem)
        for iteration in range(limit):
            elapsed_s = time.perf_counter() - t0
            if state.done or state.exhausted or (self.time_budget_s is not None and elapsed_s >= self.time_budget_s):
                break
            state.run_fraction = max(iteration / max(limit, 1),
                                     state.evaluations / state.max_evaluations if state.max_evaluations else 0.0,
                                     elapsed_s / self.time_budget_s if self.time_budget_s else 0.0)
            self.step(state, problem, rng, iteration)
            if state.best_cost < history[-1]:
                converged_at = iteration + 1
            history.append(state.best_cost)
            spent.append(state.evaluations)
            elapsed.append(time.perf_counter() - t0)
            done = iteration + 1
        repairs = 0
        while repairs < self.repair_limit(state) and not state.exhausted and self.needs_repair(state, problem):
            self.repair_step(state, problem, rng, repairs)
            repairs += 1
        try:
            waypoints, extra = self.finish(state, problem, rng)
        except NoPathFound as exc:
            # A failed run is data too: the error carries what the search spent (a study row records it).
            if state.exhausted:
                exc = BudgetExceeded(f"{exc} (the budget of {state.max_evaluations} evaluations is spent)")
            exc.evaluations, exc.iterations = state.evaluations, done
            exc.plan_time_s = time.perf_counter() - t0
            raise exc
        # The iteration (1-based) after which the best cost no longer improved.
        extra.setdefault("convergence_iteration", converged_at)
        if self.repair_limit(state):
            extra.setdefault("repair_rounds", repairs)
        return Path.from_waypoints(waypoints, time.perf_counter() - t0, iterations=done,
                                   evaluations=state.evaluations,
                                   cost_history=tuple(float(c) for c in history),
                                   evaluation_history=tuple(int(e) for e in spent),
                                   time_history=tuple(elapsed), extra=extra)
