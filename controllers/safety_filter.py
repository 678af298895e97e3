"""A safety filter after Nav2's Collision Monitor "approach" behaviour (no MuJoCo).

Nav2's Collision Monitor, in its ``approach`` mode, projects the robot forward
with the commanded velocity and slows it so that the predicted time to
collision stays at least ``time_before_collision``; when no speed is safe it
stops.  Here the obstacles are the sensed ones (``Observation.detections``),
each predicted forward with its estimated velocity, and the robot's motion is
its commanded forward speed along its current heading (the turn rate is kept:
turning on the spot does not move the round footprint).

Choices of ours: the robot's footprint is a disc of the robot radius plus
``margin_m``; the speed is scaled down in steps of ``1 / speed_steps`` and the
largest safe one kept; a *trigger* is a control step at which the filter
starts to change the command after one at which it did not (so a long stop
counts once).  Reversing is never commanded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.kinematics import DriveGeometry, wheel_speeds
from swarmnav.controllers.navigator import DetectedObstacle
from swarmnav.controllers.prediction import detection_arrays, time_to_collision_s
from swarmnav.models.world import Pose2D


@dataclass
class SafetyFilter:
    """Slows or stops a command whose predicted time to collision is below ``time_before_collision_s``.

    Args:
        geometry: the drive, to turn the filtered (v, omega) back into wheel speeds.
        robot_radius_m: the robot's footprint radius.
        time_before_collision_s: the smallest predicted time to collision allowed.
        margin_m: added to the footprint.
        speed_steps: how finely the forward speed is scaled down.
    """

    geometry: DriveGeometry
    robot_radius_m: float
    time_before_collision_s: float = 1.0
    margin_m: float = 0.03
    speed_steps: int = 10

    def __post_init__(self) -> None:
        self.active = False
        self.triggers = 0
        scales = np.linspace(1.0, 0.0, self.speed_steps + 1)
        self._scales = scales

    def apply(self, pose: Pose2D, command: ControlCommand, detections: tuple[DetectedObstacle, ...]
              ) -> tuple[ControlCommand, bool]:
        """The command to send, and whether the filter was triggered at this step (a rising edge)."""
        v = command.linear_m_s
        if not detections or v <= 0.0:
            self.active = False
            return command, False
        centres, velocities, radii = detection_arrays(detections)
        heading = np.array([math.cos(pose.heading_rad), math.sin(pose.heading_rad)])
        candidates = self._scales[:, None] * v * heading[None, :]            # (S, 2), fastest first
        ttc = time_to_collision_s(np.array([pose.x_m, pose.y_m]), candidates, centres, velocities,
                                  radii + self.robot_radius_m + self.margin_m).min(axis=1)
        if ttc[0] >= self.time_before_collision_s:
            self.active = False
            return command, False
        safe = np.flatnonzero(ttc >= self.time_before_collision_s)
        scale = float(self._scales[safe[0]]) if safe.size else 0.0
        v_new = scale * v
        filtered = ControlCommand(wheel_speeds(v_new, command.angular_rad_s, self.geometry), v_new,
                                  command.angular_rad_s, command.waypoint_index)
        rising = not self.active
        self.active = True
        self.triggers += rising
        return filtered, rising
