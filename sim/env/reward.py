"""Reward and cost of one control step.

reward = ``progress_per_m`` x (d_before - d_after)      progress towards the goal (m)
       + ``goal_bonus``     if the goal is reached at this step
       - ``time_penalty_per_s`` x control period
       - ``collision_penalty`` x collisions begun during the step (the step's ``cost``)
       - ``effort_per_s`` x |a|^2 x control period      control effort
       - ``smoothness`` x |a - a_prev|^2                 change of command

d is the straight-line distance from the base to the goal.  The reward of a
step is computed from that step's own pose and the episode's one goal, before
anything is reset.  ``a`` is the step's action normalised to [-1, 1] per
component (the ``twist`` action as given, clipped; the ``wheels`` action divided
by the wheels' limit, clipped), and ``a_prev`` the previous step's (zeros at the
episode's first step: starting to move counts as a change).  With the defaults
(the last three 0) the reward is the progress, bonus and time terms only, as
before these options existed, and collisions stay out of it: the number of
collisions that began during the step (MuJoCo contacts between a robot geom and
an obstacle geom, counted like ``swarmnav run``) is the step's ``cost``, after
Safety-Gymnasium's convention of a separate cost signal.  ``collision_penalty``
puts them into the reward as well, for learners without a cost signal.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from swarmnav.models.errors import ConfigError


@dataclass(frozen=True)
class RewardWeights:
    """The reward's weights (see the module docstring).

    Attributes:
        progress_per_m: reward per metre of progress towards the goal.
        goal_bonus: reward on the step that reaches the goal.
        time_penalty_per_s: reward taken away per simulated second.
        collision_penalty: reward taken away per collision begun (0: collisions only in ``cost``).
        effort_per_s: reward taken away per second per unit of squared normalised action.
        smoothness: reward taken away per unit of squared change of the normalised action.
    """

    progress_per_m: float = 1.0
    goal_bonus: float = 10.0
    time_penalty_per_s: float = 0.01
    collision_penalty: float = 0.0
    effort_per_s: float = 0.0
    smoothness: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
                raise ConfigError(f"env.reward.{f.name}", f"expected a finite number, got {value!r}")
        for name in ("collision_penalty", "effort_per_s", "smoothness"):
            if getattr(self, name) < 0:
                raise ConfigError(f"env.reward.{name}", f"is a penalty: must be >= 0, got {getattr(self, name)!r}")

    def reward(self, distance_before_m: float, distance_after_m: float, reached: bool, dt_s: float,
               collisions: float = 0.0, action: np.ndarray | None = None,
               previous_action: np.ndarray | None = None) -> float:
        """One step's reward; ``action`` and ``previous_action`` normalised (see the module docstring)."""
        value = (self.progress_per_m * (distance_before_m - distance_after_m)
                 + (self.goal_bonus if reached else 0.0) - self.time_penalty_per_s * dt_s)
        if self.collision_penalty:
            value -= self.collision_penalty * collisions
        if action is not None and self.effort_per_s:
            value -= self.effort_per_s * float(np.dot(action, action)) * dt_s
        if action is not None and self.smoothness:
            change = action - (np.zeros_like(action) if previous_action is None else previous_action)
            value -= self.smoothness * float(np.dot(change, change))
        return value
