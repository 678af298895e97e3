"""Controllers: waypoints in, wheel speeds out.  No MuJoCo here."""

from swarmnav.controllers.kinematics import DriveGeometry, WheelSpeeds, body_twist, wheel_speeds
from swarmnav.controllers.point_to_point import ControlCommand, GoalChecker, PointToPointController, wrap_angle_rad

__all__ = ["DriveGeometry", "WheelSpeeds", "wheel_speeds", "body_twist", "ControlCommand",
           "GoalChecker", "PointToPointController", "wrap_angle_rad"]
