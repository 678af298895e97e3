"""``follow``: plan once at t = 0 and follow that path, whatever the sensors say.

This is what every one of the five papers' planners does in its own simulator,
and the baseline every online navigator is compared with.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from swarmnav.controllers.navigator import NavigationSetup, NavigationStep, Observation


@dataclass
class FollowNavigator:
    """Hands the controller the path planned at t = 0 and relays its commands."""

    name: ClassVar[str] = "follow"
    uses_detections: ClassVar[bool] = False  # follows the first path whatever the sensors say
    uses_planner: ClassVar[bool] = False
    replan_wall_s: ClassVar[float] = 0.0  # plans nothing in step()

    def reset(self, setup: NavigationSetup) -> None:
        self._controller = setup.controller
        self._controller.reset(setup.path)

    def step(self, observation: Observation) -> NavigationStep:
        return NavigationStep(self._controller.command(observation.pose, observation.twist))
