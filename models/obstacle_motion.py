"""How moving obstacles move: pure functions of time, shared by the simulator
(which moves mocap bodies with them) and the planners (which see t = 0).

Three kinds, each a frozen dataclass with ``positions_at(times_s) -> (T, 2)``:

* :class:`LinearMotion`: constant speed and heading, Abdulla & Hadi (2025)
  Eqs. (9)-(10).  At the arena edge the obstacle either reflects (mirror
  bounce of its centre at the arena edge) or stops, as the scenario file says.
* :class:`RandomWalkMotion`: Hasan et al. (2023)'s dynamic obstacles, a step to a
  random free neighbouring position each period.  Two readings of "neighbouring":
  ``grid`` (the paper's grid walk, the default on map scenarios): the 8
  neighbouring cells, displacements ``(+-step, 0)``, ``(0, +-step)`` and
  ``(+-step, +-step)``, so a walk started on a cell centre stays on cell centres;
  ``compass`` (the default without a map): 8 compass steps of length ``step_m``
  (a diagonal step is ``step_m / sqrt(2)`` along each axis).  "Free" means the
  disc stays inside the arena (inside the walls when it has them) and its swept
  step (the capsule from one node to the next) touches no static disc and no map
  box, so a walker never passes through a wall or cuts a wall's corner.  We
  interpolate linearly within a period rather than teleport, so the physics sees a
  continuous motion (the paper's grid jumps have no physical meaning).  The walk
  is drawn from the run's world seed, one stream per obstacle.
* :class:`WaypointMotion`: patrol through points at constant speed, closing the loop.

Every kind takes ``start_s``: the obstacle holds its start position until then and
moves as described from that time on (Gong et al. (2022) §2.1 assumption 2: obstacles
switch between constant straight-line motion and the stopped state).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

WALK_STEPS = ("grid", "compass")


def _held(times_s: np.ndarray, start_s: float) -> np.ndarray:
    """Time since the motion started: 0 before ``start_s``."""
    return np.maximum(np.asarray(times_s, dtype=float).reshape(-1) - start_s, 0.0)


def segment_point_distances_m(a_m: np.ndarray, b_m: np.ndarray, points_m: np.ndarray) -> np.ndarray:
    """(N, P) distance from each segment ``a[i] -> b[i]`` to each point."""
    a = np.asarray(a_m, dtype=float).reshape(-1, 1, 2)
    d = np.asarray(b_m, dtype=float).reshape(-1, 1, 2) - a
    p = np.asarray(points_m, dtype=float).reshape(1, -1, 2)
    dd = np.sum(d * d, axis=2)
    f = np.clip(np.sum((p - a) * d, axis=2) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    return np.linalg.norm(p - (a + f[:, :, None] * d), axis=2)


def segment_box_distances_m(a_m: np.ndarray, b_m: np.ndarray, boxes_m: np.ndarray) -> np.ndarray:
    """(N, B) distance from each segment ``a[i] -> b[i]`` to each box ``(x_min, y_min, x_max, y_max)``.

    0 when they meet (slab test); otherwise the smaller of the endpoints' distances
    to the box and the box corners' distances to the segment (two disjoint convex
    shapes in the plane are nearest at a vertex of one of them).
    """
    a = np.asarray(a_m, dtype=float).reshape(-1, 2)
    b = np.asarray(b_m, dtype=float).reshape(-1, 2)
    boxes = np.asarray(boxes_m, dtype=float).reshape(-1, 4)
    lo, hi = boxes[None, :, :2], boxes[None, :, 2:]
    d = (b - a)[:, None, :]
    a3 = a[:, None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (lo - a3) / d, (hi - a3) / d
    inside = (a3 >= lo) & (a3 <= hi)
    enter = np.where(d != 0, np.minimum(t1, t2), np.where(inside, -np.inf, np.inf))
    leave = np.where(d != 0, np.maximum(t1, t2), np.where(inside, np.inf, -np.inf))
    meets = np.maximum(enter.max(axis=2), 0.0) <= np.minimum(leave.min(axis=2), 1.0)

    def point_box(p: np.ndarray) -> np.ndarray:
        gap = np.maximum(np.maximum(lo - p[:, None, :], p[:, None, :] - hi), 0.0)
        return np.linalg.norm(gap, axis=2)

    corners = np.concatenate([boxes[:, [0, 1]], boxes[:, [2, 1]], boxes[:, [0, 3]], boxes[:, [2, 3]]])
    corner = segment_point_distances_m(a, b, corners).reshape(len(a), 4, len(boxes)).min(axis=1)
    dist = np.minimum(np.minimum(point_box(a), point_box(b)), corner)
    return np.where(meets, 0.0, dist)


@dataclass(frozen=True)
class LinearMotion:
    """Eqs. (9)-(10): x(t) = x0 + v cos(theta) t, y(t) = y0 + v sin(theta) t."""

    start_m: tuple[float, float]
    speed_m_s: float
    heading_rad: float
    at_edge: str  # "reflect" | "stop"
    # Where the obstacle's centre may go (the arena; Abdulla & Hadi (2025) starts obstacles on its edge).
    lower_m: tuple[float, float]
    upper_m: tuple[float, float]
    start_s: float = 0.0  # held at the start until then

    def positions_at(self, times_s: np.ndarray) -> np.ndarray:
        t = _held(times_s, self.start_s)
        velocity = self.speed_m_s * np.array([math.cos(self.heading_rad), math.sin(self.heading_rad)])
        lo = np.asarray(self.lower_m)
        hi = np.asarray(self.upper_m)
        start = np.asarray(self.start_m)
        free = start[None, :] + t[:, None] * velocity[None, :]
        if self.at_edge == "reflect":
            span = np.maximum(hi - lo, 1e-12)
            # Fold the unbounded motion into [lo, hi] with a triangle wave.
            phase = np.mod(free - lo, 2.0 * span)
            return lo + np.where(phase <= span, phase, 2.0 * span - phase)
        # "stop": freeze at the first time any coordinate reaches its limit.
        with np.errstate(divide="ignore", invalid="ignore"):
            t_hit = np.where(velocity > 0, (hi - start) / velocity,
                             np.where(velocity < 0, (lo - start) / velocity, np.inf))
        t_stop = max(0.0, float(np.min(t_hit)))
        tc = np.minimum(t, t_stop)
        return start[None, :] + tc[:, None] * velocity[None, :]


@dataclass(frozen=True, eq=False)
class RandomWalkMotion:
    """A random walk over free neighbouring positions, one step per ``period_s``.

    The walk is drawn on first use from its own stream of the run's world seed:
    ``SeedSequence(world_seed, spawn_key=(stream,))``, with ``stream`` the
    obstacle's index in the scenario, so adding an obstacle does not shift the
    others' draws and the planner's seed never changes the world.
    """

    start_m: tuple[float, float]
    radius_m: float
    step_m: float
    period_s: float
    duration_s: float
    lower_m: tuple[float, float]
    upper_m: tuple[float, float]
    static_centres_m: np.ndarray = field(repr=False)
    static_radii_m: np.ndarray = field(repr=False)
    stream: int = 0
    world_seed: int = 0
    # (B, 4) static boxes (x_min, y_min, x_max, y_max): the map's, which the walk never touches.
    static_boxes_m: np.ndarray = field(repr=False, default_factory=lambda: np.zeros((0, 4)))
    steps: str = "compass"  # "grid" | "compass" (module docstring)
    start_s: float = 0.0

    def reseeded(self, world_seed: int) -> "RandomWalkMotion":
        """The same walk description drawn from another world seed."""
        return replace(self, world_seed=int(world_seed))

    @cached_property
    def nodes_m(self) -> np.ndarray:
        """(K+1, 2) position at the start of each period."""
        rng = np.random.default_rng(np.random.SeedSequence(self.world_seed, spawn_key=(self.stream,)))
        # The same 8 directions, counter-clockwise from east, in both readings (the draws index them).
        angles = np.arange(8) * (math.pi / 4.0)
        directions = np.column_stack([np.cos(angles), np.sin(angles)])
        directions[np.abs(directions) < 1e-12] = 0.0
        steps = self.step_m * (np.sign(directions) if self.steps == "grid" else directions)
        count = int(math.ceil(self.duration_s / self.period_s)) + 1
        nodes = np.empty((count + 1, 2))
        nodes[0] = self.start_m
        lo, hi = np.asarray(self.lower_m), np.asarray(self.upper_m)
        boxes = np.asarray(self.static_boxes_m, dtype=float).reshape(-1, 4)
        for k in range(count):
            candidates = nodes[k] + steps
            here = np.repeat(nodes[k][None, :], len(steps), axis=0)
            inside = np.all((candidates >= lo) & (candidates <= hi), axis=1)
            if len(self.static_radii_m):
                gap = segment_point_distances_m(here, candidates, self.static_centres_m) \
                    - self.static_radii_m[None, :] - self.radius_m
                inside &= np.all(gap > 0.0, axis=1)
            if len(boxes):
                inside &= np.all(segment_box_distances_m(here, candidates, boxes) > self.radius_m, axis=1)
            choices = np.flatnonzero(inside)
            nodes[k + 1] = candidates[rng.choice(choices)] if len(choices) else nodes[k]
        return nodes

    def positions_at(self, times_s: np.ndarray) -> np.ndarray:
        t = _held(times_s, self.start_s)
        if not np.any(t > 0.0):  # the start alone: no need to draw the whole walk (scenario checks)
            return np.repeat(np.asarray(self.start_m, dtype=float)[None, :], len(t), axis=0)
        nodes = self.nodes_m
        u = np.clip(t / self.period_s, 0.0, len(nodes) - 1.0)
        k = np.minimum(np.floor(u).astype(int), len(nodes) - 2)
        frac = (u - k)[:, None]
        return nodes[k] * (1.0 - frac) + nodes[k + 1] * frac


@dataclass(frozen=True)
class WaypointMotion:
    """Patrol: from the first point through the others and back to the first, repeatedly."""

    points_m: np.ndarray  # (P, 2); the loop closes back to points_m[0]
    speed_m_s: float
    start_s: float = 0.0  # held at the first point until then

    def positions_at(self, times_s: np.ndarray) -> np.ndarray:
        t = _held(times_s, self.start_s)
        loop = np.vstack([self.points_m, self.points_m[:1]])
        seg = np.linalg.norm(np.diff(loop, axis=0), axis=1)
        total = float(seg.sum())
        if total <= 0.0 or self.speed_m_s <= 0.0:
            return np.repeat(self.points_m[:1], len(t), axis=0)
        s = np.mod(t * self.speed_m_s, total)
        cum = np.concatenate([[0.0], np.cumsum(seg)])
        i = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(seg) - 1)
        frac = ((s - cum[i]) / np.where(seg[i] > 0, seg[i], 1.0))[:, None]
        return loop[i] * (1.0 - frac) + loop[i + 1] * frac


@dataclass(frozen=True)
class Stationary:
    """A static obstacle, for uniform handling."""

    position_m: tuple[float, float]

    def positions_at(self, times_s: np.ndarray) -> np.ndarray:
        t = np.asarray(times_s, dtype=float).reshape(-1)
        return np.repeat(np.asarray(self.position_m, dtype=float)[None, :], len(t), axis=0)
