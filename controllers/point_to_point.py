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

    Two limits on v keep a fast robot on its lines (ours, off by default: the paper's controller; the robot
    catalogue switches them on for its real platforms, ``models.robots``; at 0.2 m/s neither binds, with
    the values 0.05 m and 2.0 m/s^2 they bind only above about 0.28 m/s):

    * **Drift**: a heading error e corrected while driving at v, at the turn rate the controller
      commands for it, omega_e = min(k e, ``max_angular_rad_s``), drifts about v e^2 / omega_e sideways
      (v e / k while the turn rate is not saturated: the error decays as exp(-k t)); v is held to what
      keeps that within ``max_drift_m`` (the catalogue's 0.05 m: the default planning clearance).
    * **Corners**: v is held to what lets the robot brake at ``max_deceleration_m_s2`` (2.0) to the speed
      the drift limit allows for the turn at the active waypoint (0 when that turn is a turn on the
      spot): v <= sqrt(v_corner^2 + 2 a d), d the distance to the waypoint.

    Args:
        geometry: wheel radius, track and wheel speed limit, read from the model.
        max_speed_m_s: forward speed limit (the scenario's robot.max_speed_m_s).
        max_angular_rad_s: turn rate limit.
        heading_gain: k, rad/s per rad of heading error.
        switch_radius_m: distance at which an intermediate waypoint counts as passed.
        slowdown_radius_m: distance to the final waypoint below which v shrinks linearly.
        turn_in_place_rad: heading error above which the robot turns without advancing.
        max_drift_m: sideways drift allowed while a heading error is corrected (the drift limit; None: off).
        max_deceleration_m_s2: the braking rate of the corner limit (None: off).
        arc_cap: v held to what lets the robot reach the active waypoint on an arc at ``max_angular_rad_s``,
            omega_max d / (2 sin|e|) (ours, off by default; set by ``iaco_local``'s ``arc_cap``): with a
            ``turn_in_place_rad`` of 60 degrees the robot drove at 0.5 m/s on a 0.42 m circle round a
            waypoint beside it, never within ``switch_radius_m``, until the time limit.
    """

    geometry: DriveGeometry
    max_speed_m_s: float = 0.2
    max_angular_rad_s: float = 1.2
    heading_gain: float = 2.5
    switch_radius_m: float = 0.05
    slowdown_radius_m: float = 0.3
    turn_in_place_rad: float = math.radians(25.0)
    max_drift_m: float | None = None
    max_deceleration_m_s2: float | None = None
    arc_cap: bool = False

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

    def _drift_limit_m_s(self, error_rad: float) -> float:
        """The speed at which correcting ``error_rad`` drifts ``max_drift_m`` sideways (inf at 0)."""
        error_rad = abs(error_rad)
        if error_rad == 0.0 or self.max_drift_m is None:
            return math.inf
        rate = min(self.heading_gain * error_rad, self.max_angular_rad_s)
        return self.max_drift_m * rate / (error_rad * error_rad)

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
            v = min(self.max_speed_m_s * math.cos(error), self._drift_limit_m_s(error))
            if self._index == last:
                v *= min(1.0, dist / self.slowdown_radius_m)
            elif self.max_deceleration_m_s2 is not None:
                nx, ny = self._waypoints[self._index + 1]
                turn = abs(wrap_angle_rad(math.atan2(ny - ty, nx - tx) - math.atan2(ty - pose.y_m, tx - pose.x_m)))
                corner = 0.0 if turn >= self.turn_in_place_rad else self._drift_limit_m_s(turn)
                v = min(v, math.sqrt(corner * corner + 2.0 * self.max_deceleration_m_s2 * dist))
            if self.arc_cap and error != 0.0:
                v = min(v, self.max_angular_rad_s * dist / (2.0 * math.sin(abs(error))))
        return ControlCommand(wheel_speeds(v, omega, self.geometry), v, omega, self._index)
