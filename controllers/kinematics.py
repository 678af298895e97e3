"""Differential-drive inverse kinematics (Habib et al. 2021, section 2.7).

    omega_R = (v + omega * track / 2) / wheel_radius
    omega_L = (v - omega * track / 2) / wheel_radius
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class DriveGeometry:
    """What the controller needs to know about the robot, read once from the model.

    Attributes:
        wheel_radius_m: rolling radius of each drive wheel.
        track_m: distance between the two wheel contact points.
        max_wheel_speed_rad_s: the wheel actuators' limit.
    """

    wheel_radius_m: float
    track_m: float
    max_wheel_speed_rad_s: float


@dataclass(frozen=True)
class WheelSpeeds:
    """Left and right wheel angular velocities, rad/s (positive drives forward)."""

    left_rad_s: float
    right_rad_s: float


def wheel_speeds(linear_m_s: float, angular_rad_s: float, geometry: DriveGeometry) -> WheelSpeeds:
    """Inverse kinematics with saturation that keeps the curvature.

    When a wheel would exceed ``max_wheel_speed_rad_s`` both wheels are scaled by
    the same factor, so the ratio v / omega (the turning radius) is unchanged.
    """
    half_track = 0.5 * geometry.track_m
    right = (linear_m_s + angular_rad_s * half_track) / geometry.wheel_radius_m
    left = (linear_m_s - angular_rad_s * half_track) / geometry.wheel_radius_m
    peak = max(abs(left), abs(right))
    if peak > geometry.max_wheel_speed_rad_s:
        scale = geometry.max_wheel_speed_rad_s / peak
        left *= scale
        right *= scale
    return WheelSpeeds(left, right)


def body_twist(speeds: WheelSpeeds, geometry: DriveGeometry) -> tuple[float, float]:
    """Forward kinematics: (v m/s, omega rad/s) from wheel speeds."""
    r = geometry.wheel_radius_m
    v = 0.5 * r * (speeds.right_rad_s + speeds.left_rad_s)
    omega = r * (speeds.right_rad_s - speeds.left_rad_s) / geometry.track_m
    return v, omega
