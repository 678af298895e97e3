"""``optimal``: the exact shortest collision-free path among inflated discs.

In a convex workspace with disc obstacles, a shortest path is taut: it is made
of straight segments tangent to the discs and arcs along their boundaries.  So
it lies in the *tangent (visibility) graph*:

* nodes: start, goal, and the tangent points of
  - the two tangents from the start and from the goal to every disc,
  - the two outer and the two inner bitangents of every pair of discs;
* segment edges: start-goal, point-disc tangents and bitangents, kept only where
  the segment clears every disc (exact segment-disc distance) and its ends lie
  inside the bounds (the workspace is convex, so the segment does too);
* arc edges: between angularly consecutive tangent points on each disc, kept only
  where the arc meets no other disc and stays inside the bounds (both checked in
  closed form: the point of a circle nearest another centre, and the circle's
  axis-extreme points);
* Dijkstra from start to goal.

The discs are the obstacles inflated by ``Problem.inflation_m`` (robot radius
plus clearance).  The length is exact (up to floating point); it is reported as
``stats.extra["optimum_length_m"]``.  The returned waypoints follow each arc by
a polygon *circumscribed* about it (vertices a hair outside the circle, so the
polyline, which is what ``Problem.is_collision_free`` checks, never cuts into the
disc); ``stats.length_m`` of that polyline exceeds the exact length by less than
a micrometre per metre of arc.

It is the yardstick every other planner is reported against, and a planner in
its own right for users who want the true shortest path.  Box obstacles (grid
maps) are not supported.
"""

from __future__ import annotations

import heapq
import math
import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.models.errors import ConfigError
from swarmnav.planners.errors import NoPathFound
from swarmnav.models.geometry import segment_disc_distances
from swarmnav.planners.problem import Path, Problem, check_endpoints, check_supported
from swarmnav.models.world import Rect

TOLERANCE_M = 1e-9


def _unit(angle_rad: np.ndarray | float) -> np.ndarray:
    angle = np.asarray(angle_rad, dtype=float)
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def point_tangent_angles(point: np.ndarray, centre: np.ndarray, radius_m: float) -> list[float]:
    """Angles (about ``centre``) of the tangent points of the two tangents from ``point``.

    A point on the circle is its own (single) tangent point; a point inside has none.
    """
    offset = np.asarray(point, dtype=float) - centre
    d = float(np.hypot(*offset))
    if d < radius_m - TOLERANCE_M:
        return []
    base = math.atan2(offset[1], offset[0])
    if d <= radius_m + TOLERANCE_M:
        return [base]
    half = math.acos(radius_m / d)
    return [base + half, base - half]


def bitangent_angles(c_i: np.ndarray, r_i: float, c_j: np.ndarray,
                     r_j: float) -> list[tuple[float, float]]:
    """Tangent-point angles ``(on i, on j)`` of the outer and inner bitangents of two circles.

    Outer tangents exist unless one circle contains the other; inner ones only
    when the circles are disjoint.  For an outer tangent both radii to the
    tangent points are parallel (same angle); for an inner one they are opposite.
    """
    offset = np.asarray(c_j, dtype=float) - c_i
    d = float(np.hypot(*offset))
    base = math.atan2(offset[1], offset[0])
    pairs: list[tuple[float, float]] = []
    if d > abs(r_i - r_j) + TOLERANCE_M:
        beta = math.acos((r_i - r_j) / d)
        pairs += [(base + beta, base + beta), (base - beta, base - beta)]
    if d > r_i + r_j + TOLERANCE_M:
        beta = math.acos((r_i + r_j) / d)
        pairs += [(base + beta, base + beta + math.pi), (base - beta, base - beta + math.pi)]
    return pairs


def arc_is_clear(centre: np.ndarray, radius_m: float, start_rad: float, sweep_rad: float,
                 other_centres: np.ndarray, other_radii_m: np.ndarray, bounds: Rect) -> bool:
    """Whether the CCW arc ``start .. start + sweep`` stays out of other discs and inside bounds."""
    def within(angle: float) -> bool:
        return 0.0 <= (angle - start_rad) % (2.0 * math.pi) <= sweep_rad

    for k in range(4):  # the axis-extreme points of the circle that lie on the arc
        angle = k * math.pi / 2.0
        if within(angle):
            x, y = centre + radius_m * _unit(angle)
            if not bounds.contains(float(x), float(y), -TOLERANCE_M):
                return False
    if other_centres.shape[0] == 0:
        return True
    offset = other_centres - centre
    d = np.hypot(offset[:, 0], offset[:, 1])
    towards = np.arctan2(offset[:, 1], offset[:, 0])
    # angular distance from the arc to the direction of each other centre
    rel = (towards - start_rad) % (2.0 * np.pi)
    inside = rel <= sweep_rad
    gap = np.where(inside, 0.0, np.minimum(rel - sweep_rad, 2.0 * np.pi - rel))
    nearest_sq = radius_m ** 2 + d ** 2 - 2.0 * radius_m * d * np.cos(gap)
    return bool(np.all(np.sqrt(np.maximum(nearest_sq, 0.0)) >= other_radii_m - TOLERANCE_M))


def circumscribed_arc(centre: np.ndarray, radius_m: float, start_rad: float, sweep_rad: float,
                      bulge_m: float) -> np.ndarray:
    """Polyline from the arc's start to its end whose segments are tangent to the circle.

    Args:
        sweep_rad: signed sweep (positive counter-clockwise).
        bulge_m: largest distance of a vertex outside the circle.

    Returns:
        (m + 2, 2) points: arc start, m circumscribed vertices, arc end.
    """
    step_max = 2.0 * math.acos(radius_m / (radius_m + bulge_m))
    count = max(1, math.ceil(abs(sweep_rad) / step_max))
    step = sweep_rad / count
    mids = start_rad + (np.arange(count) + 0.5) * step
    vertices = centre + (radius_m / math.cos(step / 2.0)) * _unit(mids)
    return np.vstack([centre + radius_m * _unit(start_rad), vertices,
                      centre + radius_m * _unit(start_rad + sweep_rad)])


@dataclass(frozen=True)
class TangentGraph:
    """The tangent graph of a problem: node positions and weighted edges.

    Attributes:
        points: (N, 2) node positions; node 0 is the start, node 1 the goal.
        circle: (N,) the disc a node lies on (-1 for start and goal).
        angle_rad: (N,) its angle about that disc's centre.
        edges: adjacency ``node -> [(neighbour, length_m, arc_sweep_rad or None)]``.
    """

    points: np.ndarray
    circle: np.ndarray
    angle_rad: np.ndarray
    edges: dict[int, list[tuple[int, float, float | None]]]

    @property
    def edge_count(self) -> int:
        return sum(len(v) for v in self.edges.values()) // 2


def build_tangent_graph(problem: Problem) -> TangentGraph:
    """Build the tangent graph of ``problem``'s inflated discs (see the module docstring)."""
    centres = problem.disc_centres_m
    radii = problem.inflated_radii_m
    n = centres.shape[0]
    start, goal = problem.start.xy, problem.goal.xy
    points: list[np.ndarray] = [start, goal]
    circle: list[int] = [-1, -1]
    angle: list[float] = [0.0, 0.0]
    segments: list[tuple[int, int]] = [(0, 1)]

    def add(disc: int, theta: float) -> int:
        points.append(centres[disc] + radii[disc] * _unit(theta))
        circle.append(disc)
        angle.append(theta % (2.0 * math.pi))
        return len(points) - 1

    for endpoint in (0, 1):
        for i in range(n):
            for theta in point_tangent_angles(points[endpoint], centres[i], radii[i]):
                segments.append((endpoint, add(i, theta)))
    for i in range(n):
        for j in range(i + 1, n):
            for theta_i, theta_j in bitangent_angles(centres[i], radii[i], centres[j], radii[j]):
                segments.append((add(i, theta_i), add(j, theta_j)))

    pts = np.array(points)
    circ = np.array(circle)
    ang = np.array(angle)
    b = problem.bounds
    in_bounds = ((pts[:, 0] >= b.x_min_m - TOLERANCE_M) & (pts[:, 0] <= b.x_max_m + TOLERANCE_M)
                 & (pts[:, 1] >= b.y_min_m - TOLERANCE_M) & (pts[:, 1] <= b.y_max_m + TOLERANCE_M))
    if n:
        gaps = np.hypot(pts[:, None, 0] - centres[:, 0], pts[:, None, 1] - centres[:, 1]) - radii
        node_ok = in_bounds & np.all(gaps >= -TOLERANCE_M * 10, axis=1)
    else:
        node_ok = in_bounds
    edges: dict[int, list[tuple[int, float, float | None]]] = {i: [] for i in range(len(pts))}

    seg = np.array(segments, dtype=np.int64).reshape(-1, 2)
    seg = seg[node_ok[seg[:, 0]] & node_ok[seg[:, 1]]]
    if n and seg.size:
        dist = segment_disc_distances(pts[seg[:, 0]], pts[seg[:, 1]], centres)
        seg = seg[np.all(dist >= radii - TOLERANCE_M * 10, axis=1)]
    for u, v in seg.tolist():
        length = float(np.hypot(*(pts[v] - pts[u])))
        edges[u].append((v, length, None))
        edges[v].append((u, length, None))

    for i in range(n):
        members = np.flatnonzero((circ == i) & node_ok)
        if members.size < 2:
            continue
        members = members[np.argsort(ang[members], kind="stable")]
        others = np.arange(n) != i
        for a, c in zip(members, np.roll(members, -1)):
            sweep = (ang[c] - ang[a]) % (2.0 * math.pi)
            if not arc_is_clear(centres[i], radii[i], ang[a], sweep, centres[others],
                                radii[others], b):
                continue
            length = float(radii[i] * sweep)
            edges[int(a)].append((int(c), length, sweep))
            edges[int(c)].append((int(a), length, -sweep))
    return TangentGraph(points=pts, circle=circ, angle_rad=ang, edges=edges)


def shortest_tangent_route(graph: TangentGraph) -> tuple[list[int], float]:
    """Dijkstra from node 0 (start) to node 1 (goal).

    Raises:
        NoPathFound: the goal is not reachable in the graph.
    """
    dist = {0: 0.0}
    parent: dict[int, int] = {}
    heap = [(0.0, 0)]
    done: set[int] = set()
    while heap:
        d, u = heapq.heappop(heap)
        if u in done:
            continue
        done.add(u)
        if u == 1:
            break
        for v, length, _ in graph.edges[u]:
            nd = d + length
            if nd < dist.get(v, math.inf):
                dist[v] = nd
                parent[v] = u
                heapq.heappush(heap, (nd, v))
    if 1 not in done:
        raise NoPathFound("optimal: the goal is not reachable around the inflated discs")
    route = [1]
    while route[-1] != 0:
        route.append(parent[route[-1]])
    return route[::-1], dist[1]


@dataclass
class OptimalPlanner:
    """``optimal``: exact shortest path among the inflated discs, by the tangent graph.

    Attributes:
        arc_bulge_m: how far the circumscribed polygon that follows an arc may
            stand outside the circle (it never cuts inside).
    """

    name: ClassVar[str] = "optimal"
    supports: ClassVar[frozenset[str]] = frozenset({"discs"})

    arc_bulge_m: float = 1e-4

    def __post_init__(self) -> None:
        if not self.arc_bulge_m > 0:
            raise ConfigError("planner.params.arc_bulge_m", f"must be positive, got {self.arc_bulge_m!r}")

    def plan(self, problem: Problem, rng: np.random.Generator) -> Path:
        """Shortest path; ``rng`` is unused (the planner is deterministic).

        Raises:
            StartBlocked, GoalBlocked: an endpoint is outside the bounds or in a disc.
            NoPathFound: the discs separate start from goal.
            ConfigError: the problem has box obstacles.
        """
        t0 = time.perf_counter()
        check_supported(self, problem)
        check_endpoints(problem)
        graph = build_tangent_graph(problem)
        route, length_m = shortest_tangent_route(graph)
        waypoints = self._waypoints(problem, graph, route, self.arc_bulge_m)
        if not problem.is_collision_free(waypoints):
            # an arc grazes a neighbouring disc closer than the bulge: follow it tighter
            waypoints = self._waypoints(problem, graph, route, 1e-9)
        return Path.from_waypoints(waypoints, time.perf_counter() - t0, extra={
            "optimum_length_m": length_m,
            "graph_nodes": int(graph.points.shape[0]),
            "graph_edges": graph.edge_count,
        })

    @staticmethod
    def _waypoints(problem: Problem, graph: TangentGraph, route: list[int],
                   bulge_m: float) -> np.ndarray:
        pieces = [graph.points[route[0]][None, :]]
        for u, v in zip(route[:-1], route[1:]):
            # the edge Dijkstra used: the shortest of those joining u and v
            _, _, sweep = min((e for e in graph.edges[u] if e[0] == v), key=lambda e: e[1])
            if sweep is None:
                pieces.append(graph.points[v][None, :])
                continue
            disc = int(graph.circle[u])
            arc = circumscribed_arc(problem.disc_centres_m[disc], float(problem.inflated_radii_m[disc]),
                                    float(graph.angle_rad[u]), float(sweep), bulge_m)
            pieces.append(arc[1:])
        return np.vstack(pieces)
