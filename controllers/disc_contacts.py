"""Which points lie inside any of many discs, exactly as the brute-force test decides it, found through a k-d tree.

``dwa`` asks, for every point of every arc in its window, whether the robot's disc there overlaps an obstacle:
``hypot(px - ox, py - oy) < r`` for some obstacle (centre ``ox, oy``, ``r`` its radius plus the robot's).  On a
sensed map the obstacles are the occupied cells near the robot, thousands of them, and the (points x
obstacles) distance array cost ~90 % of a BARN run's CPU.  :func:`inside_any` answers the same question from
each point's nearest centre (:class:`scipy.spatial.cKDTree`, one query per distinct radius) and settles the
points whose nearest distance lies within :data:`BAND_M` of the radius by the brute-force expression itself,
so the answer is the brute-force answer bit for bit (the tree's distances differ from ``np.hypot``'s by a few
units in the last place, far inside the band).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

BAND_M = 1e-9          # nearest distances this close to a radius are recomputed with np.hypot
BRUTE_FORCE_MAX = 32   # with at most this many discs the (points x discs) array is cheaper than a tree


def inside_any(px: np.ndarray, py: np.ndarray, ox: np.ndarray, oy: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Boolean array shaped like ``px``: ``np.hypot(px - ox[n], py - oy[n]) < radius[n]`` for some n.

    ``ox``, ``oy``, ``radius``: (N,) the discs' centres and radii, in the points' frame."""
    shape = np.shape(px)
    if len(ox) <= BRUTE_FORCE_MAX:
        return _brute(np.ravel(px), np.ravel(py), ox, oy, radius).reshape(shape)
    points = np.column_stack([np.ravel(px), np.ravel(py)])
    out = np.zeros(len(points), dtype=bool)
    for r in np.unique(radius):
        mine = radius == r
        cx, cy = ox[mine], oy[mine]
        nearest, _ = cKDTree(np.column_stack([cx, cy])).query(points, k=1, distance_upper_bound=float(r) + BAND_M)
        out |= nearest < r - BAND_M
        close = np.flatnonzero(np.abs(nearest - r) <= BAND_M)
        if len(close):
            out[close] |= _brute(points[close, 0], points[close, 1], cx, cy, radius[mine])
    return out.reshape(shape)


def _brute(px: np.ndarray, py: np.ndarray, ox: np.ndarray, oy: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """(P,) the test itself, over every (point, disc) pair."""
    return (np.hypot(px[:, None] - ox[None, :], py[:, None] - oy[None, :]) < radius[None, :]).any(axis=1)
