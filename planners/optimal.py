"""``optimal``: the exact shortest collision-free path among inflated discs.

In a convex workspace with disc obstacles, a shortest path is taut: it is made of
straight segments tangent to the discs and arcs along their boundaries.  So it lies in
the *tangent graph*, built and searched by :mod:`planners.tangent_graph` (nodes: start,
goal and the tangent points of the point-disc tangents and of the outer and inner
bitangents; segment edges that clear every disc, nodes outside the bounds dropped; arc
edges between consecutive tangent points of a disc that meet no other disc and whose
axis-extreme points stay inside the bounds; Dijkstra from start to goal).

The discs are the obstacles inflated by ``Problem.inflation_m`` (robot radius plus
clearance).  The length is exact (up to floating point: the sum of the route's segment
and arc lengths); it is reported as ``stats.extra["optimum_length_m"]``, with the graph's
size as ``graph_nodes`` (the nodes an edge touches, start and goal included) and
``graph_edges`` (one per pair of joined nodes).  The returned waypoints follow each arc by
a polygon *circumscribed* about it (vertices a hair outside the circle, so the polyline,
which is what ``Problem.is_collision_free`` checks, never cuts into the disc);
``stats.length_m`` of that polyline exceeds the exact length by at most about
``2 * arc_bulge_m / (3 * radius)`` of each arc's length (a polygon of half-angle h per side
is ``tan(h) / h`` times its arc; 20 micrometres per metre of arc on a 0.35 m disc at the
default bulge, a relative excess of 1e-7 to 1e-6 on the bundled scenarios).

It is the yardstick every other planner is reported against, and a planner in its own
right for users who want the true shortest path.  Box obstacles (grid maps) are not
supported.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.models.parameters import param, within
from swarmnav.models.errors import ConfigError
from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.problem import Path, Problem, check_endpoints, check_supported
from swarmnav.planners.tangent_graph import TangentGraph, build_tangent_graph, shortest_route


def _unit(angle_rad: np.ndarray | float) -> np.ndarray:
    angle = np.asarray(angle_rad, dtype=float)
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


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


@dataclass
class OptimalPlanner:
    """``optimal``: exact shortest path among the inflated discs, by the tangent graph.

    Attributes:
        arc_bulge_m: how far the circumscribed polygon that follows an arc may
            stand outside the circle (it never cuts inside).  The default, 1e-5 m, gives
            about as many waypoints as the earlier per-pair graph did at 1e-4 m (which split
            every arc at each unused tangent point), with a tenth of its excess length.
    """

    name: ClassVar[str] = "optimal"
    supports: ClassVar[frozenset[str]] = frozenset({"discs"})

    arc_bulge_m: float = param(1e-5, within(1e-6, 1))

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
        graph = build_tangent_graph(problem.start.xy, problem.goal.xy, problem.disc_centres_m,
                                    problem.inflated_radii_m, problem.bounds)
        route = shortest_route(graph)
        if route is None:
            raise NoPathFound("optimal: the goal is not reachable around the inflated discs")
        waypoints = self._waypoints(problem, graph, route.nodes, self.arc_bulge_m)
        if not problem.is_collision_free(waypoints):
            # an arc grazes a neighbouring disc closer than the bulge: follow it tighter
            waypoints = self._waypoints(problem, graph, route.nodes, 1e-9)
        return Path.from_waypoints(waypoints, time.perf_counter() - t0, extra={
            "optimum_length_m": route.length_m,
            "graph_nodes": graph.node_count,
            "graph_edges": graph.edge_count,
        })

    @staticmethod
    def _waypoints(problem: Problem, graph: TangentGraph, route: tuple[int, ...],
                   bulge_m: float) -> np.ndarray:
        pieces = [graph.points[route[0]][None, :]]
        for u, v in zip(route[:-1], route[1:]):
            sweep = graph.step_sweep_rad(u, v)
            if math.isnan(sweep):
                pieces.append(graph.points[v][None, :])
                continue
            disc = int(graph.node_disc[u])
            arc = circumscribed_arc(problem.disc_centres_m[disc], float(problem.inflated_radii_m[disc]),
                                    float(graph.node_angle_rad[u]), sweep, bulge_m)
            pieces.append(arc[1:])
        return np.vstack(pieces)
