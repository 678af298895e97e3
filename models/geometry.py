"""Exact 2-D clearance tests between segments and discs, vectorised with NumPy.

These are the one feasibility check every planner and the CLI use: a path is
collision-free when every segment keeps at least the inflated radius from every
disc centre.  No sampling, so a segment cannot slip between samples.
"""

from __future__ import annotations

import math

import numpy as np


def segment_disc_distances(a: np.ndarray, b: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """Distance from each segment to each disc centre.

    Args:
        a: (S, 2) segment start points in metres.
        b: (S, 2) segment end points in metres.
        centres: (C, 2) disc centres in metres.

    Returns:
        (S, C) Euclidean distance from segment s to centre c.
    """
    a = np.asarray(a, dtype=float).reshape(-1, 2)
    b = np.asarray(b, dtype=float).reshape(-1, 2)
    centres = np.asarray(centres, dtype=float).reshape(-1, 2)
    ab = b - a                                            # (S, 2)
    ab_len2 = np.einsum("ij,ij->i", ab, ab)               # (S,)
    ac = centres[None, :, :] - a[:, None, :]              # (S, C, 2)
    safe_len2 = np.where(ab_len2 > 0.0, ab_len2, 1.0)
    t = np.einsum("scj,sj->sc", ac, ab) / safe_len2[:, None]
    t = np.where(ab_len2[:, None] > 0.0, np.clip(t, 0.0, 1.0), 0.0)
    nearest = a[:, None, :] + t[..., None] * ab[:, None, :]
    return np.linalg.norm(centres[None, :, :] - nearest, axis=-1)


def polyline_clearance_m(waypoints: np.ndarray, centres: np.ndarray, radii_m: np.ndarray) -> float:
    """Smallest signed gap between a polyline and a set of discs.

    Args:
        waypoints: (N, 2) polyline vertices in metres, N >= 1.
        centres: (C, 2) disc centres.
        radii_m: (C,) disc radii (already inflated where the caller wants it).

    Returns:
        min over segments and discs of (distance - radius); ``inf`` with no discs.
        Negative means the polyline enters a disc.
    """
    centres = np.asarray(centres, dtype=float).reshape(-1, 2)
    if centres.shape[0] == 0:
        return float("inf")
    pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    if pts.shape[0] == 1:
        pts = np.vstack([pts, pts])
    dist = segment_disc_distances(pts[:-1], pts[1:], centres)
    return float(np.min(dist - np.asarray(radii_m, dtype=float)[None, :]))


def polyline_length_m(waypoints: np.ndarray) -> float:
    """Sum of segment lengths of an (N, 2) polyline."""
    pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    if pts.shape[0] < 2:
        return 0.0
    return float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))


def segment_box_distances(a: np.ndarray, b: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """Distance from each segment to each axis-aligned box (0 where they touch or cross).

    Two disjoint convex sets are closest at a vertex of one of them, so the
    distance is the smallest of: each segment end to the box, and each box
    corner to the segment.  Crossing is found with the slab test.

    Args:
        a: (S, 2) segment start points in metres.
        b: (S, 2) segment end points in metres.
        boxes: (B, 4) rows of (x_min, y_min, x_max, y_max).

    Returns:
        (S, B) Euclidean distance from segment s to box k.

    See also :func:`segment_box_distance`, the same computation for one
    segment and one box in plain Python.
    """
    a = np.asarray(a, dtype=float).reshape(-1, 2)
    b = np.asarray(b, dtype=float).reshape(-1, 2)
    boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
    lo = boxes[None, :, 0:2]                               # (1, B, 2)
    hi = boxes[None, :, 2:4]

    def point_box(p: np.ndarray) -> np.ndarray:           # (S, 2) -> (S, B)
        d = np.maximum(np.maximum(lo - p[:, None, :], p[:, None, :] - hi), 0.0)
        return np.hypot(d[..., 0], d[..., 1])

    best = np.minimum(point_box(a), point_box(b))
    corners = np.stack([boxes[:, [0, 1]], boxes[:, [2, 1]], boxes[:, [0, 3]], boxes[:, [2, 3]]], axis=1)
    for k in range(4):                                     # box corners to segments
        dist = segment_disc_distances(a, b, corners[:, k, :])
        best = np.minimum(best, dist)
    # Slab test: the segment a + t (b - a), t in [0, 1], crosses the box.
    d = (b - a)[:, None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (lo - a[:, None, :]) / d
        t2 = (hi - a[:, None, :]) / d
    parallel = d == 0.0
    inside_slab = (a[:, None, :] >= lo) & (a[:, None, :] <= hi)
    t_near = np.where(parallel, np.where(inside_slab, -np.inf, np.inf), np.minimum(t1, t2))
    t_far = np.where(parallel, np.where(inside_slab, np.inf, -np.inf), np.maximum(t1, t2))
    # Element-wise over the two axes: a reduction over a last axis of length 2 is slow in NumPy.
    enter = np.maximum(np.maximum(t_near[..., 0], t_near[..., 1]), 0.0)
    leave = np.minimum(np.minimum(t_far[..., 0], t_far[..., 1]), 1.0)
    return np.where(enter <= leave, 0.0, best)


def segment_box_pair_distances(a: np.ndarray, b: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """Distance from segment k to box k, for P (segment, box) pairs: :func:`segment_box_distances`'s
    construction, operation for operation, on pairs instead of every segment against every box.

    Args:
        a, b: (P, 2) segment ends in metres.
        boxes: (P, 4) rows of (x_min, y_min, x_max, y_max), one per segment.

    Returns:
        (P,) distances, equal to the matching entries of :func:`segment_box_distances` (the tests
        compare them bit for bit).
    """
    a = np.asarray(a, dtype=float).reshape(-1, 2)
    b = np.asarray(b, dtype=float).reshape(-1, 2)
    boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
    lo, hi = boxes[:, 0:2], boxes[:, 2:4]

    def point_box(p: np.ndarray) -> np.ndarray:           # (P, 2) -> (P,)
        d = np.maximum(np.maximum(lo - p, p - hi), 0.0)
        return np.hypot(d[:, 0], d[:, 1])

    best = np.minimum(point_box(a), point_box(b))
    # Each pair's four box corners to its segment, as segment_disc_distances measures a centre.
    corners = boxes[:, [0, 1, 2, 1, 0, 3, 2, 3]].reshape(-1, 4, 2)
    ab = b - a
    ab_len2 = np.einsum("ij,ij->i", ab, ab)
    ac = corners - a[:, None, :]                           # (P, 4, 2)
    safe_len2 = np.where(ab_len2 > 0.0, ab_len2, 1.0)
    t = np.einsum("scj,sj->sc", ac, ab) / safe_len2[:, None]
    t = np.where(ab_len2[:, None] > 0.0, np.clip(t, 0.0, 1.0), 0.0)
    nearest = a[:, None, :] + t[..., None] * ab[:, None, :]
    corner = np.linalg.norm(corners - nearest, axis=-1)    # (P, 4)
    for k in range(4):
        best = np.minimum(best, corner[:, k])
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (lo - a) / ab
        t2 = (hi - a) / ab
    parallel = ab == 0.0
    inside_slab = (a >= lo) & (a <= hi)
    t_near = np.where(parallel, np.where(inside_slab, -np.inf, np.inf), np.minimum(t1, t2))
    t_far = np.where(parallel, np.where(inside_slab, np.inf, -np.inf), np.maximum(t1, t2))
    enter = np.maximum(np.maximum(t_near[:, 0], t_near[:, 1]), 0.0)
    leave = np.minimum(np.minimum(t_far[:, 0], t_far[:, 1]), 1.0)
    return np.where(enter <= leave, 0.0, best)


def segment_disc_distance(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> float:
    """Distance from the segment (ax, ay)-(bx, by) to the point (cx, cy), on plain floats.

    The same construction as :func:`segment_disc_distances` (project the centre onto the
    segment, clamp to its ends), for a caller that asks about one segment at a time (OMPL's
    validity callbacks), where a NumPy call's fixed cost would dominate.  The tests check
    that both agree.
    """
    dx = bx - ax
    dy = by - ay
    len2 = dx * dx + dy * dy
    t = 0.0
    if len2 > 0.0:
        t = min(max(((cx - ax) * dx + (cy - ay) * dy) / len2, 0.0), 1.0)
    return math.hypot(cx - (ax + t * dx), cy - (ay + t * dy))


def segment_box_distance(ax: float, ay: float, bx: float, by: float,
                         x_min: float, y_min: float, x_max: float, y_max: float) -> float:
    """Distance from the segment (ax, ay)-(bx, by) to one axis-aligned box (0 where they touch or cross).

    The same construction as :func:`segment_box_distances` (slab test for
    crossing, else the smallest of end-to-box and corner-to-segment), on plain
    floats.  Both exist because they serve different callers: the vectorised
    one answers many segments against many boxes in one NumPy call (shortcut
    fans, path clearance), while a search loop such as Theta*'s asks about one
    segment and the two or three boxes near it thousands of times, where the
    fixed cost of a NumPy call (tens of microseconds) would dominate and this
    takes about two.  The tests check that both agree.
    """
    dx = bx - ax
    dy = by - ay
    # Slab test: a + t (b - a), t in [0, 1], crosses the box.
    enter, leave = 0.0, 1.0
    crosses = True
    for p, d, lo, hi in ((ax, dx, x_min, x_max), (ay, dy, y_min, y_max)):
        if d == 0.0:
            if p < lo or p > hi:
                crosses = False
                break
        else:
            t1 = (lo - p) / d
            t2 = (hi - p) / d
            if t1 > t2:
                t1, t2 = t2, t1
            enter = max(enter, t1)
            leave = min(leave, t2)
    if crosses and enter <= leave:
        return 0.0
    # Segment ends to the box.
    best = math.hypot(max(x_min - ax, ax - x_max, 0.0), max(y_min - ay, ay - y_max, 0.0))
    best = min(best, math.hypot(max(x_min - bx, bx - x_max, 0.0), max(y_min - by, by - y_max, 0.0)))
    # Box corners to the segment.
    len2 = dx * dx + dy * dy
    for cx, cy in ((x_min, y_min), (x_max, y_min), (x_min, y_max), (x_max, y_max)):
        t = 0.0
        if len2 > 0.0:
            t = min(max(((cx - ax) * dx + (cy - ay) * dy) / len2, 0.0), 1.0)
        best = min(best, math.hypot(cx - (ax + t * dx), cy - (ay + t * dy)))
    return best
