"""The tangent graph among discs, built for every pair at once, and its shortest route.

In a convex workspace with disc obstacles (disjoint or overlapping), a shortest path is
taut: straight segments tangent to the discs and arcs along their boundaries.  So it lies
in the *tangent graph*, the reduced visibility graph of curved obstacles (Liu & Arimoto
1992, "Path planning using a tangent graph for mobile robots among polygonal and curved
obstacles", Int. J. Robotics Research 11(4)):

* nodes: start, goal, the tangent points of the two tangents from each of them to every
  disc (one point when the endpoint lies on the circle), and of the two outer and the two
  inner bitangents of every pair of discs (outer ones unless one disc contains the other,
  inner ones only when the discs are disjoint); a node inside another disc or outside the
  bounds is dropped;
* segment edges: start-goal, the point-disc tangents and the bitangents, kept where the
  segment's exact distance to every centre is at least that disc's radius and both ends
  are kept (the workspace is convex, so the segment is inside the bounds);
* arc edges: between angularly consecutive nodes of each disc that end a kept segment,
  kept where the point of the arc nearest every other centre is outside that disc and the
  circle's axis-extreme points that lie on the arc are inside the bounds (both in closed
  form);
* :func:`scipy.sparse.csgraph.dijkstra` from the start.

Both :mod:`planners.optimal` (the exact yardstick) and :mod:`planners.tangent_guess` (the
continuous planners' robust guess) use it.  Every test is whole-array NumPy: a few
milliseconds for 40 discs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario_limits import MAX_TANGENT_GRAPH_DISCS
from swarmnav.models.world import Rect
from swarmnav.planners.segment_gaps import row_blocks, segments_clear

#: An endpoint this close to a circle is on it; tangents exist only beyond it.
TANGENCY_TOLERANCE_M = 1e-9
#: How far a node, segment or arc may reach into a disc, or an arc out of the bounds.
GRAZE_TOLERANCE_M = 1e-8
START, GOAL = 0, 1


@dataclass(frozen=True)
class TangentGraph:
    """The tangent graph: node positions and undirected weighted edges.

    Attributes:
        points: (N, 2) node positions; node 0 is the start, node 1 the goal.
        node_disc: (N,) the disc a node lies on (-1 for start and goal).
        node_angle_rad: (N,) its angle about that disc's centre, in [0, 2 pi).
        edge_from, edge_to: (E,) the two nodes of each edge (``edge_from < edge_to``; one
            edge per pair of nodes, the shorter where two arcs join the same two nodes).
        edge_length_m: (E,) exact length (segment, or radius times sweep).
        edge_sweep_rad: (E,) an arc's signed sweep from ``edge_from`` to ``edge_to``
            (positive counter-clockwise); NaN for a segment.
    """

    points: np.ndarray
    node_disc: np.ndarray
    node_angle_rad: np.ndarray
    edge_from: np.ndarray
    edge_to: np.ndarray
    edge_length_m: np.ndarray
    edge_sweep_rad: np.ndarray

    @property
    def node_count(self) -> int:
        """Nodes that an edge touches (start and goal always count)."""
        touched = np.zeros(self.points.shape[0], dtype=bool)
        touched[[START, GOAL]] = True
        touched[self.edge_from] = True
        touched[self.edge_to] = True
        return int(np.count_nonzero(touched))

    @property
    def edge_count(self) -> int:
        return int(self.edge_from.size)

    def edge_index(self, u: int, v: int) -> int:
        """The edge joining nodes ``u`` and ``v`` (IndexError when there is none)."""
        return int(np.flatnonzero((self.edge_from == min(u, v)) & (self.edge_to == max(u, v)))[0])

    def step_sweep_rad(self, u: int, v: int) -> float:
        """The signed sweep of the edge walked from ``u`` to ``v`` (NaN for a segment)."""
        sweep = float(self.edge_sweep_rad[self.edge_index(u, v)])
        return sweep if u < v else -sweep


@dataclass(frozen=True)
class GraphRoute:
    """A shortest route of a :class:`TangentGraph`: its nodes from start to goal and its
    exact length (the sum of the lengths of the edges it walks)."""

    nodes: tuple[int, ...]
    length_m: float


def _unit(angle_rad: np.ndarray) -> np.ndarray:
    return np.stack([np.cos(angle_rad), np.sin(angle_rad)], axis=-1)


def _candidate_segments(start: np.ndarray, goal: np.ndarray, centres: np.ndarray,
                        radii: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every candidate tangent segment as (disc of end a, disc of end b, (S, 2) angles), with
    disc -1 for the start and -2 for the goal (whose angle is unused)."""
    n = centres.shape[0]
    discs_a, discs_b, angles = [], [], []
    for code, point in ((-1, start), (-2, goal)):
        offset = point - centres
        d = np.hypot(offset[:, 0], offset[:, 1])
        base = np.arctan2(offset[:, 1], offset[:, 0])
        beyond = d > radii + TANGENCY_TOLERANCE_M
        # on the circle (within the tolerance) the point is its own single tangent point
        half = np.where(beyond, np.arccos(np.clip(radii / np.where(beyond, d, 1.0), -1.0, 1.0)), 0.0)
        for sign, exists in ((1.0, d >= radii - TANGENCY_TOLERANCE_M), (-1.0, beyond)):
            idx = np.flatnonzero(exists)
            discs_a.append(np.full(idx.size, code))
            discs_b.append(idx)
            angles.append(np.column_stack([np.zeros(idx.size), (base + sign * half)[idx]]))
    i, j = np.triu_indices(n, 1)
    offset = centres[j] - centres[i]
    d = np.hypot(offset[:, 0], offset[:, 1])
    base = np.arctan2(offset[:, 1], offset[:, 0])
    outer = d > np.abs(radii[i] - radii[j]) + TANGENCY_TOLERANCE_M
    inner = d > radii[i] + radii[j] + TANGENCY_TOLERANCE_M
    beta_outer = np.arccos(np.clip((radii[i] - radii[j]) / np.where(outer, d, 1.0), -1.0, 1.0))
    beta_inner = np.arccos(np.clip((radii[i] + radii[j]) / np.where(inner, d, 1.0), -1.0, 1.0))
    # outer: the radii to both tangent points are parallel; inner: they are opposite
    for mask, beta, flip in ((outer, beta_outer, 0.0), (inner, beta_inner, math.pi)):
        for sign in (1.0, -1.0):
            theta = (base + sign * beta)[mask]
            discs_a.append(i[mask])
            discs_b.append(j[mask])
            angles.append(np.column_stack([theta, theta + flip]))
    return (np.concatenate(discs_a).astype(np.int64), np.concatenate(discs_b).astype(np.int64),
            np.concatenate(angles).reshape(-1, 2))


def build_tangent_graph(start: np.ndarray, goal: np.ndarray, centres: np.ndarray, radii: np.ndarray,
                        bounds: Rect) -> TangentGraph:
    """The tangent graph from ``start`` to ``goal`` around the discs ``(centres, radii)``
    within ``bounds`` (see the module docstring).

    Raises:
        ConfigError: more than :data:`MAX_TANGENT_GRAPH_DISCS` discs (checked before anything is built).
    """
    if len(radii) > MAX_TANGENT_GRAPH_DISCS:
        raise ConfigError("obstacles", f"an exact tangent graph among {len(radii):,} discs (at most "
                                       f"{MAX_TANGENT_GRAPH_DISCS:,}, MAX_TANGENT_GRAPH_DISCS: its time grows ~n^3); "
                                       "use a grid planner (astar, theta_star)")
    start = np.asarray(start, dtype=float).reshape(2)
    goal = np.asarray(goal, dtype=float).reshape(2)
    centres = np.asarray(centres, dtype=float).reshape(-1, 2)
    radii = np.asarray(radii, dtype=float).reshape(-1)
    disc_a, disc_b, angles = _candidate_segments(start, goal, centres, radii)
    # Nodes: 0 start, 1 goal, then the disc end of every candidate segment (its b end, and
    # its a end when that is a disc); an endpoint end is node 0 or 1.
    on_disc_a = disc_a >= 0
    s = disc_a.size
    count_a = int(np.count_nonzero(on_disc_a))
    node_disc = np.concatenate([[-1, -1], disc_a[on_disc_a], disc_b])
    node_angle = np.concatenate([[0.0, 0.0], angles[on_disc_a, 0], angles[:, 1]]) % (2.0 * math.pi)
    points = np.empty((node_disc.size, 2))
    points[START], points[GOAL] = start, goal
    on_disc = node_disc >= 0
    points[on_disc] = centres[node_disc[on_disc]] + radii[node_disc[on_disc], None] * _unit(node_angle[on_disc])
    ends_a = np.where(disc_a == -1, START, GOAL)
    ends_a[on_disc_a] = 2 + np.arange(count_a)
    ends_b = 2 + count_a + np.arange(s)
    ends_a = np.concatenate([[START], ends_a])
    ends_b = np.concatenate([[GOAL], ends_b])

    inner_sq = np.maximum(radii - GRAZE_TOLERANCE_M, 0.0) ** 2
    node_ok = _in_bounds(points, bounds, TANGENCY_TOLERANCE_M) & ~_inside_any(points, centres, inner_sq)
    keep = node_ok[ends_a] & node_ok[ends_b]
    ends_a, ends_b = ends_a[keep], ends_b[keep]
    if centres.shape[0]:
        clear = segments_clear(points[ends_a], points[ends_b], centres, inner_sq)
        ends_a, ends_b = ends_a[clear], ends_b[clear]
    segment_length = np.hypot(*(points[ends_b] - points[ends_a]).T)

    arc_a, arc_c, arc_sweep = _clear_arcs(ends_a, ends_b, node_disc, node_angle, centres, radii, bounds)
    arc_length = radii[node_disc[arc_a]] * arc_sweep

    first = np.concatenate([ends_a, arc_a])
    second = np.concatenate([ends_b, arc_c])
    length = np.concatenate([segment_length, arc_length])
    sweep = np.concatenate([np.full(ends_a.size, np.nan), arc_sweep])
    low, high = np.minimum(first, second), np.maximum(first, second)
    sweep = np.where(first <= second, sweep, -sweep)
    # one edge per pair of nodes: the shorter (both arcs of a disc with two nodes)
    order = np.lexsort((length, high, low))
    low, high, length, sweep = low[order], high[order], length[order], sweep[order]
    unique = np.r_[True, (low[1:] != low[:-1]) | (high[1:] != high[:-1])]
    return TangentGraph(points, node_disc, node_angle, low[unique], high[unique], length[unique], sweep[unique])


def shortest_route(graph: TangentGraph) -> GraphRoute | None:
    """Dijkstra from the start to the goal; None when the goal is not reachable."""
    from scipy.sparse import coo_matrix          # here: 7 ms of import a cold `swarmnav` need not pay
    from scipy.sparse.csgraph import dijkstra

    size = graph.points.shape[0]
    # a zero weight would read as no edge: a zero-length edge weighs a picometre here
    weights = np.maximum(graph.edge_length_m, 1e-12)
    matrix = coo_matrix((weights, (graph.edge_from, graph.edge_to)), shape=(size, size)).tocsr()
    _, parent = dijkstra(matrix, directed=False, indices=START, return_predecessors=True)
    if parent[GOAL] < 0:
        return None
    nodes = [GOAL]
    while nodes[-1] != START:
        nodes.append(int(parent[nodes[-1]]))
    nodes.reverse()
    # the exact length: the edges' own lengths, summed along the route
    length_m = math.fsum(float(graph.edge_length_m[graph.edge_index(u, v)]) for u, v in zip(nodes[:-1], nodes[1:]))
    return GraphRoute(tuple(nodes), length_m)


def _in_bounds(points: np.ndarray, bounds: Rect, tolerance_m: float) -> np.ndarray:
    return ((points[:, 0] >= bounds.x_min_m - tolerance_m) & (points[:, 0] <= bounds.x_max_m + tolerance_m)
            & (points[:, 1] >= bounds.y_min_m - tolerance_m) & (points[:, 1] <= bounds.y_max_m + tolerance_m))


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


def _clear_arcs(ends_a: np.ndarray, ends_b: np.ndarray, node_disc: np.ndarray, node_angle: np.ndarray,
                centres: np.ndarray, radii: np.ndarray,
                bounds: Rect) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The counter-clockwise arcs ``(from node, to node, sweep)`` between angularly
    consecutive nodes of each disc that end a kept segment, where the arc is clear."""
    used = np.zeros(node_disc.size, dtype=bool)
    used[ends_a] = True
    used[ends_b] = True
    members = np.flatnonzero(used & (node_disc >= 0))
    if members.size == 0:
        return members, members, np.empty(0)
    order = members[np.lexsort((node_angle[members], node_disc[members]))]
    disc_of = node_disc[order]
    first = np.r_[True, disc_of[1:] != disc_of[:-1]]
    group_start = np.maximum.accumulate(np.where(first, np.arange(order.size), 0))
    last = np.r_[disc_of[1:] != disc_of[:-1], True]
    following = np.where(last, group_start, np.arange(order.size) + 1)
    arc_a, arc_c = order, order[following]
    distinct = arc_a != arc_c
    arc_a, arc_c = arc_a[distinct], arc_c[distinct]
    sweep = (node_angle[arc_c] - node_angle[arc_a]) % (2.0 * math.pi)
    ok = np.zeros(arc_a.size, dtype=bool)
    for block in row_blocks(arc_a.size, centres.shape[0]):
        ok[block] = _arcs_clear(centres, radii, node_disc[arc_a[block]], node_angle[arc_a[block]], sweep[block],
                                bounds)
    return arc_a[ok], arc_c[ok], sweep[ok]


def _arcs_clear(centres: np.ndarray, radii: np.ndarray, arc_disc: np.ndarray, arc_from: np.ndarray,
                sweep: np.ndarray, bounds: Rect) -> np.ndarray:
    """Whether each counter-clockwise arc stays out of the other discs and inside the bounds."""
    c, r = centres[arc_disc], radii[arc_disc]
    offset = centres[None, :, :] - c[:, None, :]                      # (A, n, 2)
    d = np.hypot(offset[..., 0], offset[..., 1])
    # angular distance from the arc to the direction of each other centre
    rel = (np.arctan2(offset[..., 1], offset[..., 0]) - arc_from[:, None]) % (2.0 * math.pi)
    gap = np.where(rel <= sweep[:, None], 0.0, np.minimum(rel - sweep[:, None], 2.0 * math.pi - rel))
    nearest = np.sqrt(np.maximum(r[:, None] ** 2 + d ** 2 - 2.0 * r[:, None] * d * np.cos(gap), 0.0))
    nearest[np.arange(arc_disc.size), arc_disc] = np.inf
    ok = np.all(nearest >= radii[None, :] - GRAZE_TOLERANCE_M, axis=1)
    for k in range(4):                                                  # the axis-extreme points
        angle = k * math.pi / 2.0
        on_arc = (angle - arc_from) % (2.0 * math.pi) <= sweep
        extreme = c + r[:, None] * np.array([math.cos(angle), math.sin(angle)])
        ok &= ~on_arc | _in_bounds(extreme, bounds, GRAZE_TOLERANCE_M)
    return ok
