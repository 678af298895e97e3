"""Particle Swarm Optimisation over spline via-points: the swarm baseline.

Neither seed specifies its PSO (both cite it as the classic alternative), so this
is the plain constricted PSO of Clerc and Kennedy (2002) in its inertia form:

``v <- w v + c1 r1 (p_best - x) + c2 r2 (n_best - x)``, ``x <- x + v``

with ``w = 0.7298`` and ``c1 = c2 = 1.49618``, ``r1, r2`` uniform per particle
and coordinate, the velocity clamped to ``velocity_limit`` times the search
box's width per coordinate, and positions clipped to the box (the velocity of
a clipped coordinate is zeroed).  ``n_best`` is the swarm's best personal best
(``topology = "global"``) or the best personal best among the particle and its
two ring neighbours (``topology = "ring"``, the local-best PSO).  Each
iteration costs ``population`` evaluations.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.models.parameters import above, param, within
from swarmnav.planners.continuous import ContinuousPlanner
from swarmnav.planners.exact_check import ContinuousState
from swarmnav.models.errors import ConfigError
from swarmnav.planners.problem import Problem

TOPOLOGIES = ("global", "ring")


@dataclass
class ParticleSwarmPlanner(ContinuousPlanner):
    """``pso``: global-best or ring (local-best) PSO of the via-points.

    Attributes:
        inertia: ``w``.
        cognitive: ``c1``, the pull towards the particle's own best.
        social: ``c2``, the pull towards the neighbourhood's best.
        topology: ``"global"`` or ``"ring"``.
        velocity_limit: largest step per coordinate, as a fraction of the box width.
    """

    name: ClassVar[str] = "pso"

    inertia: float = param(0.7298, within(-10, 10))
    cognitive: float = param(1.49618, within(0, 10))
    social: float = param(1.49618, within(0, 10))
    topology: str = "global"
    velocity_limit: float = param(0.2, above(0, 100))

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.topology not in TOPOLOGIES:
            raise ConfigError("planner.params.topology",
                              f"must be one of {', '.join(TOPOLOGIES)}, got {self.topology!r}")
        if not self.velocity_limit > 0:
            raise ConfigError("planner.params.velocity_limit",
                              f"must be positive, got {self.velocity_limit!r}")

    def init_swarm(self, state: ContinuousState, rng: np.random.Generator) -> None:
        positions = self.initial_solutions(state, self.population, rng)
        costs = self.evaluate(state, positions)
        width = state.upper - state.lower
        state.data["velocity_max"] = self.velocity_limit * width
        state.data["velocities"] = (rng.random(positions.shape) * 2.0 - 1.0) * state.data["velocity_max"]
        state.data["positions"] = positions
        # "population"/"costs" are the personal bests: the candidates finish() falls back on.
        state.population = positions.copy()
        state.costs = costs.copy()

    def _neighbourhood_best(self, best_positions: np.ndarray, best_costs: np.ndarray) -> np.ndarray:
        """(P, D) the best personal best each particle is pulled towards."""
        if self.topology == "global":
            return np.broadcast_to(best_positions[np.argmin(best_costs)], best_positions.shape)
        count = best_costs.size
        ring = (np.arange(count)[:, None] + np.array([-1, 0, 1])) % count     # (P, 3)
        winner = ring[np.arange(count), np.argmin(best_costs[ring], axis=1)]
        return best_positions[winner]

    def step(self, state: ContinuousState, problem: Problem, rng: np.random.Generator,
             iteration: int) -> None:
        positions = state.data["positions"]
        velocities = state.data["velocities"]
        best_positions = state.population
        best_costs = state.costs
        lead = self._neighbourhood_best(best_positions, best_costs)
        r1 = rng.random(positions.shape)
        r2 = rng.random(positions.shape)
        velocities = (self.inertia * velocities
                      + self.cognitive * r1 * (best_positions - positions)
                      + self.social * r2 * (lead - positions))
        v_max = state.data["velocity_max"]
        velocities = np.clip(velocities, -v_max, v_max)
        moved = positions + velocities
        positions = np.clip(moved, state.lower, state.upper)
        velocities = np.where(moved == positions, velocities, 0.0)
        costs = self.evaluate(state, positions)
        better = costs < best_costs
        best_positions[better] = positions[better]
        best_costs[better] = costs[better]
        state.data["positions"] = positions
        state.data["velocities"] = velocities
