"""What a learned policy sees and what it answers: one convention for the environment and the ``policy`` navigator.

The environment (``swarmnav.sim.env``) and the ``policy`` navigator both build
their observations with :class:`PolicyObserver` and turn actions into wheel
commands with :func:`action_command`, so a policy trained in the environment
runs unchanged through ``swarmnav run``.

Observation (a dict of float64 arrays):

* ``ranges`` (K,): rangefinder distances divided by their reach, in [0, 1];
  1 = nothing in range.
* ``goal`` (2,): distance to the goal (m) and its bearing in the robot frame
  (rad, in [-pi, pi), CCW from the heading).
* ``velocity`` (2,): the measured forward speed (m/s) and turn rate (rad/s).
* ``path`` (N, 2), only when asked for: the next N waypoints of a planned path
  in the robot frame (m; x forward, y left).  "Next" counts from the waypoint
  after the nearest one, never going back along the path; when fewer than N are
  left the last (the goal) repeats.

Action (2,), in one of two modes:

* ``"twist"``: a normalised (v, omega) in [-1, 1]^2, scaled by the robot's speed
  limit and by :func:`max_turn_rate_rad_s`, then turned into wheel speeds by the
  inverse kinematics with curvature-keeping saturation (:func:`kinematics.wheel_speeds`);
* ``"wheels"``: left and right wheel speeds in rad/s, clipped to the wheels' limit.
"""

from __future__ import annotations

import math

import numpy as np

from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.kinematics import DriveGeometry, WheelSpeeds, body_twist, wheel_speeds
from swarmnav.controllers.navigator import Observation
from swarmnav.models.world import wrap_angle_rad

ACTION_MODES = ("twist", "wheels")


def max_turn_rate_rad_s(geometry: DriveGeometry, max_speed_m_s: float) -> float:
    """The turn rate that omega = 1 means: both wheels at the speed limit in opposite directions (2 v_max / track)."""
    return 2.0 * max_speed_m_s / geometry.track_m


def action_bounds(mode: str, geometry: DriveGeometry) -> tuple[float, float]:
    """(lower, upper) of each action component in ``mode``."""
    if mode == "twist":
        return -1.0, 1.0
    return -geometry.max_wheel_speed_rad_s, geometry.max_wheel_speed_rad_s


def action_command(action: np.ndarray, mode: str, geometry: DriveGeometry, max_speed_m_s: float,
                   waypoint_index: int = 0) -> ControlCommand:
    """A (2,) action in ``mode`` -> the wheel command (out-of-range values are clipped)."""
    a0, a1 = (float(a) for a in np.asarray(action, dtype=float).reshape(2))
    if mode == "twist":
        v = min(max(a0, -1.0), 1.0) * max_speed_m_s
        omega = min(max(a1, -1.0), 1.0) * max_turn_rate_rad_s(geometry, max_speed_m_s)
        return ControlCommand(wheel_speeds(v, omega, geometry), v, omega, waypoint_index)
    limit = geometry.max_wheel_speed_rad_s
    wheels = WheelSpeeds(min(max(a0, -limit), limit), min(max(a1, -limit), limit))
    v, omega = body_twist(wheels, geometry)
    return ControlCommand(wheels, v, omega, waypoint_index)


class PolicyObserver:
    """Turns an :class:`Observation` into the policy's observation dict (see the module docstring).

    Args:
        goal_xy_m: the goal position.
        path_m: (P, 2) waypoints of a planned path, or None for no ``path`` entry.
        path_waypoints: N, the number of waypoints in ``path``.
    """

    def __init__(self, goal_xy_m: tuple[float, float], path_m: np.ndarray | None = None, path_waypoints: int = 0):
        self.goal_xy_m = (float(goal_xy_m[0]), float(goal_xy_m[1]))
        self.path_m = None if path_m is None or path_waypoints <= 0 else np.asarray(path_m, dtype=float).reshape(-1, 2)
        self.path_waypoints = int(path_waypoints) if self.path_m is not None else 0
        self.cursor = 0  # index of the nearest waypoint so far (never decreases)

    def reset(self) -> None:
        self.cursor = 0

    def __call__(self, observation: Observation) -> dict[str, np.ndarray]:
        pose = observation.pose
        ranges = np.asarray(observation.ranges_m, dtype=float) / observation.range_cutoff_m
        out = {"ranges": np.minimum(ranges, 1.0),  # inf / cutoff = inf -> 1
               "goal": np.array(self.goal_in_robot_frame(pose.x_m, pose.y_m, pose.heading_rad)),
               "velocity": np.array([observation.twist.linear_m_s, observation.twist.angular_rad_s])}
        if self.path_m is not None:
            out["path"] = self.next_waypoints(pose.x_m, pose.y_m, pose.heading_rad)
        return out

    def goal_in_robot_frame(self, x_m: float, y_m: float, heading_rad: float) -> tuple[float, float]:
        dx, dy = self.goal_xy_m[0] - x_m, self.goal_xy_m[1] - y_m
        return math.hypot(dx, dy), float(wrap_angle_rad(math.atan2(dy, dx) - heading_rad))

    def next_waypoints(self, x_m: float, y_m: float, heading_rad: float) -> np.ndarray:
        path = self.path_m
        ahead = path[self.cursor:]
        self.cursor += int(np.argmin(np.hypot(ahead[:, 0] - x_m, ahead[:, 1] - y_m)))
        index = np.minimum(np.arange(self.cursor + 1, self.cursor + 1 + self.path_waypoints), len(path) - 1)
        rel = path[index] - (x_m, y_m)
        c, s = math.cos(heading_rad), math.sin(heading_rad)
        return np.stack([c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1]], axis=1)
