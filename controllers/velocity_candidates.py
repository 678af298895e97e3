"""Choosing a velocity among sampled candidates by their time to collision (velocity obstacles).

Shared by the ``velocity_obstacle`` navigator and the ``evade`` takeover (:mod:`controllers.evasion`):
each candidate is a robot-frame velocity (speed along a heading offset); its time to collision is the
earliest over the moving discs (:func:`controllers.prediction.time_to_collision_s`) and the map's boxes
(a box within reach of the candidate's straight sweep over the horizon counts as a collision at half of it).
"""

from __future__ import annotations

import math

import numpy as np

from swarmnav.controllers.prediction import time_to_collision_s
from swarmnav.models.geometry import segment_box_distances
from swarmnav.models.world import Pose2D


def world_to_robot(pose: Pose2D) -> np.ndarray:
    """(2, 2) matrix: ``row @ rotate`` turns a world-frame row vector into the robot's frame."""
    c, s = math.cos(pose.heading_rad), math.sin(pose.heading_rad)
    return np.array([[c, -s], [s, c]])


def candidate_times_s(pose: Pose2D, rotate: np.ndarray, candidates: np.ndarray, centres: np.ndarray,
                      velocities: np.ndarray, grown_radii_m: np.ndarray, boxes: np.ndarray,
                      box_clearance_m: float, horizon_s: float) -> np.ndarray:
    """(C,) time to collision of each robot-frame candidate velocity (inf: none within reach)."""
    ttc = np.full(len(candidates), np.inf)
    if len(centres):
        local = (centres - (pose.x_m, pose.y_m)) @ rotate
        ttc = time_to_collision_s(np.zeros(2), candidates, local, velocities @ rotate, grown_radii_m).min(axis=1)
    if len(boxes):
        p = np.array([pose.x_m, pose.y_m])
        ends = p + (candidates * horizon_s) @ rotate.T
        d = segment_box_distances(np.repeat(p[None, :], len(ends), axis=0), ends, boxes).min(axis=1)
        ttc = np.where(d < box_clearance_m, np.minimum(ttc, horizon_s * 0.5), ttc)
    return ttc


def chosen_candidate(ttc: np.ndarray, cost: np.ndarray, horizon_s: float) -> int:
    """The cheapest candidate free over the horizon, else the one that collides latest."""
    admissible = ttc >= horizon_s
    if admissible.any():
        return int(np.argmin(np.where(admissible, cost, np.inf)))
    return int(np.argmax(ttc - 1e-6 * cost))


def unicycle_command(speed_m_s: float, heading_error_rad: float, heading_gain: float, max_angular_rad_s: float,
                     turn_in_place_rad: float) -> tuple[float, float]:
    """(v, omega) that drives a candidate: turn toward its heading, advance along it unless far off."""
    if speed_m_s < 1e-9:
        return 0.0, 0.0
    omega = min(max(heading_gain * heading_error_rad, -max_angular_rad_s), max_angular_rad_s)
    v = speed_m_s * math.cos(heading_error_rad) if abs(heading_error_rad) < turn_in_place_rad else 0.0
    return v, omega
