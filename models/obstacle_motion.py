"""How moving obstacles move: pure functions of time, shared by the simulator
(which moves mocap bodies with them) and the planners (which see t = 0).

Three kinds, each a frozen dataclass with ``positions_at(times_s) -> (T, 2)``:

* :class:`LinearMotion`: constant speed and heading, Abdulla & Hadi (2025)
  Eqs. (9)-(10).  At the arena edge the obstacle either reflects (mirror
  bounce of its centre at the arena edge) or stops, as the scenario file says.
* :class:`RandomWalkMotion`: Hasan et al. (2023)'s dynamic obstacles, a step to a
  random free neighbouring position each period.  Neighbours are the 8
  compass steps of ``step_m``; "free" means inside the arena and not overlapping a
  static obstacle.  We interpolate linearly within a period rather than teleport,
  so the physics sees a continuous motion (the paper's grid jumps have no
  physical meaning).  The walk is drawn from the run's world seed, one stream per obstacle.
* :class:`WaypointMotion`: patrol through points at constant speed, closing the loop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np


@dataclass(frozen=True)
class LinearMotion:
    """Eqs. (9)-(10): x(t) = x0 + v cos(theta) t, y(t) = y0 + v sin(theta) t."""

    start_m: tuple[float, float]
    speed_m_s: float
    heading_rad: float
    at_edge: str  # "reflect" | "stop"
    # Where the obstacle's centre may go (the arena; seed 004 starts obstacles on its edge).
    lower_m: tuple[float, float]
    upper_m: tuple[float, float]

    def positions_at(self, times_s: np.ndarray) -> np.ndarray:
        t = np.asarray(times_s, dtype=float).reshape(-1)
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

    def reseeded(self, world_seed: int) -> "RandomWalkMotion":
        """The same walk description drawn from another world seed."""
        return replace(self, world_seed=int(world_seed))

    @cached_property
    def nodes_m(self) -> np.ndarray:
        """(K+1, 2) position at the start of each period."""
        rng = np.random.default_rng(np.random.SeedSequence(self.world_seed, spawn_key=(self.stream,)))
        angles = np.arange(8) * (math.pi / 4.0)
        steps = self.step_m * np.column_stack([np.cos(angles), np.sin(angles)])
        steps[np.abs(steps) < 1e-12] = 0.0
        count = int(math.ceil(self.duration_s / self.period_s)) + 1
        nodes = np.empty((count + 1, 2))
        nodes[0] = self.start_m
        lo, hi = np.asarray(self.lower_m), np.asarray(self.upper_m)
        for k in range(count):
            candidates = nodes[k] + steps
            inside = np.all((candidates >= lo) & (candidates <= hi), axis=1)
            if len(self.static_radii_m):
                gap = np.linalg.norm(candidates[:, None, :] - self.static_centres_m[None, :, :], axis=2) \
                    - self.static_radii_m[None, :] - self.radius_m
                inside &= np.all(gap > 0.0, axis=1)
            choices = np.flatnonzero(inside)
            nodes[k + 1] = candidates[rng.choice(choices)] if len(choices) else nodes[k]
        return nodes

    def positions_at(self, times_s: np.ndarray) -> np.ndarray:
        t = np.asarray(times_s, dtype=float).reshape(-1)
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

    def positions_at(self, times_s: np.ndarray) -> np.ndarray:
        t = np.asarray(times_s, dtype=float).reshape(-1)
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
