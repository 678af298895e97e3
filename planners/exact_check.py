"""The end of a continuous planner's run (:mod:`planners.continuous`): the exact check of the best
candidate, the population fallback, the fine-penalty repair and the polish.

The swarm optimises a sampled cost; the path it returns is checked *exactly*: ``finish`` samples the
chosen candidate's spline densely (about every ``waypoint_spacing_m``), projects it onto the workspace
bounds, and checks that polyline, the returned path, against the inflated discs and the bounds
(``Problem.is_collision_free``: segment-disc distances, no sampling).  What it does when the best
fails (the robust options ``population_fallback`` and ``repair_rounds``) and the ``polish_rounds``
afterwards are described in :mod:`planners.continuous` and :mod:`planners.run_settings`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.path_cost import PathObjective
from swarmnav.planners.polish import compass_polish
from swarmnav.planners.problem import Problem
from swarmnav.planners.run_settings import RunSettings
from swarmnav.planners.segment_gaps import polyline_gap_m
from swarmnav.planners.swarm import SwarmPlanner, SwarmState
from swarmnav.planners.via_points import ViaPointCurve

#: A fast gap below minus this rejects a candidate without the exact check (whose own
#: tolerance is 1e-6 m; the two computations differ by rounding only).
PRECHECK_SLACK_M = 1e-5


@dataclass
class ContinuousState(SwarmState):
    """:class:`planners.swarm.SwarmState` with what every continuous planner has.

    Attributes:
        objective: the cost of this run's problem.
        lower, upper: (2k,) the search box.
        chosen: the candidate that passed the exact check (None until one has).
        repaired: how ``chosen`` was found: None (the best), "population" or "fine_penalty".
        best_gap_m: the best clearance among the candidates checked.
        fine: the repair's finer objective (ten times the samples), once the repair starts.
        repair_solution, repair_cost: the repair's incumbent and its fine cost.
        repair_step_m: the repair's current step size.
        improved_at, reference_cost: the evaluation count when the best last improved by
            more than ``stall_tolerance``, and the best cost then (for ``stall_evaluations``).
        guess_fits: the fits of the guesses the first population was drawn around (the scan's
            last candidates).
    """

    settings: RunSettings = dataclasses.field(default_factory=RunSettings)
    objective: PathObjective | None = None
    lower: np.ndarray | None = None
    upper: np.ndarray | None = None
    scanned: bool = False
    chosen: np.ndarray | None = None
    repaired: str | None = None
    best_gap_m: float = -math.inf
    fine: PathObjective | None = None
    repair_solution: np.ndarray | None = None
    repair_cost: float = math.inf
    repair_step_m: float = 0.0
    improved_at: int = 0
    reference_cost: float = math.inf
    guess_fits: list[np.ndarray] = dataclasses.field(default_factory=list)


class ExactCheckStage(SwarmPlanner):
    """The loop's repair stage and ``finish`` for the continuous planners (see the module docstring).

    A subclass (:class:`planners.continuous.ContinuousPlanner`) supplies ``name``, ``population``,
    ``samples``, ``encoding``, ``waypoint_spacing_m``, ``polish_step_m`` and ``evaluate``.
    """

    name: str
    population: int
    samples: int
    encoding: str
    waypoint_spacing_m: float
    polish_step_m: float

    def evaluate(self, state: ContinuousState, population: np.ndarray,
                 objective: PathObjective | None = None, offer: bool = True) -> np.ndarray:
        raise NotImplementedError

    def repair_limit(self, state: ContinuousState) -> int:
        return state.settings.repair_rounds

    def needs_repair(self, state: ContinuousState, problem: Problem) -> bool:
        """Check the best once; with ``population_fallback``, then the final population (cheapest
        first) and the guesses' fits, for a candidate that passes the exact check; repair while
        there is none."""
        if not state.scanned:
            state.scanned = True
            candidates = [] if state.best_solution is None else [np.asarray(state.best_solution, dtype=float)]
            if state.population is not None and state.settings.population_fallback:
                order = np.argsort(state.costs, kind="stable")
                candidates.extend(np.asarray(state.population[i], dtype=float) for i in order
                                  if math.isfinite(state.costs[i]))
            if state.settings.population_fallback:
                candidates.extend(state.guess_fits)    # a swarm that moves every member may have lost them
            for rank, solution in enumerate(candidates):
                if self.passes_exact_check(problem, self.dense_waypoints(state.objective, solution), state):
                    state.chosen, state.repaired = solution, ("population" if rank > 0 else None)
                    break
        return state.chosen is None and state.best_solution is not None

    def repair_step(self, state: ContinuousState, problem: Problem, rng: np.random.Generator,
                    round_index: int) -> None:
        """One batch of the local search from the best candidate on ten times the samples;
        keeps the first candidate whose returned polyline passes the exact check."""
        if state.fine is None:
            curve = state.objective.curve
            state.fine = dataclasses.replace(state.objective, curve=ViaPointCurve(
                curve.encoding, curve.via_point_count, curve.start_m, curve.goal_m, 10 * curve.samples))
            best = np.asarray(state.best_solution, dtype=float)
            state.repair_solution = best
            state.repair_cost = float(self.evaluate(state, best[None, :], state.fine, offer=False)[0])
            state.repair_step_m = 4.0 * max(float(np.max(state.settings.margins_m)), 0.01)
        best = state.repair_solution
        trial = np.clip(best + rng.normal(0.0, state.repair_step_m, (self.population, best.size)),
                        state.lower, state.upper)
        costs = self.evaluate(state, trial, state.fine, offer=False)
        i = int(np.argmin(costs))
        if costs[i] < state.repair_cost:
            state.repair_solution, state.repair_cost = trial[i], float(costs[i])
            if self.passes_exact_check(problem, self.dense_waypoints(state.objective, trial[i]), state):
                state.chosen, state.repaired = trial[i], "fine_penalty"
        state.repair_step_m *= 0.6

    def finish(self, state: ContinuousState, problem: Problem,
               rng: np.random.Generator) -> tuple[np.ndarray, dict[str, Any]]:
        """Dense waypoints of the candidate that passed the exact check.

        Raises:
            NoPathFound: the best is not collision-free, nor (with the robust options) any
                member of the final population, nor the repair.
        """
        self.needs_repair(state, problem)          # the scan, when the loop ran no repair stage
        if state.chosen is None:
            settings = state.settings
            looked = ["the best candidate"] + (["the final population"] if settings.population_fallback else []) + (
                ["the fine-penalty repair"] if settings.repair_rounds else [])
            raise NoPathFound(f"{self.name} ({settings.mode} mode): {', '.join(looked)} cut(s) a disc "
                              f"(best clearance {state.best_gap_m:.4f} m); the penalty weight is "
                              f"{settings.penalty_weight:g}, see the robust options of planners.run_settings")
        objective = state.objective
        polished = 0
        if state.settings.polish_rounds and not state.exhausted:
            start_cost = float(objective(state.chosen[None, :])[0])
            state.chosen, _, polished = compass_polish(
                state.chosen, start_cost, lambda trial: self.evaluate(state, trial, offer=False),
                lambda x: self.passes_exact_check(problem, self.dense_waypoints(objective, x), state),
                state.lower, state.upper, self.polish_step_m, state.settings.polish_rounds)
        waypoints = self.dense_waypoints(objective, state.chosen)
        return waypoints, {
            "repaired": state.repaired,
            "via_points_m": objective.curve.via_points(state.chosen).round(6).tolist(),
            "objective_cost": float(objective(state.chosen[None, :])[0]),
            "clearance_m": problem.path_clearance_m(waypoints),
            "encoding": self.encoding,
            "polish_rounds": polished,
            "stopped_on_stall": bool(state.done),
        }

    @staticmethod
    def passes_exact_check(problem: Problem, waypoints: np.ndarray, state: ContinuousState) -> bool:
        """``problem.is_collision_free(waypoints)``, the exact check, run only when the fast
        gap (:func:`planners.segment_gaps.polyline_gap_m`, the same distances without
        temporaries) does not already show a cut deeper than :data:`PRECHECK_SLACK_M`;
        keeps the best gap seen in ``state.best_gap_m`` (for the error message)."""
        gap_m = polyline_gap_m(waypoints, problem.disc_centres_m, problem.inflated_radii_m)
        state.best_gap_m = max(state.best_gap_m, gap_m)
        return gap_m >= -PRECHECK_SLACK_M and bool(problem.is_collision_free(waypoints))

    def dense_waypoints(self, objective: PathObjective, solution: np.ndarray) -> np.ndarray:
        """The returned polyline: the spline every ``waypoint_spacing_m``, projected onto the
        bounds (or, for the polyline encoding, its knots)."""
        curve = objective.curve
        if curve.encoding == "polyline":
            return curve.knots(solution)
        xs, ys = curve.sample(solution[None, :])
        rough_m = float(np.sum(np.hypot(np.diff(xs[0]), np.diff(ys[0]))))
        count = int(min(max(math.ceil(rough_m / self.waypoint_spacing_m) + 1, self.samples), 50_000))
        waypoints = curve.dense_waypoints(solution, count)
        b = objective.bounds
        return np.column_stack([np.clip(waypoints[:, 0], b.x_min_m, b.x_max_m),
                                np.clip(waypoints[:, 1], b.y_min_m, b.y_max_m)])
