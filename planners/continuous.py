"""The shared base of the continuous swarm planners (ABC, ADL-ABC, GWO, PSO).

It fixes what the algorithms have in common and leaves each one only its
initialisation and its step (``init_swarm`` and ``step``), run by the one loop
in :class:`planners.swarm.SwarmPlanner`:

* the encoding: ``via_points`` free points between start and goal, joined by a
  not-a-knot cubic spline or a polyline (:mod:`planners.via_points`);
* the search box: each via-point coordinate within the workspace bounds;
* the cost: :class:`planners.path_cost.PathObjective`, evaluated for the whole
  population at once (:meth:`ContinuousPlanner.evaluate` also counts the
  evaluations and keeps the best);
* the exact feasibility check in :meth:`ContinuousPlanner.finish`.

Feasibility.  The optimisers see only ``samples`` points of each curve, so the
best candidate may cut into a disc between two samples.  To keep that rare the
penalty uses radii grown by ``penalty_margin_m``.  ``finish`` then samples the
spline densely (about every ``waypoint_spacing_m``), projects it onto the
workspace bounds (a spline may overshoot an arena edge by a millimetre near a
corner; the projection onto a box is non-expansive, so the path stays
continuous and gets no longer), and checks that polyline,
which is the returned path, *exactly* against the inflated discs and the bounds
(``Problem.is_collision_free``: segment-disc distances, no sampling).  If the
best candidate fails, the planner *repairs*: first by taking the cheapest
candidate of the final population that passes the same check; failing that, by a
short local search around the best candidate on a *finer* penalty (ten times the
samples, ``repair_rounds`` batches of ``population`` Gaussian steps, shrinking;
its evaluations are counted), stopping at the first candidate that passes.
``stats.extra["repaired"]`` says which ("population" or "fine_penalty").  If
nothing passes it raises :class:`planners.errors.NoPathFound`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from swarmnav.models.errors import ConfigError
from swarmnav.planners.errors import NoPathFound, check_parameters
from swarmnav.planners.path_cost import PathObjective
from swarmnav.planners.problem import Problem
from swarmnav.planners.swarm import SwarmPlanner, SwarmState
from swarmnav.planners.via_points import ENCODINGS, ViaPointCurve


@dataclass
class ContinuousPlanner(SwarmPlanner):
    """Common parameters of the via-point swarm planners.

    Attributes:
        population: candidates per iteration (food sources, wolves, particles).
        iterations: iterations of the loop (seed 004 uses 100).
        max_evaluations: optional cap on objective evaluations (0 or None: none).
        via_points: free via-points ``k`` (seeds 001 and 004 use 3).
        samples: curve samples the cost sees (seed 001's ``np``; 100).
        encoding: ``"spline"`` (not-a-knot cubic) or ``"polyline"``.
        length_weight: ``w1`` of seed 004 Eq. (6).
        smoothness_weight: ``w2`` of seed 004 Eq. (6); 0 gives seed 001's objective.
            Seed 004 gives no values for w1, w2; the default 0 makes the
            objective the path length, which the benchmark compares.
        penalty_weight: multiplier of seed 001's penalty, Eqs. (3)-(5).  The
            paper adds it with weight 1; that is too weak to keep a spline out of a
            disc (a cut of a few centimetres costs less penalty than the detour
            saves), so the default is 1000 (measured on dense-field-30 and gwo-scenario-1:
            100 leaves most dense-field optima inside a disc, 10000 traps GWO and PSO
            in infeasible basins).
        penalty_margin_m: added to the inflated radii in the penalty only, so that
            the optimum keeps a little room for the curve between samples.
        repair_rounds: batches of the fine-penalty repair (0: no such repair).
        waypoint_spacing_m: spacing of the returned waypoints along the spline; the
            polyline through them is what the exact check verifies.
    """

    population: int = 50
    iterations: int = 100
    max_evaluations: int | None = None
    via_points: int = 3
    samples: int = 100
    encoding: str = "spline"
    length_weight: float = 1.0
    smoothness_weight: float = 0.0
    penalty_weight: float = 1000.0
    penalty_margin_m: float = 0.02
    waypoint_spacing_m: float = 0.05
    repair_rounds: int = 10

    def __post_init__(self) -> None:
        checks = (
            ("population", self.population >= 4, "must be at least 4"),
            ("iterations", self.iterations >= 0, "must not be negative"),
            ("max_evaluations", self.max_evaluations is None or self.max_evaluations >= 0,
             "must not be negative"),
            ("via_points", self.via_points >= 1, "must be at least 1"),
            ("samples", self.samples >= 2, "must be at least 2"),
            ("encoding", self.encoding in ENCODINGS, f"must be one of {', '.join(ENCODINGS)}"),
            ("length_weight", self.length_weight >= 0, "must not be negative"),
            ("smoothness_weight", self.smoothness_weight >= 0, "must not be negative"),
            ("penalty_weight", self.penalty_weight > 0, "must be positive"),
            ("penalty_margin_m", self.penalty_margin_m >= 0, "must not be negative"),
            ("waypoint_spacing_m", self.waypoint_spacing_m > 0, "must be positive"),
            ("repair_rounds", self.repair_rounds >= 0, "must not be negative"),
        )
        check_parameters(self, checks)

    # ----------------------------------------------------------------- set-up
    def objective(self, problem: Problem) -> PathObjective:
        """The cost function of ``problem`` for this planner's encoding and weights."""
        curve = ViaPointCurve(self.encoding, self.via_points, problem.start.xy, problem.goal.xy,
                              self.samples)
        return PathObjective(curve=curve, centres_m=problem.disc_centres_m,
                             penalty_radii_m=problem.inflated_radii_m + self.penalty_margin_m,
                             bounds=problem.bounds, length_weight=self.length_weight,
                             smoothness_weight=self.smoothness_weight,
                             penalty_weight=self.penalty_weight)

    def search_bounds(self, problem: Problem) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper), each (2k,): x of every via-point, then y, within the workspace."""
        k = self.via_points
        b = problem.bounds
        lower = np.concatenate([np.full(k, b.x_min_m), np.full(k, b.y_min_m)])
        upper = np.concatenate([np.full(k, b.x_max_m), np.full(k, b.y_max_m)])
        return lower, upper

    def random_solutions(self, state: SwarmState, count: int, rng: np.random.Generator) -> np.ndarray:
        """``count`` uniform random decision vectors in the search box (seed 001 Eq. (6))."""
        lower, upper = state.data["lower"], state.data["upper"]
        return lower + rng.random((count, lower.size)) * (upper - lower)

    def evaluate(self, state: SwarmState, population: np.ndarray) -> np.ndarray:
        """Costs of a population; counts the evaluations and offers them to the best."""
        costs = state.data["objective"](population)
        state.evaluations += int(population.shape[0])
        state.offer(population, costs)
        return costs

    # ------------------------------------------------------- the loop's hooks
    def init_state(self, problem: Problem, rng: np.random.Generator) -> SwarmState:
        if problem.boxes:
            raise ConfigError("planner.name", f"{self.name} supports disc obstacles only, "
                              "this problem has box obstacles (a grid map)")
        lower, upper = self.search_bounds(problem)
        state = SwarmState(best_solution=None, best_cost=math.inf,
                           data={"objective": self.objective(problem), "lower": lower, "upper": upper,
                                 "rng": rng})
        self.init_swarm(state, rng)
        return state

    def init_swarm(self, state: SwarmState, rng: np.random.Generator) -> None:
        """Create and evaluate the first population; store it as ``state.data["population"]``
        and its costs as ``state.data["costs"]``."""
        raise NotImplementedError

    def finish(self, state: SwarmState, problem: Problem) -> tuple[np.ndarray, dict[str, Any]]:
        """Dense waypoints of the best candidate that passes the exact check.

        Raises:
            NoPathFound: neither the best nor any member of the final population
                is collision-free.
        """
        objective: PathObjective = state.data["objective"]
        curve = objective.curve
        candidates = [np.asarray(state.best_solution, dtype=float)]
        population = state.data.get("population")
        if population is not None:
            order = np.argsort(state.data["costs"], kind="stable")
            candidates.extend(np.asarray(population[i], dtype=float) for i in order)
        best_gap = -math.inf
        chosen, repaired = None, None
        for rank, solution in enumerate(candidates):
            waypoints = self.dense_waypoints(objective, solution)
            best_gap = max(best_gap, problem.path_clearance_m(waypoints))
            if problem.is_collision_free(waypoints):
                chosen, repaired = solution, ("population" if rank > 0 else None)
                break
        if chosen is None:
            chosen = self._repair_on_fine_penalty(state, problem)
            repaired = "fine_penalty"
        if chosen is None:
            raise NoPathFound(f"{self.name}: no candidate of the final population is collision-free "
                              f"(best clearance {best_gap:.4f} m), nor the fine-penalty repair; try "
                              f"more iterations or a larger penalty_weight")
        waypoints = self.dense_waypoints(objective, chosen)
        return waypoints, {
            "repaired": repaired,
            "via_points_m": curve.via_points(chosen).round(6).tolist(),
            "objective_cost": float(objective(chosen[None, :])[0]),
            "clearance_m": problem.path_clearance_m(waypoints),
            "encoding": self.encoding,
        }

    def _repair_on_fine_penalty(self, state: SwarmState, problem: Problem) -> np.ndarray | None:
        """Local search from the best candidate on ten times the samples; the first
        candidate whose returned polyline passes the exact check, or None."""
        objective: PathObjective = state.data["objective"]
        curve = objective.curve
        fine = dataclasses.replace(objective, curve=ViaPointCurve(
            curve.encoding, curve.via_point_count, curve.start_m, curve.goal_m, 10 * curve.samples))
        rng: np.random.Generator = state.data["rng"]
        lower, upper = state.data["lower"], state.data["upper"]
        best = np.asarray(state.best_solution, dtype=float)
        best_cost = float(fine(best[None, :])[0])
        state.evaluations += 1
        step_m = 4.0 * max(self.penalty_margin_m, 0.01)
        for _ in range(self.repair_rounds):
            trial = np.clip(best + rng.normal(0.0, step_m, (self.population, best.size)), lower, upper)
            costs = fine(trial)
            state.evaluations += trial.shape[0]
            i = int(np.argmin(costs))
            if costs[i] < best_cost:
                best, best_cost = trial[i], float(costs[i])
                if problem.is_collision_free(self.dense_waypoints(objective, best)):
                    return best
            step_m *= 0.6
        return None

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
