"""Point-to-point (PTP) waypoint following with inverse kinematics
(Habib et al. 2021, sections 2.6-2.7): the robot drives from its current pose to
each waypoint in turn along a straight line, turning toward it first.

It implements the :class:`~controllers.controller.Controller` seam: ``reset(path)``
then ``command(pose, twist) -> ControlCommand`` every control step.  Stopping
at the goal is the goal checker's job (:mod:`controllers.goal`), not this one's.
No MuJoCo here: plain numbers in, wheel speeds out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarmnav.controllers.controller import ControlCommand, Twist
from swarmnav.controllers.kinematics import DriveGeometry, WheelSpeeds, wheel_speeds
from swarmnav.models.world import Pose2D, wrap_angle_rad
from swarmnav.planners.problem import Path


@dataclass
class PointToPointController:
    """Walks the waypoints in turn.

    Each step: heading error e to the active waypoint gives omega = k * e within
    +-``max_angular_rad_s``; v = ``max_speed_m_s`` * cos(e) when |e| < ``turn_in_place_rad``
    (else 0, turning on the spot), further reduced within ``slowdown_radius_m`` of the
    final waypoint; the next waypoint becomes active within ``switch_radius_m``.

    Args:
        geometry: wheel radius, track and wheel speed limit, read from the model.
        max_speed_m_s: forward speed limit (the scenario's robot.max_speed_m_s).
        max_angular_rad_s: turn rate limit.
        heading_gain: k, rad/s per rad of heading error.
        switch_radius_m: distance at which an intermediate waypoint counts as passed.
        slowdown_radius_m: distance to the final waypoint below which v shrinks linearly.
        turn_in_place_rad: heading error above which the robot turns without advancing.
    """

    geometry: DriveGeometry
    max_speed_m_s: float = 0.2
    max_angular_rad_s: float = 1.2
    heading_gain: float = 2.5
    switch_radius_m: float = 0.05
    slowdown_radius_m: float = 0.3
    turn_in_place_rad: float = math.radians(25.0)

    def __post_init__(self) -> None:
        self._waypoints: list[tuple[float, float]] = []
        self._index = 0

    def reset(self, path: Path) -> None:
        """Start following a new path (also after a replan); the first waypoint is the start."""
        pts = [(float(x), float(y)) for x, y in np.asarray(path.waypoints, dtype=float).reshape(-1, 2)]
        if not pts:
            raise ValueError("a path needs at least one waypoint")
        self._waypoints = pts
        self._index = 1 if len(pts) > 1 else 0

    @property
    def waypoint_index(self) -> int:
        return self._index

    def command(self, pose: Pose2D, twist: Twist | None = None) -> ControlCommand:
        """Wheel speeds that drive ``pose`` toward the active waypoint (the twist is not needed)."""
        last = len(self._waypoints) - 1
        tx, ty = self._waypoints[self._index]
        dist = math.hypot(tx - pose.x_m, ty - pose.y_m)
        while self._index < last and dist < self.switch_radius_m:
            self._index += 1
            tx, ty = self._waypoints[self._index]
            dist = math.hypot(tx - pose.x_m, ty - pose.y_m)
        if dist == 0.0:  # on the last waypoint exactly: no heading to steer by
            return ControlCommand(WheelSpeeds(0.0, 0.0), 0.0, 0.0, self._index)
        error = wrap_angle_rad(math.atan2(ty - pose.y_m, tx - pose.x_m) - pose.heading_rad)
        omega = max(-self.max_angular_rad_s, min(self.max_angular_rad_s, self.heading_gain * error))
        if abs(error) >= self.turn_in_place_rad:
            v = 0.0
        else:
            v = self.max_speed_m_s * math.cos(error)
            if self._index == last:
                v *= min(1.0, dist / self.slowdown_radius_m)
        return ControlCommand(wheel_speeds(v, omega, self.geometry), v, omega, self._index)
