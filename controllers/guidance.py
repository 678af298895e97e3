"""The global path as guidance for local navigators: a carrot point a lookahead ahead (no MuJoCo).

``dwa`` and ``velocity_obstacle`` do not follow the path exactly: they steer
toward a point ``lookahead_m`` further along it than the robot's projection,
and nearer obstacles bend their choice.  Progress along the path only moves
forward (the projection is searched from the last one onward), so a detour
does not send the carrot back.
"""

from __future__ import annotations

import math

import numpy as np

from swarmnav.models.world import Pose2D


class PathCarrot:
    """Projects the robot on a polyline and returns the point ``lookahead_m`` ahead of it."""

    def __init__(self, waypoints: np.ndarray, lookahead_m: float):
        pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
        if len(pts) == 1:
            pts = np.vstack([pts, pts])
        self.points = pts
        self.seg = np.diff(pts, axis=0)
        self.seg_len = np.hypot(self.seg[:, 0], self.seg[:, 1])
        self.cum = np.concatenate([[0.0], np.cumsum(self.seg_len)])
        self.lookahead_m = lookahead_m
        self.progress_m = 0.0

    @property
    def length_m(self) -> float:
        return float(self.cum[-1])

    def point_at(self, s_m: float) -> np.ndarray:
        s = min(max(s_m, 0.0), self.length_m)
        i = int(min(np.searchsorted(self.cum, s, side="right") - 1, len(self.seg) - 1))
        frac = (s - self.cum[i]) / self.seg_len[i] if self.seg_len[i] > 0 else 0.0
        return self.points[i] + frac * self.seg[i]

    def update(self, pose: Pose2D, window_m: float = 2.0) -> np.ndarray:
        """Advance the progress to the robot's projection (within ``window_m`` ahead) and return the carrot."""
        lo = int(min(max(np.searchsorted(self.cum, self.progress_m, side="right") - 1, 0), len(self.seg) - 1))
        hi = int(min(np.searchsorted(self.cum, self.progress_m + window_m, side="right"), len(self.seg)))
        hi = max(hi, lo + 1)
        a = self.points[lo:hi]
        d = self.seg[lo:hi]
        l2 = np.maximum(self.seg_len[lo:hi] ** 2, 1e-12)
        p = np.array([pose.x_m, pose.y_m])
        t = np.clip(((p - a) * d).sum(axis=1) / l2, 0.0, 1.0)
        near = a + t[:, None] * d
        k = int(np.argmin(np.hypot(*(near - p).T)))
        s = float(self.cum[lo + k] + t[k] * self.seg_len[lo + k])
        self.progress_m = max(self.progress_m, s)
        return self.point_at(self.progress_m + self.lookahead_m)

    def remaining_m(self, pose: Pose2D) -> float:
        """Straight distance from the robot to the path's end."""
        end = self.points[-1]
        return math.hypot(end[0] - pose.x_m, end[1] - pose.y_m)
