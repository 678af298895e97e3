"""OMPL's other geometric planners behind swarmnav's seam, one registered name each: ``rrt``, ``rrt_connect``,
``kpiece1``, ``bkpiece1``, ``lbkpiece1``, ``prm``, ``fmt_star``, ``bfmt_star`` and ``aorrtc`` (nine).

Every one runs exactly as the four of :mod:`planners.sampling_ompl` do (that module's docstring): the plane
as a bounded ``RealVectorStateSpace(2)``, swarmnav's exact segment checks as OMPL's state and motion
validity (:mod:`planners.ompl_checks`), the path-length objective, the budget in collision checks
(``max_evaluations``, refused past it, so ``stats.evaluations`` never exceeds it; ``time_s`` on top), the
best length recorded every ``round_evaluations`` checks, the seed drawn from ``rng`` and given to OMPL
before anything is built, and the exact check of the returned path.  So in a study or ``bench planners
--sampling`` they compete at equal budgets with the rest.

What each does is OMPL's, as its class documents it; what differs between them here:

* **Feasible planners** (RRT, RRT-Connect, the KPIECE family) stop at their first exact solution, as OMPL
  runs them: they spend only the checks they need, and their cost history is ``inf`` then that length.
  Their paths are OMPL's raw paths: no simplification (``PathSimplifier``) is run, so lengths compare with
  the optimizing planners' as the planners themselves made them.
* **Optimizing planners** (AORRTC, FMT*, BFMT*) keep improving until the budget is spent (FMT* and
  BFMT* until their ``num_samples`` batch is searched).
* **PRM** is driven as ``prm_star`` is (``sampling_ompl``: OMPL's ``PRM::solve`` grows the roadmap on time
  slices and checks for a solution on a second thread), with PRM's own fixed ``max_nearest_neighbors``
  connections instead of PRM*'s k = k_PRM log n.

The bindings of PyPI's ``ompl`` 2.0.1 expose fourteen geometric planners: these nine, the four of
``sampling_ompl`` and SORRT* (Gammell, Barfoot and Srinivasa 2018), which is not offered: its ordered batch
sampling loops in C++ until it has drawn valid states, without asking the termination condition, so once the
budget is spent (every check refused) it never returns (measured: ``dyn-crossing-1`` at 1000 checks ran past
60 s), and it failed at once on the ``adl-abc-path-*`` scenarios.  LazyPRM*, EST, SBL, STRIDE and OMPL's other
C++ planners are not bound there.  KPIECE1's family projects the plane onto itself (OMPL's default projection
of a two-dimensional real vector space).

References: RRT, LaValle (1998), TR 98-11; RRT-Connect, Kuffner and LaValle (2000), ICRA; KPIECE, Sucan and
Kavraki (2009), WAFR; PRM, Kavraki, Svestka, Latombe and Overmars (1996), IEEE T-RA 12(4); FMT*, Janson,
Schmerling, Clark and Pavone (2015), IJRR 34(7); BFMT*, Starek, Gomez, Schmerling, Janson, Moreno and Pavone
(2015), IROS; AORRTC, Wilson, Zhao,
Driess and Kavraki (2025), arXiv:2505.10542.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from swarmnav.models.parameters import Range, above, param, within
from swarmnav.planners.sampling_ompl import OmplPlanner, PRMStarPlanner, _path_waypoints, solve_in_rounds

MIN_BORDER_FRACTION = 1e-3  # KPIECE's share of border expansions: OMPL throws below machine epsilon

RANGE_M: Range = within(0, 1e6)


@dataclass
class _FirstSolutionPlanner(OmplPlanner):
    """A planner whose ``solve`` runs on the calling thread: one ``solve`` under a termination condition
    that also closes each round; the best cost is the length of the solution the problem holds."""

    def search(self, ob, planner, pdef, checks, progress):
        # The callbacks reach the planner through this list, emptied after the solve: AORRTC keeps its
        # termination condition, and a closure holding the planner would be a cycle through C++ that
        # Python's collector cannot see (nanobind reports the leaked instances at exit).
        held = [planner, pdef]

        def best() -> float:  # the planner's own best cost where it keeps one (AORRTC)
            own, problem = held
            if hasattr(own, "bestCost"):
                return float(own.bestCost().value())
            return problem.getSolutionPath().length() if problem.hasExactSolution() else math.inf

        solve_in_rounds(ob, planner, checks, progress, best, self.round_evaluations, record_last_improvement=True)
        held.clear()
        if not pdef.hasExactSolution():
            return None, len(progress.costs) - 1
        return _path_waypoints(pdef.getSolutionPath()), len(progress.costs) - 1


@dataclass
class _RangedPlanner(_FirstSolutionPlanner):
    """A first-solution planner with OMPL's ``range`` (the longest motion added at once; 0: OMPL's default)."""

    range_m: float = param(0.0, RANGE_M)

    def configure(self, planner) -> None:
        if self.range_m:
            planner.setRange(self.range_m)


@dataclass
class RRTPlanner(_RangedPlanner):
    """``rrt``: OMPL's RRT (LaValle 1998), stops at its first solution.

    Attributes:
        range_m: longest motion added at once (0: OMPL's default, a fifth of the space's extent).
        goal_bias: probability of sampling the goal (OMPL's default 0.05).
    """

    name: ClassVar[str] = "rrt"
    ompl_class: ClassVar[str] = "RRT"
    goal_bias: float = param(0.05, within(0, 1))

    def configure(self, planner) -> None:
        super().configure(planner)
        planner.setGoalBias(self.goal_bias)


@dataclass
class RRTConnectPlanner(_RangedPlanner):
    """``rrt_connect``: OMPL's RRT-Connect (Kuffner and LaValle 2000), two trees, stops at its first solution.

    Attributes:
        range_m: longest motion added at once (0: OMPL's default).
    """

    name: ClassVar[str] = "rrt_connect"
    ompl_class: ClassVar[str] = "RRTConnect"


@dataclass
class LBKPIECE1Planner(_RangedPlanner):
    """``lbkpiece1``: OMPL's Lazy Bi-directional KPIECE (Sucan and Kavraki 2009), one level of discretization,
    motions checked lazily; stops at its first solution.

    Attributes:
        range_m: longest motion added at once (0: OMPL's default).
        border_fraction: share of expansions spent on the discretization's border cells (OMPL's 0.9).
    """

    name: ClassVar[str] = "lbkpiece1"
    ompl_class: ClassVar[str] = "LBKPIECE1"
    border_fraction: float = param(0.9, within(MIN_BORDER_FRACTION, 1))
    # OMPL refuses a border fraction below machine epsilon (a RuntimeError): 0.001 is the stated floor

    def configure(self, planner) -> None:
        super().configure(planner)
        planner.setBorderFraction(self.border_fraction)


@dataclass
class BKPIECE1Planner(LBKPIECE1Planner):
    """``bkpiece1``: OMPL's Bi-directional KPIECE (Sucan and Kavraki 2009); stops at its first solution."""

    name: ClassVar[str] = "bkpiece1"
    ompl_class: ClassVar[str] = "BKPIECE1"


@dataclass
class KPIECE1Planner(LBKPIECE1Planner):
    """``kpiece1``: OMPL's KPIECE (Sucan and Kavraki 2009), one tree; stops at its first solution.

    Attributes:
        goal_bias: probability of sampling the goal (OMPL's default 0.05).
    """

    name: ClassVar[str] = "kpiece1"
    ompl_class: ClassVar[str] = "KPIECE1"
    goal_bias: float = param(0.05, within(0, 1))

    def configure(self, planner) -> None:
        super().configure(planner)
        planner.setGoalBias(self.goal_bias)


@dataclass
class AORRTCPlanner(_RangedPlanner):
    """``aorrtc``: OMPL's AORRTC (Wilson et al. 2025), asymptotically optimal RRT-Connect: bidirectional
    searches in a shrinking informed set; improves until the budget is spent.

    Attributes:
        range_m: longest motion added at once (0: OMPL's default).
    """

    name: ClassVar[str] = "aorrtc"
    ompl_class: ClassVar[str] = "AORRTC"


@dataclass
class FMTStarPlanner(_FirstSolutionPlanner):
    """``fmt_star``: OMPL's FMT* (Janson et al. 2015, Algorithm 2): ``num_samples`` samples, then a
    lazy dynamic-programming march through them; ends when the batch is searched or the budget spent.

    Attributes:
        num_samples: the batch of samples (OMPL's default 1000).
        radius_multiplier: the connection-radius factor of the paper's Eq. (3) (OMPL's default 1.1).
    """

    name: ClassVar[str] = "fmt_star"
    ompl_class: ClassVar[str] = "FMT"
    num_samples: int = param(1000, within(1, 1_000_000))
    radius_multiplier: float = param(1.1, above(0, 1e3))

    def configure(self, planner) -> None:
        planner.setNumSamples(self.num_samples)
        planner.setRadiusMultiplier(self.radius_multiplier)


@dataclass
class BFMTStarPlanner(FMTStarPlanner):
    """``bfmt_star``: OMPL's bidirectional FMT* (Starek et al. 2015)."""

    name: ClassVar[str] = "bfmt_star"
    ompl_class: ClassVar[str] = "BFMT"


@dataclass
class PRMPlanner(PRMStarPlanner):
    """``prm``: OMPL's PRM (Kavraki et al. 1996) with ``max_nearest_neighbors`` connections per milestone,
    grown round by round and queried by Dijkstra as ``prm_star`` is.

    Attributes:
        max_nearest_neighbors: connections tried per new milestone (OMPL's default 10).
    """

    name: ClassVar[str] = "prm"
    ompl_class: ClassVar[str] = "PRM"
    max_nearest_neighbors: int = param(10, within(1, 10_000))

    def configure(self, planner) -> None:
        planner.setMaxNearestNeighbors(self.max_nearest_neighbors)


OMPL_GEOMETRIC_PLANNERS: tuple[type, ...] = (RRTPlanner, RRTConnectPlanner, KPIECE1Planner, BKPIECE1Planner,
                                             LBKPIECE1Planner, PRMPlanner, FMTStarPlanner, BFMTStarPlanner,
                                             AORRTCPlanner)
