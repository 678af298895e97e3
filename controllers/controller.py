"""The controller seam, after nav2's ``computeVelocityCommands``: a path in, wheel speeds out.

``reset(path)`` when a path is given (at the start and after every replan),
then ``command(pose, twist) -> ControlCommand`` at every control step.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from swarmnav.controllers.kinematics import WheelSpeeds
from swarmnav.models.world import Pose2D
from swarmnav.planners.problem import Path


@dataclass(frozen=True, init=False)
class Twist:
    """The base's measured velocity in its own frame: forward speed and turn rate."""

    linear_m_s: float = 0.0
    angular_rad_s: float = 0.0

    def __init__(self, linear_m_s: float = 0.0, angular_rad_s: float = 0.0):
        # Built every control step: set once, straight into the dict (see models.world.Pose2D).
        self.__dict__.update(linear_m_s=linear_m_s, angular_rad_s=angular_rad_s)


@dataclass(frozen=True)
class ControlCommand:
    """One control step's output: wheel speeds and the (v, omega) they came from."""

    wheels: WheelSpeeds
    linear_m_s: float
    angular_rad_s: float
    waypoint_index: int

    @classmethod
    def stop(cls, waypoint_index: int = 0) -> "ControlCommand":
        return cls(WheelSpeeds(0.0, 0.0), 0.0, 0.0, waypoint_index)


class Controller(Protocol):
    def reset(self, path: Path) -> None: ...
    def command(self, pose: Pose2D, twist: Twist) -> ControlCommand: ...
