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

Modes.  ``mode = "paper"`` (the default) runs the algorithm as its paper writes it, on any
scene; ``mode = "robust"`` is swarmnav's hybrid that starts from the exact tangent-graph
route.  The table of what each mode sets, and the options that set each mechanism on its
own, is in :mod:`planners.run_settings`.  No behaviour depends on which file a problem came
from.  The resolved options of a run are in ``stats.extra["settings"]`` and its mode in
``stats.extra["mode"]``.

Feasibility.  ``finish`` samples the best candidate's spline densely (about every
``waypoint_spacing_m``), projects it onto the workspace bounds, and checks that polyline,
which is the returned path, *exactly* against the inflated discs and the bounds
(``Problem.is_collision_free``: segment-disc distances, no sampling); that stage, with the
population fallback, the repair and the polish, is :class:`planners.exact_check.ExactCheckStage`.

Deviations from both papers (Kamil et al. 2020 Sect. 6; Abdulla & Hadi 2025 Sect. 6), in
every mode:

* the papers report their best candidate as the path; we check it exactly and a best that
  cuts a disc is :class:`planners.errors.NoPathFound` (paper mode looks no further; the
  robust mode's ``population_fallback`` and ``repair_rounds`` look for another);
* the returned polyline is projected onto the arena (a spline may overshoot an edge near a
  corner; the papers' arenas have no walls and they do not say what happens there; the
  projection onto a box is non-expansive, so the path stays continuous and gets no longer);
* a via-point coordinate that a move takes out of the search box is clipped back to it
  (neither paper says; Karaboga's ABC and Mirjalili's GWO reference codes clip).

Robust options (:mod:`planners.run_settings` has the table):

* ``guess``: the geometric guess the other options start from: ``"tangent"`` (robust default
  up to 100 discs),
  the shortest route of the tangent graph around the inflated discs grown by
  ``guess_margin_m`` (default: each disc's penalty margin; :mod:`planners.tangent_guess`), or
  ``"grid"``, a line-of-sight-shortcut A* path on the problem's grid (``guess_cell_m``), or
  ``"none"`` (the paper mode's);
* ``via_points``: chosen from the scene (:func:`planners.path_guess.via_points_for_turns`:
  two per turn of the tangent route plus seven; for the grid guess
  :func:`planners.path_guess.via_points_for_guess`, one per bend plus two) and *grown*
  (doubled, up to ``via_point_growth`` times, the search rerun on what is left of the
  budget) when no candidate passes the exact check;
* ``guess_fraction``: that share of the first population is placed on the least-squares
  fit of the guess, perturbed by at most ``guess_spread_m`` (:mod:`planners.path_guess`), the
  rest uniformly at random as in the paper (later random draws, e.g. ABC's scouts, stay the
  paper's);
* ``fit_push_rounds``: rounds of :func:`planners.path_guess.pushed_fit_via_points`, which
  moves the fit's curve out of the penalty's discs (a plain least-squares fit cuts the
  corners of a route that hugs them; 0: the plain fit);
* ``penalty_margin_m`` and ``penalty_weight``: the optimisers see only ``samples`` points of
  each curve, so the best candidate may cut into a disc between two samples; the robust
  penalty uses radii grown by the margin, with weight 1000 (Kamil et al. 2020's weight 1 is
  too weak to keep a spline out of a disc: a cut of a few centimetres costs less penalty
  than the detour saves; measured on dense-field-30 and gwo-scenario-1, 100 leaves most
  dense-field optima inside a disc, 10000 traps GWO and PSO in infeasible basins);
* ``population_fallback``: when the best fails the exact check, the cheapest member of the
  final population (then the guesses' fits) that passes it;
* ``repair_rounds``: failing that, a short local search around the best candidate on a
  *finer* penalty (ten times the samples, ``repair_rounds`` batches of ``population``
  Gaussian steps, shrinking), stopping at the first candidate that passes.  It runs as the
  loop's repair stage (:mod:`planners.swarm`), so its evaluations count against the same
  budget.  ``stats.extra["repaired"]`` says which ("population" or "fine_penalty");
* ``polish_rounds``: a compass search from the chosen candidate (:mod:`planners.polish`);
  its result is kept only if the returned path passes the exact check; its evaluations
  count against the budget;
* ``gap_margins``: the penalty's margin shrinks, disc by disc, to less than half of every
  narrower gap between two footprints (and less than a wall gap), so that the cost does not
  close a gap the robot fits through (:func:`planners.path_guess.gap_margins_m`; our choice);
* ``stall_evaluations``: the search stops early once that many evaluations in a row have
  not lowered the best cost by more than ``stall_tolerance`` (relative).  Started from a
  guided population, the swarm mostly refines the guess's fit, and on the random fields
  the best stops improving within a few iterations (the default stops only a guided
  search: from a uniform random start a swarm may stall for a while and then find a
  feasible basin).  A stop on lack of improvement is the
  "improvement-based" criterion of Zielinski & Laur (2008, "Stopping criteria for
  differential evolution in constrained single-objective optimization", in Chakraborty
  (ed.), Advances in Differential Evolution, Springer, Sect. 3.1); counting evaluations
  rather than iterations makes it the same for the algorithms that evaluate once an
  iteration (GWO, PSO) and those that evaluate two or three times (ABC, ADL-ABC).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.models.parameters import above, param, within
from swarmnav.models.errors import ConfigError
from swarmnav.planners.errors import BudgetExceeded, NoPathFound, check_parameters
from swarmnav.planners.exact_check import ContinuousState, ExactCheckStage
from swarmnav.planners.path_cost import PathObjective
from swarmnav.planners.path_guess import MAX_AUTO_VIA_POINTS, fit_via_points, population_around, pushed_fit_via_points
from swarmnav.planners.problem import Path, Problem, check_endpoints, check_supported
from swarmnav.planners.run_settings import (GUESSES, MODES, PAPER_VIA_POINTS, RunSettings, mode_value,
                                            resolve_settings)
from swarmnav.planners.via_points import ENCODINGS, ViaPointCurve

#: Most curve points one evaluation batch may sample (population x samples): the
#: cost's temporaries grow with it.
MAX_POPULATION_SAMPLES = 1_000_000

@dataclass
class ContinuousPlanner(ExactCheckStage):
    """Common parameters of the via-point swarm planners.

    Options left at ``None`` take their mode's value (:mod:`planners.run_settings`).

    Attributes:
        population: candidates per iteration (food sources, wolves, particles); population
            x samples may be at most :data:`MAX_POPULATION_SAMPLES` (1,000,000).
        iterations: iterations of the loop (Abdulla & Hadi 2025 uses 100).
        max_evaluations: optional cap on objective evaluations (0 or None: none).
        via_points: free via-points ``k`` (``None``: the papers' 3 in paper mode, chosen from
            the guess in robust mode).
        samples: curve samples the cost sees (Kamil et al. 2020's ``np``; 100).
        encoding: ``"spline"`` (not-a-knot cubic) or ``"polyline"``.
        length_weight: ``w1`` of Abdulla & Hadi (2025) Eq. (6).
        smoothness_weight: ``w2`` of Abdulla & Hadi (2025) Eq. (6); 0 gives Kamil et al. 2020's objective.
            Abdulla & Hadi (2025) gives no values for w1, w2; the default 0 makes the
            objective the path length, which the benchmark compares.
        penalty_weight: multiplier of Kamil et al. 2020's penalty, Eqs. (3)-(5) (paper: 1).
        penalty_margin_m: added to the inflated radii in the penalty only (paper: 0).
        bounds_penalty: penalise curve samples outside the arena (in neither paper).
        population_fallback: scan the final population when the best cuts a disc.
        repair_rounds: batches of the fine-penalty repair (0: no such repair).
        waypoint_spacing_m: spacing of the returned waypoints along the spline; the
            polyline through them is what the exact check verifies.
        mode: "paper" (default) or "robust" (see :mod:`planners.run_settings`).
        guess_fraction: share of the first population drawn around the geometric guess.
        guess_spread_m: largest standard deviation of the perturbation around the guess's fit.
        guess_cell_m: cell of the A* guess's grid (``None``: the problem's).
        polish_rounds: compass-search rounds on the result.
        polish_step_m: the compass search's first step.
        via_point_growth: doublings of ``k`` when nothing passes.
        guess: ``"tangent"``, ``"grid"`` or ``"none"``: the geometric guess of the guided members and
            of ``k`` (``None``: "none" in paper mode; in robust mode "tangent" up to
            :data:`planners.path_guess.MAX_TANGENT_DISCS` discs, "grid" above).
        guess_margin_m: how much the tangent guess grows the inflated discs (``None``: each
            disc's penalty margin, so that the guess clears the discs the penalty sees).
        fit_push_rounds: rounds that push the guess's fit out of the discs (it stops early
            once the fit is clear).
        stall_evaluations: end the search once this many evaluations in a row have not
            improved the best (``None``: never in paper mode; in robust mode 10 x
            ``population`` when the first population is guided, never otherwise; 0: never).
        stall_tolerance: the relative drop of the best cost that counts as an improvement.
        gap_margins: whether each disc's penalty margin shrinks to keep narrow gaps open
            (:func:`planners.path_guess.gap_margins_m`).  The tangent guess then grows each
            disc by its own margin (unless ``guess_margin_m`` is set).
    """

    supports: ClassVar[frozenset[str]] = frozenset({"discs"})

    # population x samples: at most MAX_POPULATION_SAMPLES, checked with both known (__post_init__)
    population: int = param(50, within(4, 1e9))
    iterations: int = param(100, within(0, 1_000_000))
    max_evaluations: int | None = param(None, within(0, 1e9))
    via_points: int | None = param(None, within(1, 1000))
    samples: int = param(100, within(2, 1e9))
    encoding: str = "spline"
    length_weight: float = param(1.0, within(0, 1e6))
    smoothness_weight: float = param(0.0, within(0, 1e6))
    penalty_weight: float | None = param(None, above(0, 1e12))
    penalty_margin_m: float | None = param(None, within(0, 100))
    bounds_penalty: bool | None = None
    population_fallback: bool | None = None
    waypoint_spacing_m: float = param(0.05, within(0.001, 100))
    repair_rounds: int | None = param(None, within(0, 100_000))
    mode: str = "paper"
    guess_fraction: float | None = param(None, within(0, 1))
    guess_spread_m: float = param(0.2, within(0, 100))
    guess_cell_m: float | None = param(None, within(0.01, 100))
    polish_rounds: int | None = param(None, within(0, 100_000))
    polish_step_m: float = param(0.05, above(0, 100))
    via_point_growth: int | None = param(None, within(0, 10))
    guess: str | None = None
    guess_margin_m: float | None = param(None, within(0, 100))
    fit_push_rounds: int | None = param(None, within(0, 100_000))
    stall_evaluations: int | None = param(None, within(0, 1e9))
    stall_tolerance: float = param(1e-4, within(0, 1))
    gap_margins: bool | None = None

    def __post_init__(self) -> None:
        optional = lambda value, ok: value is None or ok(value)   # noqa: E731
        checks = (
            ("population", self.population >= 4, "must be at least 4"),
            ("iterations", self.iterations >= 0, "must not be negative"),
            ("max_evaluations", self.max_evaluations is None or self.max_evaluations >= 0,
             "must not be negative"),
            ("via_points", self.via_points is None or self.via_points >= 1, "must be at least 1"),
            ("samples", self.samples >= 2, "must be at least 2"),
            ("encoding", self.encoding in ENCODINGS, f"must be one of {', '.join(ENCODINGS)}"),
            ("length_weight", self.length_weight >= 0, "must not be negative"),
            ("smoothness_weight", self.smoothness_weight >= 0, "must not be negative"),
            ("penalty_weight", optional(self.penalty_weight, lambda v: v > 0), "must be positive"),
            ("penalty_margin_m", optional(self.penalty_margin_m, lambda v: v >= 0), "must not be negative"),
            ("waypoint_spacing_m", self.waypoint_spacing_m > 0, "must be positive"),
            ("repair_rounds", optional(self.repair_rounds, lambda v: v >= 0), "must not be negative"),
            ("mode", self.mode in MODES, f"must be one of {', '.join(MODES)}"),
            ("guess_fraction", optional(self.guess_fraction, lambda v: 0.0 <= v <= 1.0), "must be between 0 and 1"),
            ("guess_spread_m", self.guess_spread_m >= 0, "must not be negative"),
            ("guess_cell_m", self.guess_cell_m is None or self.guess_cell_m > 0, "must be positive"),
            ("polish_rounds", self.polish_rounds is None or self.polish_rounds >= 0, "must not be negative"),
            ("polish_step_m", self.polish_step_m > 0, "must be positive"),
            ("via_point_growth", self.via_point_growth is None or self.via_point_growth >= 0,
             "must not be negative"),
            ("guess", self.guess is None or self.guess in GUESSES, f"must be one of {', '.join(GUESSES)}"),
            ("guess_margin_m", self.guess_margin_m is None or self.guess_margin_m >= 0, "must not be negative"),
            ("fit_push_rounds", self.fit_push_rounds is None or self.fit_push_rounds >= 0, "must not be negative"),
            ("stall_evaluations", self.stall_evaluations is None or self.stall_evaluations >= 0,
             "must not be negative"),
            ("stall_tolerance", self.stall_tolerance >= 0, "must not be negative"),
        )
        check_parameters(self, checks)
        points = self.population * self.samples
        if points > MAX_POPULATION_SAMPLES:
            raise ConfigError("planner.params.population",
                              f"population x samples = {self.population:,} x {self.samples:,} needs {points:,} "
                              f"curve points an evaluation, more than the maximum {MAX_POPULATION_SAMPLES:,}")

    # ----------------------------------------------------------------- set-up
    state_type = ContinuousState

    def settings_for(self, problem: Problem) -> RunSettings:
        """Resolve ``mode`` and the options left at ``None`` for ``problem``
        (:func:`planners.run_settings.resolve_settings`)."""
        return resolve_settings(self, problem)

    def plan(self, problem: Problem, rng: np.random.Generator) -> Path:
        """Resolve the mode, then run the search; with ``via_point_growth``, rerun it with twice
        the via-points (on what is left of the budget) while nothing passes the exact check."""
        t0 = time.perf_counter()
        check_endpoints(problem)
        check_supported(self, problem)
        settings = self.settings_for(problem)
        spent = 0
        for attempt in range(settings.growth + 1):
            budget = None if not self.max_evaluations else self.max_evaluations - spent
            state = self.state_type(max_evaluations=budget, settings=settings)
            search_started_s = time.perf_counter() - t0
            try:
                path = self.run_search(problem, rng, state)
                break
            except BudgetExceeded as exc:
                exc.evaluations, exc.plan_time_s = spent + state.evaluations, time.perf_counter() - t0
                raise
            except NoPathFound as exc:
                spent += state.evaluations
                if attempt == settings.growth or settings.via_points >= MAX_AUTO_VIA_POINTS * 2:
                    exc.evaluations, exc.plan_time_s = spent, time.perf_counter() - t0
                    raise
                settings = dataclasses.replace(settings, via_points=2 * settings.via_points)
        extra = dict(path.stats.extra, mode=settings.mode, via_point_count=settings.via_points, guess=settings.guess,
                     via_point_growths=attempt, settings=settings.summary(), guess_lengths_m=[
                         float(np.sum(np.hypot(*np.diff(g, axis=0).T))) for g in settings.guesses])
        return Path.from_waypoints(path.waypoints, time.perf_counter() - t0, iterations=path.stats.iterations,
                                   evaluations=spent + path.stats.evaluations,
                                   cost_history=path.stats.cost_history,
                                   # The last search's histories (a failed search raised, and its best costs
                                   # had fewer via-points); its evaluation counts start after the failed ones'.
                                   evaluation_history=tuple(spent + e for e in path.stats.evaluation_history),
                                   time_history=tuple(search_started_s + t for t in path.stats.time_history),
                                   extra=extra)

    def objective(self, problem: Problem, via_points: int | None = None,
                  margins_m: np.ndarray | float | None = None, settings: RunSettings | None = None) -> PathObjective:
        """The cost function of ``problem`` for this planner's encoding and weights, with
        ``via_points`` free via-points (default: the parameter, else the papers' 3), the
        penalty margins ``margins_m`` (one per disc, or one for all) and the penalty weight and
        bounds penalty of ``settings`` (default: this planner's mode's)."""
        k = via_points or self.via_points or PAPER_VIA_POINTS
        curve = ViaPointCurve(self.encoding, k, problem.start.xy, problem.goal.xy,
                              self.samples)
        if margins_m is None:
            margins_m = settings.margins_m if settings is not None else mode_value(self, "penalty_margin_m")
        weight = settings.penalty_weight if settings is not None else mode_value(self, "penalty_weight")
        bounds = settings.bounds_penalty if settings is not None else mode_value(self, "bounds_penalty")
        return PathObjective(curve=curve, centres_m=problem.disc_centres_m,
                             penalty_radii_m=problem.inflated_radii_m + margins_m,
                             bounds=problem.bounds, length_weight=self.length_weight,
                             smoothness_weight=self.smoothness_weight,
                             penalty_weight=weight, bounds_penalty=bounds)

    def search_bounds(self, problem: Problem, via_points: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper), each (2k,): x of every via-point, then y, within the workspace."""
        k = via_points or self.via_points or PAPER_VIA_POINTS
        b = problem.bounds
        lower = np.concatenate([np.full(k, b.x_min_m), np.full(k, b.y_min_m)])
        upper = np.concatenate([np.full(k, b.x_max_m), np.full(k, b.y_max_m)])
        return lower, upper

    def random_solutions(self, state: ContinuousState, count: int, rng: np.random.Generator) -> np.ndarray:
        """``count`` uniform random decision vectors in the search box (Kamil et al. 2020 Eq. (6))."""
        return state.lower + rng.random((count, state.lower.size)) * (state.upper - state.lower)

    def initial_solutions(self, state: ContinuousState, count: int, rng: np.random.Generator) -> np.ndarray:
        """The first population: :meth:`random_solutions` (the papers'), except that with a
        ``guess_fraction`` and guesses that share of it is drawn around the guesses' fits (first,
        split evenly between them)."""
        settings = state.settings
        guided = int(round(settings.guess_fraction * count)) if settings.guesses else 0
        if guided == 0:
            return self.random_solutions(state, count, rng)
        shares = np.diff(np.linspace(0, guided, len(settings.guesses) + 1).round().astype(int))
        objective = state.objective
        state.guess_fits = [np.clip(pushed_fit_via_points(objective.curve, guess, objective.centres_m,
                                                         objective.penalty_radii_m, settings.push_rounds)
                                   if settings.push_rounds else fit_via_points(objective.curve, guess),
                                   state.lower, state.upper)
                           for guess, share in zip(settings.guesses, shares) if share]
        around = [population_around(fit, int(share), self.guess_spread_m, state.lower, state.upper, rng)
                  for fit, share in zip(state.guess_fits, [share for share in shares if share])]
        return np.vstack(around + [self.random_solutions(state, count - guided, rng)])

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
            self.note_stall(state)
        return costs

    def note_stall(self, state: ContinuousState) -> None:
        """Track the last improvement of the best by more than ``stall_tolerance`` and end
        the search (``state.done``) once ``stall_evaluations`` have passed without one."""
        improved = state.best_cost < state.reference_cost * (1.0 - self.stall_tolerance)
        if improved or not math.isfinite(state.reference_cost):
            state.reference_cost, state.improved_at = state.best_cost, state.evaluations
        limit = state.settings.stall_evaluations
        if limit and state.evaluations - state.improved_at >= limit:
            state.done = True

    # ------------------------------------------------------- the loop's hooks
    def init_state(self, state: ContinuousState, problem: Problem, rng: np.random.Generator) -> None:
        check_supported(self, problem)
        k = state.settings.via_points
        state.objective = self.objective(problem, k, settings=state.settings)
        state.lower, state.upper = self.search_bounds(problem, k)
        self.init_swarm(state, rng)

    def init_swarm(self, state: ContinuousState, rng: np.random.Generator) -> None:
        """Create and evaluate the first population (``state.population``, ``state.costs``)."""
        raise NotImplementedError
