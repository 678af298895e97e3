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
samples, ``repair_rounds`` batches of ``population`` Gaussian steps, shrinking),
stopping at the first candidate that passes.  The repair runs as the loop's
repair stage (:mod:`planners.swarm`), so its evaluations count against the same
``max_evaluations`` budget as the search's.  ``stats.extra["repaired"]`` says
which ("population" or "fine_penalty").  If nothing passes it raises
:class:`planners.errors.NoPathFound` (:class:`planners.errors.BudgetExceeded`
when the budget ran out).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from swarmnav.models.errors import ConfigError
from swarmnav.planners.errors import NoPathFound, check_parameters
from swarmnav.planners.path_cost import PathObjective
from swarmnav.planners.problem import Problem, check_supported
from swarmnav.planners.swarm import SwarmPlanner, SwarmState
from swarmnav.planners.via_points import ENCODINGS, ViaPointCurve


#: Most curve points one evaluation batch may sample (population x samples): the
#: cost's temporaries grow with it.
MAX_POPULATION_SAMPLES = 1_000_000

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
    """

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


@dataclass
class ContinuousPlanner(SwarmPlanner):
    """Common parameters of the via-point swarm planners.

    Attributes:
        population: candidates per iteration (food sources, wolves, particles); population
            x samples may be at most :data:`MAX_POPULATION_SAMPLES` (1,000,000).
        iterations: iterations of the loop (Abdulla & Hadi 2025 uses 100).
        max_evaluations: optional cap on objective evaluations (0 or None: none).
        via_points: free via-points ``k`` (Kamil et al. 2020 and Abdulla & Hadi (2025) use 3).
        samples: curve samples the cost sees (Kamil et al. 2020's ``np``; 100).
        encoding: ``"spline"`` (not-a-knot cubic) or ``"polyline"``.
        length_weight: ``w1`` of Abdulla & Hadi (2025) Eq. (6).
        smoothness_weight: ``w2`` of Abdulla & Hadi (2025) Eq. (6); 0 gives Kamil et al. 2020's objective.
            Abdulla & Hadi (2025) gives no values for w1, w2; the default 0 makes the
            objective the path length, which the benchmark compares.
        penalty_weight: multiplier of Kamil et al. 2020's penalty, Eqs. (3)-(5).  The
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

    supports: ClassVar[frozenset[str]] = frozenset({"discs"})

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
        points = self.population * self.samples
        if points > MAX_POPULATION_SAMPLES:
            raise ConfigError("planner.params.population",
                              f"population x samples = {self.population:,} x {self.samples:,} needs {points:,} "
                              f"curve points an evaluation, more than the maximum {MAX_POPULATION_SAMPLES:,}")

    # ----------------------------------------------------------------- set-up
    state_type = ContinuousState

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

    def random_solutions(self, state: ContinuousState, count: int, rng: np.random.Generator) -> np.ndarray:
        """``count`` uniform random decision vectors in the search box (Kamil et al. 2020 Eq. (6))."""
        return state.lower + rng.random((count, state.lower.size)) * (state.upper - state.lower)

    def evaluate(self, state: ContinuousState, population: np.ndarray,
                 objective: PathObjective | None = None, offer: bool = True) -> np.ndarray:
        """Costs of a population; counts the evaluations and offers them to the best.

        Only as many candidates as the budget has left are evaluated (the first
        ones); the others cost ``inf`` and count for nothing.

        Args:
            objective: the cost to use (default: the run's).
            offer: offer the costs to ``state``'s best (off for the repair's finer cost).
        """
        objective = objective or state.objective
        count = population.shape[0]
        left = state.evaluations_left
        if left >= count:
            costs = objective(population)
        else:
            left = int(left)
            costs = np.full(count, math.inf)
            if left:
                costs[:left] = objective(population[:left])
            count = left
        state.evaluations += count
        if offer:
            state.offer(population, costs)
        return costs

    # ------------------------------------------------------- the loop's hooks
    def init_state(self, state: ContinuousState, problem: Problem, rng: np.random.Generator) -> None:
        check_supported(self, problem)
        state.objective = self.objective(problem)
        state.lower, state.upper = self.search_bounds(problem)
        self.init_swarm(state, rng)

    def init_swarm(self, state: ContinuousState, rng: np.random.Generator) -> None:
        """Create and evaluate the first population (``state.population``, ``state.costs``)."""
        raise NotImplementedError

    def repair_limit(self) -> int:
        return self.repair_rounds

    def needs_repair(self, state: ContinuousState, problem: Problem) -> bool:
        """Scan the best and then the final population (cheapest first) once for a
        candidate that passes the exact check; repair while there is none."""
        if not state.scanned:
            state.scanned = True
            candidates = [] if state.best_solution is None else [np.asarray(state.best_solution, dtype=float)]
            if state.population is not None:
                order = np.argsort(state.costs, kind="stable")
                candidates.extend(np.asarray(state.population[i], dtype=float) for i in order
                                  if math.isfinite(state.costs[i]))
            for rank, solution in enumerate(candidates):
                waypoints = self.dense_waypoints(state.objective, solution)
                state.best_gap_m = max(state.best_gap_m, problem.path_clearance_m(waypoints))
                if problem.is_collision_free(waypoints):
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
            state.repair_step_m = 4.0 * max(self.penalty_margin_m, 0.01)
        best = state.repair_solution
        trial = np.clip(best + rng.normal(0.0, state.repair_step_m, (self.population, best.size)),
                        state.lower, state.upper)
        costs = self.evaluate(state, trial, state.fine, offer=False)
        i = int(np.argmin(costs))
        if costs[i] < state.repair_cost:
            state.repair_solution, state.repair_cost = trial[i], float(costs[i])
            if problem.is_collision_free(self.dense_waypoints(state.objective, trial[i])):
                state.chosen, state.repaired = trial[i], "fine_penalty"
        state.repair_step_m *= 0.6

    def finish(self, state: ContinuousState, problem: Problem,
               rng: np.random.Generator) -> tuple[np.ndarray, dict[str, Any]]:
        """Dense waypoints of the candidate that passed the exact check.

        Raises:
            NoPathFound: neither the best, nor any member of the final population,
                nor the repair is collision-free.
        """
        self.needs_repair(state, problem)          # the scan, when the loop ran no repair stage
        if state.chosen is None:
            raise NoPathFound(f"{self.name}: no candidate of the final population is collision-free "
                              f"(best clearance {state.best_gap_m:.4f} m), nor the fine-penalty repair; try "
                              f"more iterations or a larger penalty_weight")
        objective = state.objective
        waypoints = self.dense_waypoints(objective, state.chosen)
        return waypoints, {
            "repaired": state.repaired,
            "via_points_m": objective.curve.via_points(state.chosen).round(6).tolist(),
            "objective_cost": float(objective(state.chosen[None, :])[0]),
            "clearance_m": problem.path_clearance_m(waypoints),
            "encoding": self.encoding,
        }

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
