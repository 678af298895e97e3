"""A minimal ``detector`` sensing model: every moving obstacle whose surface lies within range.

Exact centre and radius, and the velocity from the last control period (a
backward difference: the robot never sees where an obstacle will be), as seed 003 §2.1 assumes its sensors report
direction, step length, size and shape.  Placeholder for the navigation work's
detector (issue 10); the track id is the obstacle's index among the moving ones.
"""

from __future__ import annotations

import numpy as np

from swarmnav.controllers.navigator import DetectedObstacle


def detect(track_m: np.ndarray, step: int, dt_s: float, radii_m: np.ndarray, x_m: float, y_m: float,
           range_m: float) -> tuple[DetectedObstacle, ...]:
    """Detections at control step ``step`` from the (T, M, 2) obstacle track."""
    if track_m.shape[1] == 0:
        return ()
    here = track_m[step]
    velocity = (here - track_m[step - 1]) / dt_s if step > 0 else np.zeros_like(here)
    gap = np.hypot(here[:, 0] - x_m, here[:, 1] - y_m) - radii_m
    return tuple(DetectedObstacle(float(here[i, 0]), float(here[i, 1]), float(radii_m[i]),
                                  float(velocity[i, 0]), float(velocity[i, 1]), int(i))
                 for i in np.flatnonzero(gap <= range_m))
