"""Wheel odometry: the pose a navigator sees with ``knowledge = { pose = "odometry" }`` (no MuJoCo here).

Dead reckoning of a differential drive from the measured wheel speeds (each wheel's mean speed over the
control period, from its hinge angle: what an encoder counts; ``sim.stepper``; one sample of MuJoCo's
``jointvel`` sensors per period gave the same drift on gwo-scenario-1, 0.54 m against 0.56 m): v = r (w_R + w_L) / 2 and omega = r (w_R - w_L) / b with the model's
wheel radius r and track b (``sim.scene.index_scene``), integrated over the control period at the mid-point
heading (second-order Runge-Kutta, as ROS' ``diff_drive_controller`` odometry does).  Slip, skid-steer
scrub (the Jackal's four wheels turn by sliding) and contacts make it drift from the truth; the run reports
that drift (``pose_error_m``, ``max_pose_error_m``).

Encoder noise (``knowledge.encoder_noise``, default 0): each measured wheel speed is multiplied by
(1 + noise * N(0, 1)), drawn from the world seed's own stream (:data:`ODOMETRY_STREAM`), so the same
world seed gives the same drift.
"""

from __future__ import annotations

import math

import numpy as np

from swarmnav.models.world import Pose2D, wrap_angle_rad

ODOMETRY_STREAM = 7  # spawn key of the encoder-noise generator under the world seed


class WheelOdometry:
    """Integrates wheel speeds from a start pose.

    Args:
        start: the pose it starts from (the true start: odometry's frame is the map's at t = 0).
        wheel_radius_m, track_m: the drive geometry read from the model.
        encoder_noise: relative standard deviation of each wheel-speed reading (0: exact readings).
        world_seed: seeds the noise.
    """

    def __init__(self, start: Pose2D, wheel_radius_m: float, track_m: float, encoder_noise: float = 0.0,
                 world_seed: int = 0):
        self.x_m, self.y_m, self.heading_rad = start.x_m, start.y_m, start.heading_rad
        self.radius_m, self.track_m = float(wheel_radius_m), float(track_m)
        self.noise = float(encoder_noise)
        self.rng = np.random.default_rng(np.random.SeedSequence(int(world_seed), spawn_key=(ODOMETRY_STREAM,)))

    def update(self, left_rad_s: float, right_rad_s: float, dt_s: float) -> Pose2D:
        """Advance by one period with the wheels' measured speeds; the new pose estimate."""
        if self.noise > 0.0:
            left_rad_s, right_rad_s = (float(w) * (1.0 + self.noise * float(e))
                                       for w, e in zip((left_rad_s, right_rad_s), self.rng.standard_normal(2)))
        v = self.radius_m * (right_rad_s + left_rad_s) / 2.0
        omega = self.radius_m * (right_rad_s - left_rad_s) / self.track_m
        mid = self.heading_rad + omega * dt_s / 2.0
        self.x_m += v * math.cos(mid) * dt_s
        self.y_m += v * math.sin(mid) * dt_s
        self.heading_rad = float(wrap_angle_rad(self.heading_rad + omega * dt_s))
        return self.pose

    @property
    def pose(self) -> Pose2D:
        return Pose2D(self.x_m, self.y_m, self.heading_rad)
