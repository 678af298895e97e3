"""The continuous planners' two modes, resolved for one problem: what a run of ``gwo``, ``abc``,
``adl_abc`` or ``pso`` actually uses (:class:`RunSettings`).

``mode = "paper"`` (the default) is the algorithm as its paper writes it, whatever the scene:

* Kamil, Mohamed & Olewi (2020) Eqs. (1)-(5): the cost is the sampled length plus the
  obstacle penalty ``$p`` (``F + $p``, the reciprocal of its fitness Eq. (2)), with no
  penalty for leaving the arena (neither paper has one).  The penalty's weight is 1000 and
  the discs it sees are grown by a 2 cm margin (besides the robot radius and the clearance):
  the settings the papers' results need, a deviation stated in the README's table.  With
  the printed weight 1 (and no margin) the best candidate cuts a disc on every bundled
  scenario of Abdulla & Hadi (2025) for every seed tried (``gwo-scenario-1``: best clearance
  -0.39 m, seeds 0-4): a cut of a few centimetres costs less penalty than the detour saves.
  ``penalty_weight = 1, penalty_margin_m = 0`` gives the printed objective;
* 3 via-points (Kamil et al. 2020 Sect. 6; Abdulla & Hadi 2025 Sect. 6.1), a uniform random
  first population (Eq. (6)), the paper's iterations and nothing after them: the best
  candidate is the answer.  swarmnav checks it exactly (segment-disc distances,
  :meth:`planners.problem.Problem.is_collision_free`); a best that cuts a disc is
  :class:`planners.errors.NoPathFound` (the papers report the best as a path; we report it
  as a failure, honestly, rather than look elsewhere for one).

``mode = "robust"`` is swarmnav's hybrid, not a paper's algorithm: it **starts from the exact
tangent-graph route** (the ``optimal`` planner's, :mod:`planners.tangent_guess`; a grid A*
route above :data:`planners.path_guess.MAX_TANGENT_DISCS` discs), fits the via-points to it,
draws half the first population around it, runs the swarm, and polishes.  Each of its
mechanisms is a named option, set on its own in either mode (an explicit value always wins
over the mode's default):

============================  ==========  ==========  ===========================================
option                        paper       robust      what it does
============================  ==========  ==========  ===========================================
``penalty_weight``            1000        1000        weight of the obstacle (and bounds) penalty
``penalty_margin_m``          0.02        0.02        added to the penalty's radii only
``bounds_penalty``            false       true        penalise samples outside the arena
``population_fallback``       false       true        if the best cuts a disc, take the cheapest
                                                      member of the final population that does not
``repair_rounds``             0           10          fine-penalty local search when nothing passes
``guess``                     ``"none"``  tangent     the geometric guess (``"tangent"``, ``"grid"``,
                                                      ``"none"``)
``guess_fraction``            0           0.5         share of the first population drawn around it
``via_points``                3           from guess  free via-points
``via_point_growth``          0           2           doublings of the via-points when nothing passes
``fit_push_rounds``           0           40          push the guess's fit out of the discs
``polish_rounds``             0           40          compass search on the answer
``gap_margins``               false       true        shrink margins to keep narrow gaps open
``stall_evaluations``         0 (never)   10 pop.     stop after so many evaluations without gain
============================  ==========  ==========  ===========================================

The robust mode's ablation is measurable on the same seeds: ``guess = "none"`` (no guess: the
swarm alone from a uniform start, with the robust penalty and repair), ``iterations = 0``
(no swarm: the guess's fit, its perturbed copies and the polish only).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.path_guess import MAX_TANGENT_DISCS, gap_margins_m, scene_guesses
from swarmnav.planners.problem import Problem

MODES = ("paper", "robust")
GUESSES = ("grid", "tangent", "none")
#: Via-points of both papers (Kamil et al. 2020 Sect. 6; Abdulla & Hadi 2025 Sect. 6.1).
PAPER_VIA_POINTS = 3

#: Each mode's value of the options left unset (``None``).  ``stall_evaluations`` of the robust
#: mode is in populations, and applies only to a guided search.
MODE_DEFAULTS: dict[str, dict[str, Any]] = {
    "paper": {"penalty_weight": 1000.0, "penalty_margin_m": 0.02, "bounds_penalty": False,
              "population_fallback": False, "repair_rounds": 0, "guess_fraction": 0.0, "polish_rounds": 0,
              "via_point_growth": 0, "fit_push_rounds": 0, "gap_margins": False, "stall_evaluations": 0},
    "robust": {"penalty_weight": 1000.0, "penalty_margin_m": 0.02, "bounds_penalty": True,
               "population_fallback": True, "repair_rounds": 10, "guess_fraction": 0.5, "polish_rounds": 40,
               "via_point_growth": 2, "fit_push_rounds": 40, "gap_margins": True, "stall_evaluations": 10},
}
#: The robust mode's default guess (up to :data:`MAX_TANGENT_DISCS` discs; "grid" above).
ROBUST_GUESS = "tangent"


def mode_value(planner: Any, name: str) -> Any:
    """``planner.<name>``, or its mode's default when it is None."""
    value = getattr(planner, name)
    return MODE_DEFAULTS[planner.mode][name] if value is None else value


@dataclass(frozen=True)
class RunSettings:
    """What one run uses once the mode is resolved (:func:`resolve_settings`).

    Attributes:
        mode: "paper" or "robust".
        via_points: ``k`` of this attempt.
        guess_fraction: share of the first population drawn around ``guesses``.
        polish_rounds: compass-search rounds on the chosen candidate.
        growth: how many more times ``k`` may double when nothing passes.
        guesses: the geometric guesses, (N, 2) waypoints each (empty: none).
        push_rounds: rounds that push the guesses' fits out of the discs.
        stall_evaluations: evaluations without improvement that end the search (0: never).
        margins_m: (n,) the penalty margin of each disc.
        guess: the kind of the guesses ("tangent", "grid" or "none").
        penalty_weight: the weight of the penalty.
        bounds_penalty: whether the cost penalises samples outside the arena.
        population_fallback: whether the final population is scanned when the best cuts a disc.
        repair_rounds: rounds of the fine-penalty repair.
    """

    mode: str = "paper"
    via_points: int = PAPER_VIA_POINTS
    guess_fraction: float = 0.0
    polish_rounds: int = 0
    growth: int = 0
    guesses: tuple[np.ndarray, ...] = ()
    push_rounds: int = 0
    stall_evaluations: int = 0
    margins_m: np.ndarray | float = 0.0
    guess: str = "none"
    penalty_weight: float = 1.0
    bounds_penalty: bool = False
    population_fallback: bool = False
    repair_rounds: int = 0

    def summary(self) -> dict[str, Any]:
        """The resolved options a run reports (``stats.extra["settings"]``)."""
        margins = np.asarray(self.margins_m, dtype=float)
        return {"mode": self.mode, "via_points": self.via_points, "guess": self.guess,
                "guess_fraction": self.guess_fraction, "polish_rounds": self.polish_rounds,
                "via_point_growth": self.growth, "fit_push_rounds": self.push_rounds,
                "stall_evaluations": self.stall_evaluations, "penalty_weight": self.penalty_weight,
                "penalty_margin_m": float(margins.max()) if margins.size else 0.0,
                "bounds_penalty": self.bounds_penalty, "population_fallback": self.population_fallback,
                "repair_rounds": self.repair_rounds}


def resolve_settings(planner: Any, problem: Problem) -> RunSettings:
    """Resolve ``planner.mode`` and the options it left at ``None`` for ``problem`` (computing the
    geometric guess when one is used).  Nothing here depends on where the problem came from.

    Raises:
        NoPathFound: the tangent guess proves that no route exists (the exact tangent graph
            joins none).
    """
    mode = planner.mode
    value = lambda name: mode_value(planner, name)   # noqa: E731
    margin_m = value("penalty_margin_m")
    margins = gap_margins_m(problem, margin_m) if value("gap_margins") and margin_m > 0 else margin_m
    kind = planner.guess or ("none" if mode == "paper" else
                             ROBUST_GUESS if problem.disc_centres_m.shape[0] <= MAX_TANGENT_DISCS else "grid")
    fraction = value("guess_fraction") if kind != "none" else 0.0
    guesses, chosen_k = (), PAPER_VIA_POINTS
    if kind != "none" and (fraction or (planner.via_points is None and mode == "robust")):
        guess_margin = planner.guess_margin_m if planner.guess_margin_m is not None else margins
        guesses, chosen_k = scene_guesses(problem, kind, planner.guess_cell_m, guess_margin)
        if kind == "tangent" and not guesses:
            raise NoPathFound(f"{planner.name}: no collision-free path exists: the tangent graph of the inflated "
                              f"discs (exact, as the optimal planner's) joins no route from start to goal")
    if mode == "paper" and planner.via_points is None:
        chosen_k = PAPER_VIA_POINTS
    stall = value("stall_evaluations")
    if planner.stall_evaluations is None and mode == "robust":
        stall = stall * planner.population if (fraction and guesses) else 0
    return RunSettings(
        mode=mode, via_points=planner.via_points or chosen_k, guess_fraction=fraction,
        polish_rounds=value("polish_rounds"), growth=value("via_point_growth"), guesses=tuple(guesses),
        push_rounds=value("fit_push_rounds"), stall_evaluations=stall, margins_m=margins, guess=kind,
        penalty_weight=value("penalty_weight"), bounds_penalty=value("bounds_penalty"),
        population_fallback=value("population_fallback"), repair_rounds=value("repair_rounds"))
