"""``slow_follow``: follow the path planned at t = 0 at a fraction of the robot's top speed."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.kinematics import WheelSpeeds
from swarmnav.controllers.navigator import NavigationSetup, NavigationStep, Observation


@dataclass
class SlowFollowNavigator:
    """Follows the first path, its wheel commands scaled by ``speed_fraction``."""

    name: ClassVar[str] = "slow_follow"
    uses_detections: ClassVar[bool] = False
    uses_planner: ClassVar[bool] = False
    replan_wall_s: ClassVar[float] = 0.0
    speed_fraction: float = 0.5

    def __post_init__(self) -> None:
        if not 0.0 < self.speed_fraction <= 1.0:
            raise ValueError(f"speed_fraction must be in (0, 1], got {self.speed_fraction}")

    def reset(self, setup: NavigationSetup) -> None:
        self._controller = setup.controller
        self._controller.reset(setup.path)

    def step(self, observation: Observation) -> NavigationStep:
        command = self._controller.command(observation.pose, observation.twist)
        k = self.speed_fraction
        return NavigationStep(ControlCommand(WheelSpeeds(command.wheels.left_rad_s * k, command.wheels.right_rad_s * k),
                                             command.linear_m_s * k, command.angular_rad_s, command.waypoint_index))
