"""Segment-to-disc gaps by squared distances: the fast pre-check of the continuous planners'
exact check, and the tangent guess's visibility test.

:meth:`planners.problem.Problem.is_collision_free` is *the* exact check every returned path
passes; on a dense spline of 300 points among 40 discs it takes a few milliseconds
(:func:`models.geometry.segment_disc_distances` builds (S, n, 2) temporaries and a root per
pair).  The continuous planners check many candidates that clearly cut a disc (the scan of
the final population, the repair, the polish's fall-back); :func:`polyline_gap_m` measures
the same gap with (S, n) arrays and one root per segment, so that those candidates are
rejected at a tenth of the cost and only the plausible ones reach the exact check.
"""

from __future__ import annotations

import numpy as np

#: Segments of a polyline measured together by :func:`polyline_gap_m`.
POLYLINE_CHUNK = 64
#: Most elements of one (rows, discs) temporary (8 MB of float64).
BLOCK_ELEMENTS = 1_000_000


def segment_gaps_sq(a: np.ndarray, b: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """(S, n) the squared distance from each segment ``a[s] -> b[s]`` to each centre: the
    centre's projection onto the segment's line, clipped to the segment, is the nearest
    point (a segment of zero length is its point)."""
    ab = b - a
    length_sq = ab[:, 0] * ab[:, 0] + ab[:, 1] * ab[:, 1]
    inverse = np.divide(1.0, length_sq, out=np.zeros_like(length_sq), where=length_sq > 0.0)[:, None]
    ox = centres[None, :, 0] - a[:, 0, None]
    oy = centres[None, :, 1] - a[:, 1, None]
    t = (ox * ab[:, 0, None] + oy * ab[:, 1, None]) * inverse
    np.clip(t, 0.0, 1.0, out=t)
    ox -= t * ab[:, 0, None]
    oy -= t * ab[:, 1, None]
    ox *= ox
    oy *= oy
    ox += oy
    return ox


def row_blocks(rows: int, columns: int, budget: int = BLOCK_ELEMENTS) -> list[slice]:
    """Slices of ``rows`` such that a block of rows times ``columns`` stays within
    ``budget`` elements (the (rows, columns) temporaries of a large scene stay small)."""
    size = max(1, budget // max(columns, 1))
    return [slice(i, min(i + size, rows)) for i in range(0, rows, size)]


def segments_clear(a: np.ndarray, b: np.ndarray, centres: np.ndarray, radii_sq: np.ndarray) -> np.ndarray:
    """(S,) whether each segment stays out of every disc (``radii_sq``: squared radii)."""
    clear = np.ones(a.shape[0], dtype=bool)
    for block in row_blocks(a.shape[0], centres.shape[0]):
        clear[block] = ~np.any(segment_gaps_sq(a[block], b[block], centres) < radii_sq[None, :], axis=1)
    return clear


def polyline_gap_m(waypoints: np.ndarray, centres: np.ndarray, radii: np.ndarray,
                   chunk: int = POLYLINE_CHUNK) -> float:
    """The smallest signed gap between a polyline and the discs it comes near.

    The polyline is taken ``chunk`` segments at a time, and only the discs that reach the
    chunk's bounding box are measured (a disc that does not reach it is clear of those
    segments).  So the result is never below the true smallest gap
    (:meth:`planners.problem.Problem.path_clearance_m` for disc obstacles), equals it (up to
    rounding) whenever the polyline cuts a disc, and is ``inf`` when no disc comes near."""
    pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    if centres.shape[0] == 0:
        return float("inf")
    if pts.shape[0] == 1:
        pts = np.vstack([pts, pts])
    best = np.inf
    for i in range(0, pts.shape[0] - 1, chunk):
        piece = pts[i:i + chunk + 1]
        low, high = piece.min(axis=0), piece.max(axis=0)
        near = np.flatnonzero(np.all((centres + radii[:, None] >= low) & (centres - radii[:, None] <= high), axis=1))
        if near.size == 0:
            continue
        gaps = np.sqrt(segment_gaps_sq(piece[:-1], piece[1:], centres[near])) - radii[near][None, :]
        best = min(best, float(gaps.min()))
    return best
