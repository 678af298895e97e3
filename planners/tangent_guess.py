"""The tangent-graph guess of the continuous planners' robust mode: the shortest route
among the discs, as a polyline the planners fit their own curve to.

The route is the shortest route of the tangent graph (:mod:`planners.tangent_graph`, the
same graph and search as the ``optimal`` yardstick's, so its length is the exact optimum),
returned with each arc followed by points on the circle every ``arc_step_rad``, together
with the number of turns (arcs) it makes and the middle of each turn.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarmnav.models.world import Rect
from swarmnav.planners.segment_gaps import segments_clear
from swarmnav.planners.tangent_graph import (GRAZE_TOLERANCE_M, GraphRoute, TangentGraph, build_tangent_graph,
                                             shortest_route)


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


def tangent_route(start: np.ndarray, goal: np.ndarray, centres: np.ndarray, radii: np.ndarray,
                  bounds: Rect, arc_step_rad: float = 0.2) -> TangentRoute | None:
    """The shortest route from ``start`` to ``goal`` around the discs ``(centres, radii)``
    within ``bounds`` (None when the discs separate them).  Both endpoints must lie outside
    every disc."""
    start = np.asarray(start, dtype=float).reshape(2)
    goal = np.asarray(goal, dtype=float).reshape(2)
    centres = np.asarray(centres, dtype=float).reshape(-1, 2)
    radii = np.asarray(radii, dtype=float).reshape(-1)
    direct = centres.shape[0] == 0 or bool(segments_clear(start[None], goal[None], centres,
                                                          np.maximum(radii - GRAZE_TOLERANCE_M, 0.0) ** 2)[0])
    if direct:
        return TangentRoute(np.vstack([start, goal]), float(np.hypot(*(goal - start))), 0, np.empty((0, 2)))
    graph = build_tangent_graph(start, goal, centres, radii, bounds)
    route = shortest_route(graph)
    if route is None:
        return None
    return _route_polyline(graph, route, centres, radii, arc_step_rad)


def _route_polyline(graph: TangentGraph, route: GraphRoute, centres: np.ndarray, radii: np.ndarray,
                    arc_step_rad: float) -> TangentRoute:
    nodes = route.nodes
    pieces = [graph.points[nodes[0]][None, :]]
    turns: list[tuple[int, float, float]] = []          # (disc, first angle, signed sweep)
    previous_disc = -3
    for u, v in zip(nodes[:-1], nodes[1:]):
        signed = graph.step_sweep_rad(u, v)
        if math.isnan(signed):
            pieces.append(graph.points[v][None, :])
            previous_disc = -3
            continue
        disc = int(graph.node_disc[u])
        start_rad = float(graph.node_angle_rad[u])
        steps = max(1, math.ceil(abs(signed) / arc_step_rad))
        theta = start_rad + signed * np.arange(1, steps + 1) / steps
        pieces.append(centres[disc] + radii[disc] * _unit(theta))
        if disc == previous_disc:                       # the same turn goes on round the disc
            turns[-1] = (disc, turns[-1][1], turns[-1][2] + signed)
        else:
            turns.append((disc, start_rad, signed))
        previous_disc = disc
    turns = [t for t in turns if abs(t[2]) > 0.01]
    knees = np.array([centres[d] + radii[d] * _unit(np.array(a + w / 2.0)) for d, a, w in turns]).reshape(-1, 2)
    return TangentRoute(np.vstack(pieces), route.length_m, len(turns), knees)
