"""The pheromone trail limits of the MAX-MIN Ant System (Stützle & Hoos 2000), shared by ``mmas`` and ``immas``.

Stützle & Hoos (2000), *MAX-MIN Ant System*, Future Generation Computer Systems 16(8):

* the update (their Eq. 6; Hasan et al. 2023 Eq. 2) is ``tau <- rho * tau + delta_best`` with
  ``rho`` the trail **persistence** (their ``rho = 0.98``; the evaporation is ``1 - rho``) and
  ``delta_best = 1 / f(s_best)`` deposited by one ant only, the iteration-best or the best so far;
* the trails are kept in ``[tau_min, tau_max]`` after every update (their Sect. 3.3);
* ``tau_max = 1 / ((1 - rho) f(s_gb))`` (their Eq. 7, the limit of the update under the best
  solution's deposit), re-estimated whenever a new best solution ``s_gb`` is found;
* ``tau_min = tau_max (1 - p_best^(1/n)) / ((avg - 1) p_best^(1/n))`` (their Eq. 11), with ``n``
  the decision points of a solution, ``avg`` the average number of choices at a decision
  point and ``p_best = 0.05`` the probability of building the best solution once converged;
* trails start at ``tau_max`` (their Sect. 3.4: "initialised to an arbitrarily high value",
  which the first update's bounds bring to ``tau_max``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Stützle & Hoos (2000)'s default probability of constructing the best solution once converged.
P_BEST = 0.05


@dataclass(frozen=True)
class TrailLimits:
    """``[tau_min, tau_max]`` of one moment of a MAX-MIN run."""

    tau_min: float
    tau_max: float

    def clamp(self, tau: np.ndarray, where: np.ndarray | None = None) -> np.ndarray:
        """In place: every trail into ``[tau_min, tau_max]`` (only at ``where``, if given); returns ``tau``."""
        if where is None:
            np.clip(tau, self.tau_min, self.tau_max, out=tau)
        else:
            tau[where] = np.clip(tau[where], self.tau_min, self.tau_max)
        return tau

    def clamp_value(self, value: float) -> float:
        """One trail into ``[tau_min, tau_max]``."""
        return min(max(value, self.tau_min), self.tau_max)


def trail_limits(persistence: float, best_cost: float, decisions: float, choices: float,
                 p_best: float = P_BEST) -> TrailLimits:
    """Stützle & Hoos (2000) Eqs. (7) and (11).

    Args:
        persistence: ``rho`` of the update ``tau <- rho tau + delta`` (in [0, 1)).
        best_cost: ``f(s_gb)``, the best solution's cost (positive).
        decisions: ``n``, the decision points of a solution (at least 1).
        choices: ``avg``, the average number of choices at a decision point (above 1).
        p_best: the probability of building the best solution once converged (in (0, 1)).
    """
    tau_max = 1.0 / ((1.0 - persistence) * best_cost)
    root = p_best ** (1.0 / max(decisions, 1.0))
    tau_min = tau_max * (1.0 - root) / ((max(choices, 1.0 + 1e-9) - 1.0) * root)
    return TrailLimits(tau_min=min(tau_min, tau_max), tau_max=tau_max)


def unit_limits(persistence: float, deposit: float, decisions: float, choices: float,
                p_best: float = P_BEST) -> TrailLimits:
    """The limits of an update whose largest deposit is ``deposit``: Eq. (7) with ``1 / f(s_gb) = deposit``."""
    return trail_limits(persistence, 1.0 / deposit, decisions, choices, p_best)


def check_limits(tau: np.ndarray, limits: TrailLimits, where: np.ndarray | None = None) -> bool:
    """Whether every trail (at ``where``) lies in ``[tau_min, tau_max]`` (tests and diagnostics)."""
    values = tau if where is None else tau[where]
    finite = values[np.isfinite(values)]
    return bool(finite.size == values.size and np.all(finite >= limits.tau_min - 1e-12 * max(1.0, limits.tau_min))
                and np.all(finite <= limits.tau_max * (1 + 1e-12)))


__all__ = ["P_BEST", "TrailLimits", "trail_limits", "unit_limits", "check_limits"]
