"""The tangent-graph guess of the continuous planners' robust mode: the shortest path among
the discs, built with whole-array NumPy and solved with SciPy's Dijkstra.

The shortest path among disjoint or overlapping discs in a convex workspace is made of
straight segments tangent to the discs and arcs along their boundaries, so it lies in the
*tangent graph* (the reduced visibility graph of curved obstacles: Liu & Arimoto 1992,
"Path planning using a tangent graph for mobile robots among polygonal and curved
obstacles", Int. J. Robotics Research 11(4); for discs, e.g. Chen, Chiang & Hsu 2010 call
it the "tangent visibility graph").  :mod:`planners.optimal` builds the same graph one
pair at a time as the yardstick; this module builds it for every pair at once, which is
what the robust mode needs as a *guess* (about 5-15 ms for 40 discs where the yardstick
takes 0.15 s):

* nodes: start, goal, the tangent points of the two tangents from each of them to every
  disc, and of the two outer and two inner bitangents of every pair of discs; a node
  inside another disc or outside the bounds is dropped;
* segment edges: kept where the segment's exact distance to every centre is at least
  that disc's radius;
* arc edges: between angularly consecutive nodes of each disc, kept where the point of
  the arc nearest every other centre is outside that disc and the arc's axis-extreme
  points are inside the bounds;
* :func:`scipy.sparse.csgraph.dijkstra` from the start.

The route is returned as a polyline with each arc followed by points on the circle every
``arc_step_rad`` (it is a guess: the planners fit their own curve to it), together with
the number of turns (arcs) it makes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from swarmnav.models.world import Rect
from swarmnav.planners.segment_gaps import row_blocks, segments_clear

TOLERANCE_M = 1e-9


@dataclass(frozen=True)
class TangentRoute:
    """A shortest route of the tangent graph.

    Attributes:
        waypoints: (N, 2) the route, arcs sampled on their circles.
        length_m: its exact length (segments plus arcs).
        turns: the arcs it follows that sweep more than a hundredth of a radian.
        knees: (turns, 2) the middle of each of those arcs.
    """

    waypoints: np.ndarray
    length_m: float
    turns: int
    knees: np.ndarray


def _unit(angle_rad: np.ndarray) -> np.ndarray:
    return np.stack([np.cos(angle_rad), np.sin(angle_rad)], axis=-1)


def _tangent_nodes(start: np.ndarray, goal: np.ndarray, centres: np.ndarray,
                   radii: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every candidate segment: (disc of end a, angle of a, disc of end b, angle of b) with
    disc -1 (start) or -2 (goal) for an endpoint.  Returned as (disc_a, disc_b) int arrays
    of shape (S,) and an (S, 2) array of angles."""
    n = centres.shape[0]
    discs_a, discs_b, angles = [], [], []
    for code, point in ((-1, start), (-2, goal)):
        offset = point - centres
        d = np.hypot(offset[:, 0], offset[:, 1])
        ok = d > radii + TOLERANCE_M
        base = np.arctan2(offset[:, 1], offset[:, 0])
        half = np.arccos(np.clip(radii / np.where(ok, d, 1.0), -1.0, 1.0))
        for sign in (1.0, -1.0):
            idx = np.flatnonzero(ok)
            discs_a.append(np.full(idx.size, code))
            discs_b.append(idx)
            angles.append(np.column_stack([np.zeros(idx.size), (base + sign * half)[idx]]))
    i, j = np.triu_indices(n, 1)
    offset = centres[j] - centres[i]
    d = np.hypot(offset[:, 0], offset[:, 1])
    base = np.arctan2(offset[:, 1], offset[:, 0])
    outer = d > np.abs(radii[i] - radii[j]) + TOLERANCE_M
    inner = d > radii[i] + radii[j] + TOLERANCE_M
    beta_out = np.arccos(np.clip((radii[i] - radii[j]) / np.where(outer, d, 1.0), -1.0, 1.0))
    beta_in = np.arccos(np.clip((radii[i] + radii[j]) / np.where(inner, d, 1.0), -1.0, 1.0))
    for mask, beta, flip in ((outer, beta_out, 0.0), (inner, beta_in, math.pi)):
        for sign in (1.0, -1.0):
            theta = (base + sign * beta)[mask]
            discs_a.append(i[mask])
            discs_b.append(j[mask])
            angles.append(np.column_stack([theta, theta + flip]))
    return (np.concatenate(discs_a).astype(np.int64), np.concatenate(discs_b).astype(np.int64),
            np.concatenate(angles).reshape(-1, 2))


def tangent_route(start: np.ndarray, goal: np.ndarray, centres: np.ndarray, radii: np.ndarray,
                  bounds: Rect, arc_step_rad: float = 0.2) -> TangentRoute | None:
    """The shortest route from ``start`` to ``goal`` around the discs ``(centres, radii)``
    within ``bounds`` (None when the discs separate them).  Both endpoints must lie outside
    every disc."""
    start = np.asarray(start, dtype=float).reshape(2)
    goal = np.asarray(goal, dtype=float).reshape(2)
    centres = np.asarray(centres, dtype=float).reshape(-1, 2)
    radii = np.asarray(radii, dtype=float).reshape(-1)
    n = centres.shape[0]
    from scipy.sparse import coo_matrix          # here: 7 ms of import a cold `swarmnav` need not pay
    from scipy.sparse.csgraph import dijkstra

    direct = n == 0 or bool(segments_clear(start[None], goal[None], centres,
                                            np.maximum(radii - TOLERANCE_M, 0.0) ** 2)[0])
    if direct:
        return TangentRoute(np.vstack([start, goal]), float(np.hypot(*(goal - start))), 0, np.empty((0, 2)))
    disc_a, disc_b, angles = _tangent_nodes(start, goal, centres, radii)
    # Nodes: 0 start, 1 goal, then both ends of every candidate segment.
    s = disc_a.size
    node_disc = np.concatenate([[-1, -2], disc_a, disc_b])
    node_angle = np.concatenate([[0.0, 0.0], angles[:, 0], angles[:, 1]]) % (2.0 * math.pi)
    on_disc = node_disc >= 0
    safe = np.where(on_disc, node_disc, 0)
    points = np.where(on_disc[:, None], centres[safe] + radii[safe, None] * _unit(node_angle), 0.0)
    points[0], points[1] = start, goal
    ends_a = np.where(disc_a == -1, 0, np.where(disc_a == -2, 1, 2 + np.arange(s)))
    ends_b = 2 + s + np.arange(s)
    b = bounds
    node_ok = ((points[:, 0] >= b.x_min_m - TOLERANCE_M) & (points[:, 0] <= b.x_max_m + TOLERANCE_M)
               & (points[:, 1] >= b.y_min_m - TOLERANCE_M) & (points[:, 1] <= b.y_max_m + TOLERANCE_M))
    inner_sq = np.maximum(radii - 1e-8, 0.0) ** 2
    node_ok &= ~_inside_any(points, centres, inner_sq)
    keep = node_ok[ends_a] & node_ok[ends_b]
    ends_a, ends_b = ends_a[keep], ends_b[keep]
    clear = segments_clear(points[ends_a], points[ends_b], centres, inner_sq)
    ends_a, ends_b = ends_a[clear], ends_b[clear]
    seg_len = np.hypot(*(points[ends_b] - points[ends_a]).T)

    # Arcs between angularly consecutive usable nodes of each disc.
    used = np.zeros(points.shape[0], dtype=bool)
    used[ends_a] = True
    used[ends_b] = True
    members = np.flatnonzero(used & on_disc)
    order = members[np.lexsort((node_angle[members], node_disc[members]))]
    disc_of = node_disc[order]
    first = np.r_[True, disc_of[1:] != disc_of[:-1]]
    group_start = np.maximum.accumulate(np.where(first, np.arange(order.size), 0))
    last = np.r_[disc_of[1:] != disc_of[:-1], True]
    nxt = np.where(last, group_start, np.arange(order.size) + 1)
    arc_a, arc_c = order, order[nxt]
    solo = arc_a == arc_c
    arc_a, arc_c = arc_a[~solo], arc_c[~solo]
    arc_disc = node_disc[arc_a]
    arc_from = node_angle[arc_a]
    sweep = (node_angle[arc_c] - arc_from) % (2.0 * math.pi)
    arc_ok = _arcs_clear(centres, radii, arc_disc, arc_from, sweep, bounds)
    arc_a, arc_c, arc_disc, arc_from, sweep = (v[arc_ok] for v in (arc_a, arc_c, arc_disc, arc_from, sweep))
    arc_len = radii[arc_disc] * sweep

    rows = np.concatenate([ends_a, arc_a])
    cols = np.concatenate([ends_b, arc_c])
    weights = np.maximum(np.concatenate([seg_len, arc_len]), 1e-12)
    # Undirected graph; duplicates (both arcs of a disc with two nodes) keep the shorter.
    lo, hi = np.minimum(rows, cols), np.maximum(rows, cols)
    key_order = np.lexsort((weights, hi, lo))
    lo, hi, weights = lo[key_order], hi[key_order], weights[key_order]
    unique = np.r_[True, (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1])]
    lo, hi, weights = lo[unique], hi[unique], weights[unique]
    size = points.shape[0]
    graph = coo_matrix((weights, (lo, hi)), shape=(size, size)).tocsr()
    distance, parent = dijkstra(graph, directed=False, indices=0, return_predecessors=True)
    if not math.isfinite(distance[1]):
        return None
    route = [1]
    while route[-1] != 0:
        route.append(int(parent[route[-1]]))
    route.reverse()
    return _route_polyline(route, points, node_disc, node_angle, centres, radii,
                           (arc_a, arc_c, sweep), float(distance[1]), arc_step_rad)


def _inside_any(points: np.ndarray, centres: np.ndarray, radii_sq: np.ndarray) -> np.ndarray:
    """(N,) whether each point is strictly inside one of the discs (squared radii given)."""
    inside = np.zeros(points.shape[0], dtype=bool)
    for block in row_blocks(points.shape[0], centres.shape[0]):
        dx = points[block, 0, None] - centres[None, :, 0]
        dy = points[block, 1, None] - centres[None, :, 1]
        dx *= dx
        dy *= dy
        dx += dy
        inside[block] = np.any(dx < radii_sq, axis=1)
    return inside


def _arcs_clear(centres: np.ndarray, radii: np.ndarray, arc_disc: np.ndarray, arc_from: np.ndarray,
                sweep: np.ndarray, bounds: Rect) -> np.ndarray:
    """Whether each counter-clockwise arc stays out of the other discs and inside the bounds."""
    ok = np.zeros(arc_disc.size, dtype=bool)
    for block in row_blocks(arc_disc.size, centres.shape[0]):
        ok[block] = _arc_block_clear(centres, radii, arc_disc[block], arc_from[block], sweep[block], bounds)
    return ok


def _arc_block_clear(centres: np.ndarray, radii: np.ndarray, arc_disc: np.ndarray, arc_from: np.ndarray,
                     sweep: np.ndarray, bounds: Rect) -> np.ndarray:
    c, r = centres[arc_disc], radii[arc_disc]
    offset = centres[None, :, :] - c[:, None, :]                      # (A, n, 2)
    d = np.hypot(offset[..., 0], offset[..., 1])
    rel = (np.arctan2(offset[..., 1], offset[..., 0]) - arc_from[:, None]) % (2.0 * math.pi)
    gap = np.where(rel <= sweep[:, None], 0.0, np.minimum(rel - sweep[:, None], 2.0 * math.pi - rel))
    nearest = np.sqrt(np.maximum(r[:, None] ** 2 + d ** 2 - 2.0 * r[:, None] * d * np.cos(gap), 0.0))
    nearest[np.arange(arc_disc.size), arc_disc] = np.inf
    ok = np.all(nearest >= radii[None, :] - 1e-8, axis=1)
    for k in range(4):                                                  # axis-extreme points
        rel_k = (k * math.pi / 2.0 - arc_from) % (2.0 * math.pi)
        on_arc = rel_k <= sweep
        x = c[:, 0] + r * math.cos(k * math.pi / 2.0)
        y = c[:, 1] + r * math.sin(k * math.pi / 2.0)
        inside = ((x >= bounds.x_min_m - 1e-8) & (x <= bounds.x_max_m + 1e-8)
                  & (y >= bounds.y_min_m - 1e-8) & (y <= bounds.y_max_m + 1e-8))
        ok &= ~on_arc | inside
    return ok


def _route_polyline(route: list[int], points: np.ndarray, node_disc: np.ndarray, node_angle: np.ndarray,
                    centres: np.ndarray, radii: np.ndarray, arcs: tuple[np.ndarray, ...], length_m: float,
                    arc_step_rad: float) -> TangentRoute:
    arc_a, arc_c, sweep = arcs
    pieces = [points[route[0]][None, :]]
    turns: list[tuple[int, float, float]] = []          # (disc, first angle, signed sweep)
    previous_disc = -3
    for u, v in zip(route[:-1], route[1:]):
        disc = int(node_disc[u])
        if disc < 0 or disc != int(node_disc[v]):
            pieces.append(points[v][None, :])
            previous_disc = -3
            continue
        forward = sweep[(arc_a == u) & (arc_c == v)]
        backward = sweep[(arc_a == v) & (arc_c == u)]
        signed = min([float(x) for x in forward] + [-float(x) for x in backward], key=abs)
        steps = max(1, math.ceil(abs(signed) / arc_step_rad))
        theta = node_angle[u] + signed * np.arange(1, steps + 1) / steps
        pieces.append(centres[disc] + radii[disc] * _unit(theta))
        if disc == previous_disc:                       # the same turn goes on round the disc
            turns[-1] = (disc, turns[-1][1], turns[-1][2] + signed)
        else:
            turns.append((disc, float(node_angle[u]), signed))
        previous_disc = disc
    turns = [t for t in turns if abs(t[2]) > 0.01]
    knees = np.array([centres[d] + radii[d] * _unit(np.array(a + w / 2.0)) for d, a, w in turns]).reshape(-1, 2)
    return TangentRoute(np.vstack(pieces), length_m, len(turns), knees)
