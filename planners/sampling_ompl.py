"""OMPL's asymptotically optimal sampling planners behind swarmnav's seam: ``rrt_star``,
``informed_rrt_star``, ``bit_star`` and ``prm_star``.

The Open Motion Planning Library (Sucan, Moll and Kavraki 2012, "The Open Motion Planning
Library", IEEE Robotics & Automation Magazine 19(4)), through its Python bindings (PyPI
``ompl``, 2.x), plans; swarmnav decides what is free:

* **State space.** The robot is a disc, so its configuration space is the plane: a
  ``RealVectorStateSpace(2)`` bounded by ``Problem.bounds`` (already shrunk by the inflation).
  An SE(2) space would add the heading to OMPL's distance, and the path-length objective
  would no longer be metres.
* **Validity.** A state is valid when the point clears every inflated disc and box, a
  motion when the straight segment does: both by ``Problem.segment_clearances_m`` (the exact
  segment-disc and segment-box distances of :mod:`models.geometry`, at the problem's
  inflation, robot radius plus the scenario's clearance), never by OMPL's discretised
  motion checking.  So every returned path passes ``Problem.is_collision_free`` (:mod:`planners.ompl_checks`).
* **Objective.** ``PathLengthOptimizationObjective``: the cost is the path's length in metres,
  the ``cost_history`` every swarm planner records.
* **Budget.** ``max_evaluations`` counts collision checks (state and motion validity
  calls, what these planners spend as the swarms spend objective evaluations); once it is
  spent, further checks answer "invalid" without being made (``extra["refused_checks"]``)
  and the planner stops, so ``stats.evaluations`` never exceeds it.  ``time_s`` (0: none) is
  a wall-clock limit on top.
* **Progress.** An *iteration* here is a round of ``round_evaluations`` collision checks;
  ``cost_history`` is the best length after the set-up and after each round (``inf`` until
  the first solution), ``evaluation_history`` the checks spent by then.  OMPL's own
  iteration count (one sample each) is ``extra["ompl_iterations"]``.
* **Seeding.** Each plan draws a seed from ``rng`` and gives it to ``ompl.util.RNG.setSeed``
  before any OMPL object is built, so every sampler of the run is seeded from it.  OMPL
  (``RandomNumbers.cpp``) seeds each sampler's generator from one global seed generator, and
  ``setSeed`` reseeds that generator even after seeds were handed out (it logs an error,
  silenced here), so a plan is reproducible in any process, after any earlier plan.  Plans
  are serialised by a lock, since that generator is process-wide.  Guaranteed: with no
  ``time_s`` the same seed gives the same path, bit for bit, on one thread (``rrt_star``,
  ``informed_rrt_star`` and ``bit_star`` run their solve on the calling thread; ``prm_star``
  is driven as below).  With ``time_s`` set, where the run stops depends on the machine.
* **PRM\\*.** OMPL's ``PRM::solve`` alternates growing and expanding the roadmap on 2:1 *time*
  slices and checks for a solution on a second thread, so it is not reproducible, and that
  thread cannot call back into Python.  ``prm_star`` therefore drives OMPL's ``PRMstar``
  roadmap directly: start and goal are added as milestones, then ``growRoadmap`` (sample a
  valid state, connect it to its k-nearest, k = k_PRM log n: Karaman and Frazzoli 2011,
  "Sampling-based algorithms for optimal motion planning", IJRR 30(7), Algorithm 4 with
  Eq. (4)'s connection rule) runs round by round, and after each round the shortest
  start-goal route on the roadmap (Dijkstra on its ``PlannerData``, edge cost the segment
  length) is the best cost.  That is the algorithm of the paper; OMPL's extra expansion
  step (random bounces from weakly connected milestones) is not run.
* **Attempts.** ``attempts`` (default 1) runs the planner that many times, each from its own seed drawn
  from ``rng`` in turn, and returns the shortest path: MoveIt's ``num_planning_attempts`` ("the shortest
  solution will be reported"), for the feasible planners that stop at their first solution, whose length is
  a draw.  The attempts share the budget: each runs on the collision checks and the time the earlier ones
  left, and ``stats.evaluations`` counts them all (so it never exceeds ``max_evaluations``).  The chosen
  attempt's histories are its own, its checks offset by the attempts before it; ``extra["attempt_lengths_m"]``
  lists every attempt's length (``inf``: none found) when ``attempts`` > 1.  With 1 (the default) a plan is
  the single run above, bit for bit.  An optimizing planner spends the whole budget in its first attempt, so
  the later ones get none.
* **Console.** OMPL's log level is set to ``LOG_NONE`` once, at the first import (which
  happens on the first plan, so the CLI does not pay for it elsewhere).

A goal OMPL cannot reach within the budget is :class:`planners.errors.NoPathFound`.
"""

from __future__ import annotations

import math
import threading
import time
import dataclasses
from dataclasses import dataclass, field
from typing import Callable, ClassVar

import numpy as np

from swarmnav.models.parameters import above, check_declared, param, within
from swarmnav.planners.errors import NoPathFound, check_parameters
from swarmnav.planners.ompl_checks import CollisionChecks, motion_validator_type, ompl_modules
from swarmnav.planners.problem import Path, Problem, check_endpoints, check_supported

_OMPL_LOCK = threading.Lock()


@dataclass
class _Progress:
    """Best cost after the set-up and after each round, with the checks spent by then."""

    costs: list[float] = field(default_factory=list)
    checks: list[int] = field(default_factory=list)

    def record(self, cost: float, checks: int) -> None:
        self.costs.append(float(cost))
        self.checks.append(int(checks))


@dataclass
class OmplPlanner:
    """Shared set-up of the OMPL planners (see the module docstring).

    Attributes:
        max_evaluations: the budget in collision checks (0 or None: none, then ``time_s`` is needed).
        time_s: wall-clock limit in seconds (0 or None: none).
        round_evaluations: collision checks per recorded round of the best-cost history.
        attempts: plans made in turn on the one budget, the shortest returned (module docstring).
    """

    name: ClassVar[str]
    supports: ClassVar[frozenset[str]] = frozenset({"discs", "boxes"})
    #: The OMPL class (in ``ompl.geometric``) this planner runs.
    ompl_class: ClassVar[str]

    max_evaluations: int | None = param(5000, within(0, 100_000_000))
    time_s: float | None = param(None, within(0, 86_400))
    round_evaluations: int = param(100, within(1, 100_000_000))
    attempts: int = param(1, within(1, 100))
    # models.parameters checks these on build: collision checks are a few microseconds each, so 10^8 is minutes.

    def with_budget(self, budget) -> "OmplPlanner":
        """A copy that runs to a study's budget: ``evaluations`` as collision checks (this planner's own unit
        of work, which its rows count as evaluations), or ``time_s`` of wall-clock time with no check limit."""
        if budget.evaluations is not None:
            return dataclasses.replace(self, max_evaluations=int(budget.evaluations), time_s=None)
        return dataclasses.replace(self, max_evaluations=None, time_s=float(budget.time_s))

    def __post_init__(self) -> None:
        check_declared(self, "planner")  # every field's declared range, for a planner made directly in Python
        check_parameters(self, (
            ("max_evaluations", bool(self.max_evaluations) or bool(self.time_s),
             "must be positive unless time_s is (a sampling planner needs a budget)"),
        ))
        self.check_own_parameters()

    def check_own_parameters(self) -> None:
        """Checks of a subclass's own parameters that no declared range says (a rule between fields)."""

    def configure(self, planner) -> None:
        """Set a subclass's own parameters on the OMPL planner."""

    def plan(self, problem: Problem, rng: np.random.Generator) -> Path:
        """Plan with OMPL seeded from ``rng``.

        Raises:
            StartBlocked, GoalBlocked: an endpoint is outside the bounds or in an obstacle.
            NoPathFound: no start-goal path within the budget.
        """
        t0 = time.perf_counter()
        check_supported(self, problem)
        check_endpoints(problem)
        limit = self.max_evaluations or math.inf
        best: Path | None = None
        made, lengths = 0, []
        with _OMPL_LOCK:
            for _ in range(self.attempts):
                if made >= limit:
                    break
                seed = int(rng.integers(1, 2**31 - 1))
                path, checks = self._run(problem, seed, t0, limit - made)
                if path is not None and (best is None or path.stats.length_m < best.stats.length_m):
                    best = dataclasses.replace(path, stats=dataclasses.replace(
                        path.stats, evaluation_history=tuple(made + c for c in path.stats.evaluation_history)))
                lengths.append(path.stats.length_m if path is not None else math.inf)
                made += checks
        if best is None:
            raise NoPathFound(f"{self.name}: no path within the budget of "
                              f"{self._budget_text()} ({made} collision checks made)")
        if self.attempts == 1:
            return best
        return dataclasses.replace(best, stats=dataclasses.replace(
            best.stats, evaluations=made, plan_time_s=time.perf_counter() - t0,
            extra={**best.stats.extra, "attempt_lengths_m": lengths}))

    def _run(self, problem: Problem, seed: int, t0: float, max_checks: float) -> tuple[Path | None, int]:
        """One attempt on ``max_checks`` collision checks: its path (None: none found) and the checks it made."""
        ob, og, ou = ompl_modules()
        ou.RNG.setSeed(seed)
        space = ob.RealVectorStateSpace(2)
        bounds = ob.RealVectorBounds(2)
        b = problem.bounds
        bounds.low = [b.x_min_m, b.y_min_m]
        bounds.high = [b.x_max_m, b.y_max_m]
        space.setBounds(bounds)
        si = ob.SpaceInformation(space)
        checks = CollisionChecks(problem, max_checks, t0 + self.time_s if self.time_s else math.inf)
        si.setStateValidityChecker(checks.state_valid)
        validator = motion_validator_type()(si, checks)
        si.setMotionValidator(validator)
        si.setup()
        start, goal = si.allocState(), si.allocState()
        start[0], start[1] = problem.start.x_m, problem.start.y_m
        goal[0], goal[1] = problem.goal.x_m, problem.goal.y_m
        pdef = ob.ProblemDefinition(si)
        pdef.setStartAndGoalStates(start, goal)
        pdef.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
        planner = getattr(og, self.ompl_class)(si)
        self.configure(planner)
        planner.setProblemDefinition(pdef)
        planner.setup()
        progress = _Progress()
        try:
            waypoints, iterations = self.search(ob, planner, pdef, checks, progress)
        finally:
            validator.checks = None  # no cycle left between the validator and the run
            del planner, pdef, validator, si
        if waypoints is None:
            return None, checks.made
        waypoints[0], waypoints[-1] = problem.start.xy, problem.goal.xy
        if not problem.is_collision_free(waypoints):  # the validity checks make this unreachable
            raise NoPathFound(f"{self.name}: OMPL returned a path the exact check refuses")
        improved = [i for i in range(1, len(progress.costs)) if progress.costs[i] < progress.costs[i - 1]]
        return Path.from_waypoints(
            waypoints, time.perf_counter() - t0, iterations=len(progress.costs) - 1, evaluations=checks.made,
            cost_history=tuple(progress.costs), evaluation_history=tuple(progress.checks),
            extra={"ompl_planner": self.ompl_class, "ompl_seed": seed, "ompl_iterations": iterations,
                   "refused_checks": checks.refused,
                   "convergence_iteration": improved[-1] if improved else 0}), checks.made

    def _budget_text(self) -> str:
        parts = ([f"{self.max_evaluations} collision checks"] if self.max_evaluations else []) + (
            [f"{self.time_s:g} s"] if self.time_s else [])
        return " and ".join(parts)

    def search(self, ob, planner, pdef, checks: CollisionChecks,
               progress: _Progress) -> tuple[np.ndarray | None, int]:
        """Run the OMPL planner to the budget, recording the best cost after each round; return
        the waypoints of the best exact solution (None: none) and OMPL's iteration count."""
        raise NotImplementedError


def solve_in_rounds(ob, planner, checks: CollisionChecks, progress: _Progress, best: Callable[[], float],
                    round_evaluations: int, record_last_improvement: bool = False) -> None:
    """One ``solve`` under a termination condition that ends at the budget and records ``best()`` after each
    round of ``round_evaluations`` collision checks, then once more for the checks of the last part round
    (``record_last_improvement``: also when only the best cost moved since the last record)."""
    progress.record(math.inf, checks.made)
    next_round = [checks.made + round_evaluations]

    def stop() -> bool:
        if checks.made >= next_round[0]:
            progress.record(best(), checks.made)
            next_round[0] = checks.made + round_evaluations
        return checks.spent

    planner.solve(ob.PlannerTerminationCondition(stop))
    if checks.made > progress.checks[-1] or (record_last_improvement and best() < progress.costs[-1]):
        progress.record(best(), checks.made)


def _path_waypoints(path) -> np.ndarray:
    return np.array([(s[0], s[1]) for s in path.getStates()], dtype=float).reshape(-1, 2)


@dataclass
class _TreePlanner(OmplPlanner):
    """A planner whose ``solve`` runs on the calling thread and keeps a best cost (RRT*, BIT*):
    one ``solve`` under a termination condition that also closes each round."""

    def search(self, ob, planner, pdef, checks, progress):
        solve_in_rounds(ob, planner, checks, progress, lambda: planner.bestCost().value(), self.round_evaluations)
        if not pdef.hasExactSolution():
            return None, planner.numIterations()
        return _path_waypoints(pdef.getSolutionPath()), planner.numIterations()


@dataclass
class RRTStarPlanner(_TreePlanner):
    """``rrt_star``: OMPL's RRT* (Karaman and Frazzoli 2011, Algorithm 6), k-nearest rewiring off,
    the r-disc radius of its Eq. (5) scaled by ``rewire_factor``.

    Attributes:
        range_m: longest motion added at once (0: OMPL's default, a fifth of the space's extent).
        goal_bias: probability of sampling the goal (OMPL's default 0.05).
        rewire_factor: OMPL's rewiring-radius factor (> 1 keeps the asymptotic optimality; default 1.1).
    """

    name: ClassVar[str] = "rrt_star"
    ompl_class: ClassVar[str] = "RRTstar"

    range_m: float = param(0.0, within(0, 1e6))
    goal_bias: float = param(0.05, within(0, 1))
    rewire_factor: float = param(1.1, above(0, 1e3))

    def check_own_parameters(self) -> None:
        check_parameters(self, (("rewire_factor", self.rewire_factor >= 1.0, "must be a finite number >= 1"),))

    def configure(self, planner) -> None:
        if self.range_m:
            planner.setRange(self.range_m)
        planner.setGoalBias(self.goal_bias)
        planner.setRewireFactor(self.rewire_factor)


@dataclass
class InformedRRTStarPlanner(RRTStarPlanner):
    """``informed_rrt_star``: OMPL's Informed RRT* (Gammell, Srinivasa and Barfoot 2014, "Informed
    RRT*: optimal sampling-based path planning focused via direct sampling of an admissible
    ellipsoidal heuristic", IROS; Algorithm 1): RRT* that, once it has a solution of length c,
    samples only the prolate hyperspheroid of states that could improve it (Eq. (10))."""

    name: ClassVar[str] = "informed_rrt_star"
    ompl_class: ClassVar[str] = "InformedRRTstar"


@dataclass
class BITStarPlanner(_TreePlanner):
    """``bit_star``: OMPL's BIT* (Gammell, Barfoot and Srinivasa 2020, "Batch Informed Trees (BIT*):
    informed asymptotically optimal anytime search", IJRR 39(5); Algorithms 1-3), k-nearest
    variant (OMPL's default).

    Attributes:
        samples_per_batch: samples added per batch (OMPL's default 100).
        rewire_factor: the connection-radius factor (default 1.1).
    """

    name: ClassVar[str] = "bit_star"
    ompl_class: ClassVar[str] = "BITstar"

    samples_per_batch: int = param(100, within(1, 1_000_000))
    rewire_factor: float = param(1.1, above(0, 1e3))

    def check_own_parameters(self) -> None:
        check_parameters(self, (("rewire_factor", self.rewire_factor >= 1.0, "must be a finite number >= 1"),))

    def configure(self, planner) -> None:
        planner.setSamplesPerBatch(self.samples_per_batch)
        planner.setRewireFactor(self.rewire_factor)


@dataclass
class PRMStarPlanner(OmplPlanner):
    """``prm_star``: OMPL's PRM* roadmap (Karaman and Frazzoli 2011, Algorithm 4, k-nearest
    connections), grown round by round and queried by Dijkstra (see the module docstring for why
    OMPL's ``solve`` is not used)."""

    name: ClassVar[str] = "prm_star"
    ompl_class: ClassVar[str] = "PRMstar"

    def search(self, ob, planner, pdef, checks, progress):
        # Start and goal become milestones (the solve ends at once: its termination condition holds).
        planner.solve(ob.plannerAlwaysTerminatingCondition())
        pdef.clearSolutionPaths()
        waypoints, cost = _roadmap_route(ob, planner)
        progress.record(cost, checks.made)
        while not checks.spent:
            limit = checks.made + self.round_evaluations
            before = checks.made
            planner.growRoadmapPtc(ob.PlannerTerminationCondition(lambda: checks.made >= limit or checks.spent))
            if checks.made == before:  # nothing left to sample within the budget
                break
            route, cost = _roadmap_route(ob, planner)
            if route is not None and cost < progress.costs[-1]:
                waypoints = route
            progress.record(min(cost, progress.costs[-1]), checks.made)
        return waypoints, planner.milestoneCount()


def _roadmap_route(ob, planner) -> tuple[np.ndarray | None, float]:
    """Shortest start-goal route on a PRM roadmap (edges weighted by length) and its length."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    data = ob.PlannerData(planner.getSpaceInformation())
    planner.getPlannerData(data)
    n = data.numVertices()
    if data.numStartVertices() == 0 or data.numGoalVertices() == 0:
        return None, math.inf
    points = np.array([(s[0], s[1]) for s in (data.getVertex(i).getState() for i in range(n))], dtype=float)
    pairs = [(i, j) for i in range(n) for j in data.getEdges(i)]
    if not pairs:
        return None, math.inf
    rows, cols = np.array(pairs, dtype=np.int64).T
    lengths = np.hypot(*(points[rows] - points[cols]).T)
    # A zero-length edge would vanish from the sparse matrix: keep it as the smallest positive weight.
    graph = coo_matrix((np.maximum(lengths, np.finfo(float).tiny), (rows, cols)), shape=(n, n)).tocsr()
    source, target = data.getStartIndex(0), data.getGoalIndex(0)
    distances, predecessors = dijkstra(graph, directed=False, indices=source, return_predecessors=True)
    if not math.isfinite(distances[target]):
        return None, math.inf
    route = [target]
    while route[-1] != source:
        route.append(int(predecessors[route[-1]]))
    waypoints = points[route[::-1]]
    return waypoints, float(np.sum(np.hypot(*np.diff(waypoints, axis=0).T)))


OMPL_PLANNERS: tuple[type, ...] = (RRTStarPlanner, InformedRRTStarPlanner, BITStarPlanner, PRMStarPlanner)
