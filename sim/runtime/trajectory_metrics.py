"""Shape metrics of a path or a driven trajectory: the papers' bends and turns."""

from __future__ import annotations

import math

import numpy as np

BEND_TOLERANCE_RAD = 1e-6  # a turn smaller than this between two segments is no bend
TURN_THRESHOLD_RAD = math.radians(22.5)


def bends(waypoints: np.ndarray) -> int:
    """Interior waypoints where the heading changes (IACO, Gong et al. 2022, Table 3 'number of bends')."""
    if len(waypoints) < 3:
        return 0
    seg = np.diff(waypoints, axis=0)
    seg = seg[np.hypot(seg[:, 0], seg[:, 1]) > 0]
    if len(seg) < 2:
        return 0
    heading = np.arctan2(seg[:, 1], seg[:, 0])
    turn = np.abs((np.diff(heading) + np.pi) % (2 * np.pi) - np.pi)
    return int(np.count_nonzero(turn > BEND_TOLERANCE_RAD))


def count_turns(poses: np.ndarray, spacing_m: float, threshold_rad: float = TURN_THRESHOLD_RAD) -> int:
    """Heading changes above ``threshold_rad`` along the driven path, resampled every ``spacing_m``."""
    xy = np.asarray(poses, dtype=float)[:, :2]
    seg = np.linalg.norm(np.diff(xy, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    if arc[-1] < 2 * spacing_m:
        return 0
    s = np.arange(0.0, arc[-1], spacing_m)
    pts = np.column_stack([np.interp(s, arc, xy[:, 0]), np.interp(s, arc, xy[:, 1])])
    d = np.diff(pts, axis=0)
    heading = np.arctan2(d[:, 1], d[:, 0])
    change = np.abs((np.diff(heading) + math.pi) % (2 * math.pi) - math.pi)
    return int(np.count_nonzero(change > threshold_rad))
