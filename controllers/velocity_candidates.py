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

SPEED_GROUPS = 2  # footprint_candidate_times_s: candidates tested together, each group against its fastest's reach
PRUNE_SLACK_M = 1e-3  # footprint_candidate_times_s: obstacles this much beyond a candidate's reach are still tested


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


def footprint_candidate_times_s(pose: Pose2D, rotate: np.ndarray, candidates: np.ndarray, headings_rad: np.ndarray,
                                discs_m: np.ndarray, centres: np.ndarray, velocities: np.ndarray,
                                grown_radii_m: np.ndarray, boxes: np.ndarray, box_clearance_m: float,
                                horizon_s: float) -> np.ndarray:
    """(C,) time to collision of each robot-frame candidate velocity for a chassis of several discs
    (``discs_m``, (n, 2) in the base frame), each candidate driven facing its own direction
    (``headings_rad``, robot frame): the earliest over the discs of :func:`candidate_times_s`' test with the
    disc's centre as the moving point (the grown radii are the obstacles' plus the discs' radius).

    Exact below ``horizon_s``; a time at or beyond it may read later (``inf``), which
    :func:`chosen_candidate` cannot tell apart: it reads only which times reach the horizon and, when none
    does, the times themselves.  Why (speed): a candidate is tested only against the obstacles that stand
    still and lie within the reach over the horizon of the fastest candidate of its group (:data:`SPEED_GROUPS`
    groups of consecutive speeds; that speed x ``horizon_s``, plus the discs' largest offset and
    :data:`PRUNE_SLACK_M`: from farther, ``|d + q t| >= |d| - |q| t`` keeps the disc out until after the
    horizon) and every moving one; the sums over x and y are written out as :func:`time_to_collision_s`
    writes them, the values of ``np.sum(axis=2)``.  The (C, N, 2) arrays over every obstacle cost 58 % of a
    BARN run's CPU (``tests/test_velocity_candidates_identity.py`` holds that version as the reference)."""
    ttc = np.full(len(candidates), np.inf)
    c, s = np.cos(headings_rad), np.sin(headings_rad)
    local = (centres - (pose.x_m, pose.y_m)) @ rotate if len(centres) else centres
    obstacle_v = velocities @ rotate if len(centres) else velocities
    if len(centres):
        moving = (obstacle_v[:, 0] != 0.0) | (obstacle_v[:, 1] != 0.0)
        gap = np.hypot(local[:, 0], local[:, 1]) - grown_radii_m                         # (N,) from the base
        speeds = np.hypot(candidates[:, 0], candidates[:, 1])
        # The candidates in SPEED_GROUPS groups of consecutive speeds (fewer NumPy calls, a little more work each).
        groups = [np.flatnonzero(np.isin(speeds, part)) for part in np.array_split(np.unique(speeds), SPEED_GROUPS)
                  if len(part)]
        lx, ly, ovx, ovy, r2 = local[:, 0], local[:, 1], obstacle_v[:, 0], obstacle_v[:, 1], grown_radii_m ** 2
    discs = np.asarray(discs_m, dtype=float).reshape(-1, 2)
    starts = [np.column_stack([dx * c - dy * s, dx * s + dy * c]) for dx, dy in discs]   # (C, 2) each, robot frame
    if len(centres):  # every disc at once: its rows below the others'
        offset_m = float(np.hypot(discs[:, 0], discs[:, 1]).max())
        sx_all, sy_all = np.stack([st[:, 0] for st in starts]), np.stack([st[:, 1] for st in starts])  # (D, C)
        for group in groups:
            speed = float(speeds[group].max())
            near = np.flatnonzero(moving | (gap <= speed * horizon_s + offset_m + PRUNE_SLACK_M))
            if not len(near):
                continue
            sx, sy = sx_all[:, group].reshape(-1, 1), sy_all[:, group].reshape(-1, 1)            # (D G, 1)
            ux = np.tile(candidates[group, 0], len(discs))[:, None]
            uy = np.tile(candidates[group, 1], len(discs))[:, None]
            ddx, ddy = lx[near] - sx, ly[near] - sy                                           # (D G, M)
            qx, qy = ovx[near] - ux, ovy[near] - uy
            a = qx * qx + qy * qy
            b = 2.0 * ((0.0 + ddx * qx) + ddy * qy)
            cc = (ddx * ddx + ddy * ddy) - r2[near]
            disc = b * b - 4.0 * a * cc
            with np.errstate(divide="ignore", invalid="ignore"):
                t = (-b - np.sqrt(np.maximum(disc, 0.0))) / (2.0 * a)
            t = np.where((disc >= 0.0) & (a > 1e-12) & (t >= 0.0), t, np.inf)
            t = np.where(cc <= 0.0, np.where(b >= 0.0, np.inf, 0.0), t)
            ttc[group] = np.minimum(ttc[group], t.min(axis=1).reshape(len(discs), -1).min(axis=0))
    if len(boxes):
        for start in starts:
            p = np.array([pose.x_m, pose.y_m]) + start @ rotate.T
            ends = p + (candidates * horizon_s) @ rotate.T
            box_gap = segment_box_distances(p, ends, boxes).min(axis=1)
            ttc = np.where(box_gap < box_clearance_m, np.minimum(ttc, horizon_s * 0.5), ttc)
    return ttc
