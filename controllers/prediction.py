"""Where sensed obstacles will be: swept footprints, the path ahead, time to collision (no MuJoCo).

Every online navigator predicts a sensed obstacle forward with its estimated
velocity held constant (the robot never sees the true future).  The helpers
here are shared by ``replan``, ``dstar_replan``, ``velocity_obstacle`` and the
safety filter, so they all mean the same thing by "in the way".
"""

from __future__ import annotations

import math

import numpy as np

from swarmnav.controllers.navigator import DetectedObstacle
from swarmnav.models.geometry import segment_disc_distances
from swarmnav.models.world import Disc, Pose2D

MAX_SWEEP_DISCS = 16


def detection_arrays(detections: tuple[DetectedObstacle, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(N, 2) centres, (N, 2) velocities and (N,) radii of the detections."""
    if not detections:
        return np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0)
    arr = np.array([(d.x_m, d.y_m, d.vx_m_s, d.vy_m_s, d.radius_m) for d in detections], dtype=float)
    return arr[:, :2], arr[:, 2:4], arr[:, 4]


def swept_discs(detections: tuple[DetectedObstacle, ...], horizon_s: float) -> list[Disc]:
    """Each detection's footprint swept along its velocity over ``horizon_s``, as a chain of discs.

    Consecutive discs are at most half a radius apart, so the chain covers the
    swept capsule but for scallops no deeper than r (1 - sqrt(15/16)) ~ 3 % of r.
    """
    counts = [min(MAX_SWEEP_DISCS, int(math.ceil(math.hypot(d.vx_m_s, d.vy_m_s) * horizon_s
                                                  / max(0.5 * d.radius_m, 1e-6))) + 1) for d in detections]
    if not horizon_s > 0.0 or max(counts, default=1) == 1:
        return swept_discs_reference(detections, horizon_s, counts)
    # All chains' times at once, as np.linspace(0, horizon_s, count) makes each: k * (horizon_s / (count - 1))
    # + 0.0, the last one horizon_s exactly.
    many = np.array([c for c in counts if c > 1])
    ends = np.cumsum(many)
    k = np.arange(ends[-1]) - np.repeat(ends - many, many)
    t = k * np.repeat(horizon_s / (many - 1), many) + 0.0
    t[ends - 1] = horizon_s
    moving = [(d.x_m, d.y_m, d.vx_m_s, d.vy_m_s) for d, c in zip(detections, counts) if c > 1]
    x, y, vx, vy = np.repeat(np.array(moving, dtype=float), many, axis=0).T
    xs, ys = x + vx * t, y + vy * t
    out: list[Disc] = []
    at = 0
    for d, count in zip(detections, counts):
        if count > 1:
            out.extend(Disc(px, py, d.radius_m) for px, py in zip(xs[at:at + count], ys[at:at + count]))
            at += count
        else:
            out.append(Disc(d.x_m + d.vx_m_s * 0.0, d.y_m + d.vy_m_s * 0.0, d.radius_m))
    return out


def swept_discs_reference(detections: tuple[DetectedObstacle, ...], horizon_s: float,
                          counts: list[int] | None = None) -> list[Disc]:
    """:func:`swept_discs` one detection at a time (its reference, and its path for a zero horizon)."""
    out: list[Disc] = []
    for i, d in enumerate(detections):
        travel = math.hypot(d.vx_m_s, d.vy_m_s) * horizon_s
        count = min(MAX_SWEEP_DISCS, int(math.ceil(travel / max(0.5 * d.radius_m, 1e-6))) + 1) \
            if counts is None else counts[i]
        for t in np.linspace(0.0, horizon_s, count) if count > 1 else (0.0,):
            out.append(Disc(d.x_m + d.vx_m_s * t, d.y_m + d.vy_m_s * t, d.radius_m))
    return out


def path_ahead(pose: Pose2D, waypoints: np.ndarray, index: int, lookahead_m: float) -> np.ndarray:
    """The polyline from the robot through the waypoints still to come, cut at ``lookahead_m``."""
    pts = [np.array([pose.x_m, pose.y_m])]
    left = lookahead_m
    for p in np.asarray(waypoints, dtype=float)[index:]:
        step = float(np.hypot(*(p - pts[-1])))
        if step >= left:
            pts.append(pts[-1] + (p - pts[-1]) * (left / max(step, 1e-12)))
            break
        pts.append(p)
        left -= step
    if len(pts) == 1:
        pts.append(pts[0])
    return np.array(pts)


def polyline_gap_m(polyline: np.ndarray, discs: list[Disc], inflation_m: float) -> float:
    """Smallest gap between a polyline and the discs grown by ``inflation_m`` (inf with none)."""
    if not discs:
        return math.inf
    centres = np.array([(d.x_m, d.y_m) for d in discs])
    radii = np.array([d.radius_m for d in discs]) + inflation_m
    pts = np.asarray(polyline, dtype=float)
    dist = segment_disc_distances(pts[:-1], pts[1:], centres)  # (S, C)
    return float(np.min(dist - radii[None, :]))


def time_to_collision_s(position_m: np.ndarray, velocities_m_s: np.ndarray, centres_m: np.ndarray,
                        obstacle_velocities_m_s: np.ndarray, radii_m: np.ndarray) -> np.ndarray:
    """(V, N) first time at which a point moving from ``position_m`` with each of V constant velocities
    comes within ``radii_m`` of each of N discs moving with constant velocities (inf if never).

    A point already within a disc gets 0 if the relative motion closes in, inf if it separates.

    Solves |d + q t| = R for the smallest t >= 0, d the disc's centre relative to the
    point and q = w - u the relative velocity (the velocity obstacle's defining test,
    Fiorini & Shiller 1998, Eq. 4, with a time horizon applied by the caller).
    """
    # By components: the values of the sums over x and y by ``np.sum(axis=2)``, which is (0.0 + x) + y (only the
    # sign of a zero sum can differ from x + y, and a sum of squares has none) (tests/test_prediction_identity.py).
    u = np.asarray(velocities_m_s, dtype=float).reshape(-1, 2)
    d = (np.asarray(centres_m, dtype=float) - np.asarray(position_m, dtype=float)).reshape(-1, 2)
    w = np.asarray(obstacle_velocities_m_s, dtype=float).reshape(-1, 2)
    r = np.asarray(radii_m, dtype=float).reshape(1, -1)
    dx, dy = d[:, 0], d[:, 1]
    qx = w[:, 0] - u[:, 0:1]                                                   # (V, N)
    qy = w[:, 1] - u[:, 1:2]
    a = qx * qx + qy * qy
    b = 2.0 * ((0.0 + dx * qx) + dy * qy)
    c = (dx * dx + dy * dy) - r * r                                            # (1, N)
    disc = b * b - 4.0 * a * c
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (-b - np.sqrt(np.maximum(disc, 0.0))) / (2.0 * a)
    t = np.where((disc >= 0.0) & (a > 1e-12) & (t >= 0.0), t, np.inf)
    return np.where(c <= 0.0, np.where(b >= 0.0, np.inf, 0.0), t)


class LocalObstacles:
    """The known map's discs and boxes near the robot, plus the sensed obstacles, as arrays.

    Built once from the map problem; :meth:`near` returns what lies within
    ``reach_m`` of a point: disc centres (N, 2), their velocities (N, 2, zero for
    the map's), radii (N,), and boxes (B, 4) as (x_min, y_min, x_max, y_max).
    """

    def __init__(self, map_centres_m: np.ndarray, map_radii_m: np.ndarray, map_boxes_m: np.ndarray):
        self.centres = np.asarray(map_centres_m, dtype=float).reshape(-1, 2)
        self.radii = np.asarray(map_radii_m, dtype=float).reshape(-1)
        self.boxes = np.asarray(map_boxes_m, dtype=float).reshape(-1, 4)

    def near(self, x_m: float, y_m: float, reach_m: float, detections: tuple[DetectedObstacle, ...]
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        if len(self.centres):
            keep = np.hypot(self.centres[:, 0] - x_m, self.centres[:, 1] - y_m) - self.radii <= reach_m
            centres, radii = self.centres[keep], self.radii[keep]
            velocities = np.zeros_like(centres)
            if detections:
                dc, dv, dr = detection_arrays(detections)
                centres, velocities = np.vstack([centres, dc]), np.vstack([velocities, dv])
                radii = np.concatenate([radii, dr])
        else:  # no disc on the map (the dynamic suite): only the sensed ones
            centres, velocities, radii = detection_arrays(detections)
        boxes = self.boxes
        if len(boxes):
            gap_x = np.maximum(np.maximum(boxes[:, 0] - x_m, x_m - boxes[:, 2]), 0.0)
            gap_y = np.maximum(np.maximum(boxes[:, 1] - y_m, y_m - boxes[:, 3]), 0.0)
            boxes = boxes[np.hypot(gap_x, gap_y) <= reach_m]
        return centres, velocities, radii, boxes
