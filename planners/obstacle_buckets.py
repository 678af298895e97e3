"""Buckets of obstacles for fast exact segment tests: only the obstacles near a segment are measured.

:func:`planners.grid_shortcut.exact_shortcut` asks, many times, whether fans of
segments keep the inflation from every obstacle.  Measuring every segment
against every obstacle (:meth:`planners.problem.Problem.segment_clearances_m`)
is exact but costs the number of obstacles per segment: 10,000 discs make a
shortcut take seconds, and the NumPy calls of the general segment-box distance
dominate on the small bundled maps.

:class:`ObstacleBuckets` files each obstacle (a disc with its inflated radius, or
a box grown by the inflation) under every square *bucket* its bounding box meets.
A segment that comes within reach of an obstacle has its nearest point inside that
obstacle's grown bounding box, so in a bucket that lists the obstacle and that the
segment passes through; the buckets a segment passes through are those whose
centre lies within half a bucket diagonal of it.  Only those (segment, obstacle)
pairs are measured, with the same constructions as
:func:`models.geometry.segment_disc_distances` and
:func:`models.geometry.segment_box_distances`, one pair per element
(:func:`pair_disc_distances`, :func:`pair_box_distances`); the tests compare them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Most buckets of one kind of obstacle.
MAX_BUCKETS = 1 << 18


def pair_disc_distances(ax, ay, bx, by, cx, cy) -> np.ndarray:
    """Distance from segment ``k`` (a -> b) to point ``k`` (c), elementwise over equal-length arrays."""
    dx = bx - ax
    dy = by - ay
    length2 = dx * dx + dy * dy
    px = cx - ax
    py = cy - ay
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (px * dx + py * dy) / length2
    t = np.where(length2 > 0.0, np.clip(t, 0.0, 1.0), 0.0)
    return np.hypot(px - t * dx, py - t * dy)


def pair_box_distances(ax, ay, bx, by, boxes: np.ndarray) -> np.ndarray:
    """Distance from segment ``k`` to box ``k`` (rows of x_min, y_min, x_max, y_max), 0 where
    they touch or cross: the smallest of the ends to the box and the corners to the segment,
    unless the slab test finds a crossing (:func:`models.geometry.segment_box_distances`)."""
    x0, y0, x1, y1 = boxes[:, 0], boxes[:, 1], boxes[:, 2], boxes[:, 3]
    best = np.minimum(np.hypot(np.maximum(np.maximum(x0 - ax, ax - x1), 0.0),
                               np.maximum(np.maximum(y0 - ay, ay - y1), 0.0)),
                      np.hypot(np.maximum(np.maximum(x0 - bx, bx - x1), 0.0),
                               np.maximum(np.maximum(y0 - by, by - y1), 0.0)))
    for cx, cy in ((x0, y0), (x1, y0), (x0, y1), (x1, y1)):
        best = np.minimum(best, pair_disc_distances(ax, ay, bx, by, cx, cy))
    enter = np.zeros_like(best)
    leave = np.ones_like(best)
    for p, d, lo, hi in ((ax, bx - ax, x0, x1), (ay, by - ay, y0, y1)):
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = (lo - p) / d
            t2 = (hi - p) / d
        parallel = d == 0.0
        inside = (p >= lo) & (p <= hi)
        enter = np.maximum(enter, np.where(parallel, np.where(inside, -np.inf, np.inf), np.minimum(t1, t2)))
        leave = np.minimum(leave, np.where(parallel, np.where(inside, np.inf, -np.inf), np.maximum(t1, t2)))
    return np.where(enter <= leave, 0.0, best)


@dataclass(frozen=True, eq=False)
class ObstacleBuckets:
    """Obstacles filed by square buckets (see the module docstring).

    Attributes:
        extents: (N, 4) each obstacle's grown bounding box (x_min, y_min, x_max, y_max).
        origin_m: (2,) lower-left corner of the buckets.
        bucket_m: side of a bucket.
        shape: (nx, ny) buckets per axis.
        starts: (nx * ny + 1,) where bucket ``ix * ny + iy``'s obstacles begin in ``items``.
        items: obstacle indices, bucket by bucket.
    """

    extents: np.ndarray
    origin_m: np.ndarray
    bucket_m: float
    shape: tuple[int, int]
    starts: np.ndarray
    items: np.ndarray

    @classmethod
    def build(cls, extents: np.ndarray) -> "ObstacleBuckets":
        """Buckets over obstacles with grown bounding boxes ``extents`` (N, 4), N >= 1."""
        extents = np.asarray(extents, dtype=float).reshape(-1, 4)
        low = extents[:, :2].min(axis=0)
        high = extents[:, 2:].max(axis=0)
        span = np.maximum(high - low, 1e-9)
        sizes = np.maximum(extents[:, 2:] - extents[:, :2], 1e-9)
        bucket = max(2.0 * float(np.median(sizes)), float(max(span)) / 512.0)
        while math.ceil(span[0] / bucket) * math.ceil(span[1] / bucket) > MAX_BUCKETS:
            bucket *= 1.5
        nx, ny = (max(int(math.ceil(s / bucket)), 1) for s in span)
        first = np.clip(np.floor((extents[:, :2] - low) / bucket), 0, [nx - 1, ny - 1]).astype(np.int64)
        last = np.clip(np.floor((extents[:, 2:] - low) / bucket), 0, [nx - 1, ny - 1]).astype(np.int64)
        spans_x = last[:, 0] - first[:, 0] + 1
        spans_y = last[:, 1] - first[:, 1] + 1
        per = spans_x * spans_y
        owner = np.repeat(np.arange(len(extents)), per)
        offset = np.arange(owner.size) - np.repeat(np.cumsum(per) - per, per)
        flat = (first[owner, 0] + offset // spans_y[owner]) * ny + first[owner, 1] + offset % spans_y[owner]
        order = np.argsort(flat, kind="stable")
        counts = np.bincount(flat, minlength=nx * ny)
        starts = np.concatenate([[0], np.cumsum(counts)])
        return cls(extents, low, bucket, (nx, ny), starts, owner[order])

    def candidate_pairs(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(segment index, obstacle index) pairs to measure for segments ``a[k] -> b[k]`` (K, 2):
        every obstacle that may come within its grown bounding box of the segment (with repeats)."""
        nx, ny = self.shape
        lo = (np.minimum(a, b) - self.origin_m) / self.bucket_m
        hi = (np.maximum(a, b) - self.origin_m) / self.bucket_m
        first = np.clip(np.floor(lo), 0, [nx - 1, ny - 1]).astype(np.int64)
        last = np.clip(np.floor(hi), 0, [nx - 1, ny - 1]).astype(np.int64)
        outside = np.any((hi < 0) | (lo >= [nx, ny]), axis=1)
        spans_x = last[:, 0] - first[:, 0] + 1
        spans_y = last[:, 1] - first[:, 1] + 1
        per = np.where(outside, 0, spans_x * spans_y)
        seg = np.repeat(np.arange(len(a)), per)
        offset = np.arange(seg.size) - np.repeat(np.cumsum(per) - per, per)
        bx_ = first[seg, 0] + offset // spans_y[seg]
        by_ = first[seg, 1] + offset % spans_y[seg]
        # Keep the buckets the segment passes through: centre within half a diagonal (and a margin).
        centre_x = self.origin_m[0] + (bx_ + 0.5) * self.bucket_m
        centre_y = self.origin_m[1] + (by_ + 0.5) * self.bucket_m
        near = pair_disc_distances(a[seg, 0], a[seg, 1], b[seg, 0], b[seg, 1], centre_x, centre_y)
        keep = near <= self.bucket_m * (math.sqrt(0.5) + 1e-6)
        seg, flat = seg[keep], (bx_ * ny + by_)[keep]
        lengths = self.starts[flat + 1] - self.starts[flat]
        pair_seg = np.repeat(seg, lengths)
        where = np.arange(pair_seg.size) - np.repeat(np.cumsum(lengths) - lengths, lengths) \
            + np.repeat(self.starts[flat], lengths)
        obstacle = self.items[where]
        # Drop the pairs whose bounding boxes do not meet.
        ext = self.extents[obstacle]
        lo_pts = np.minimum(a[pair_seg], b[pair_seg])
        hi_pts = np.maximum(a[pair_seg], b[pair_seg])
        meet = ((ext[:, 0] <= hi_pts[:, 0]) & (ext[:, 2] >= lo_pts[:, 0])
                & (ext[:, 1] <= hi_pts[:, 1]) & (ext[:, 3] >= lo_pts[:, 1]))
        return pair_seg[meet], obstacle[meet]


@dataclass(frozen=True, eq=False)
class ClearanceBuckets:
    """The inflated discs and boxes of a problem in :class:`ObstacleBuckets`, for yes/no segment tests.

    Attributes:
        centres_m, radii_m: (C, 2), (C,) discs and their inflated radii.
        boxes_m: (B, 4) boxes, not inflated; ``inflation_m`` their reach.
        discs, boxes: the buckets (None without discs / boxes).
    """

    centres_m: np.ndarray
    radii_m: np.ndarray
    boxes_m: np.ndarray
    inflation_m: float
    discs: ObstacleBuckets | None
    boxes: ObstacleBuckets | None

    @classmethod
    def of(cls, centres_m: np.ndarray, radii_m: np.ndarray, boxes_m: np.ndarray,
           inflation_m: float) -> "ClearanceBuckets":
        centres = np.asarray(centres_m, dtype=float).reshape(-1, 2)
        radii = np.asarray(radii_m, dtype=float).reshape(-1)
        boxes = np.asarray(boxes_m, dtype=float).reshape(-1, 4)
        # The grown boxes carry a margin far above rounding, so a pair at exactly the reach is kept.
        pad = 1e-9 * (1.0 + float(np.abs(np.concatenate([centres.ravel(), boxes.ravel(), [0.0]])).max()))
        discs = (ObstacleBuckets.build(np.hstack([centres - radii[:, None] - pad, centres + radii[:, None] + pad]))
                 if len(centres) else None)
        reach = inflation_m + pad
        grown = (ObstacleBuckets.build(np.hstack([boxes[:, :2] - reach, boxes[:, 2:] + reach]))
                 if len(boxes) else None)
        return cls(centres, radii, boxes, float(inflation_m), discs, grown)

    def segments_clear(self, a: np.ndarray, b: np.ndarray, tolerance_m: float = 1e-9) -> np.ndarray:
        """(K,) whether each segment ``a[k] -> b[k]`` keeps at least the inflated radius from every
        disc and the inflation from every box, less ``tolerance_m`` (the decision of
        :meth:`planners.problem.Problem.segment_clearances_m` ``>= -tolerance_m``)."""
        a, b = np.broadcast_arrays(np.asarray(a, dtype=float).reshape(-1, 2), np.asarray(b, dtype=float).reshape(-1, 2))
        ok = np.ones(a.shape[0], dtype=bool)
        if self.discs is not None and ok.size:
            seg, disc = self.discs.candidate_pairs(a, b)
            if seg.size:
                gap = pair_disc_distances(a[seg, 0], a[seg, 1], b[seg, 0], b[seg, 1],
                                          self.centres_m[disc, 0], self.centres_m[disc, 1]) - self.radii_m[disc]
                ok[seg[gap < -tolerance_m]] = False
        if self.boxes is not None and ok.any():
            seg, box = self.boxes.candidate_pairs(a, b)
            if seg.size:
                gap = pair_box_distances(a[seg, 0], a[seg, 1], b[seg, 0], b[seg, 1], self.boxes_m[box]) \
                    - self.inflation_m
                ok[seg[gap < -tolerance_m]] = False
        return ok
