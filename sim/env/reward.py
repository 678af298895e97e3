"""Reward and cost of one control step.

reward = ``progress_per_m`` x (d_before - d_after)      progress towards the goal (m)
       + ``goal_bonus``     if the goal is reached at this step
       - ``time_penalty_per_s`` x control period

d is the straight-line distance from the base to the goal.  The reward of a
step is computed from that step's own pose and the episode's one goal, before
anything is reset.  Collisions never enter the reward: the number of collisions
that began during the step (MuJoCo contacts between a robot geom and an
obstacle geom, counted like ``swarmnav run``) is the step's ``cost``, after
Safety-Gymnasium's convention of a separate cost signal.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class RewardWeights:
    """The reward's weights (see the module docstring).

    Attributes:
        progress_per_m: reward per metre of progress towards the goal.
        goal_bonus: reward on the step that reaches the goal.
        time_penalty_per_s: reward taken away per simulated second.
    """

    progress_per_m: float = 1.0
    goal_bonus: float = 10.0
    time_penalty_per_s: float = 0.01

    def reward(self, distance_before_m: float, distance_after_m: float, reached: bool, dt_s: float) -> float:
        return (self.progress_per_m * (distance_before_m - distance_after_m)
                + (self.goal_bonus if reached else 0.0) - self.time_penalty_per_s * dt_s)
