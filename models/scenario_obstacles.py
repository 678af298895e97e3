"""A scenario's ``[[obstacles]]``: cylinders, each static or with a ``motion`` table.

Read with the one TOML reader (:mod:`swarmnav.models.toml_table`): every problem names the file and the
field (``obstacles[3].motion.kind``).  The schema is documented in the README; units are in the field names.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarmnav.models.crowd_agents import AGENT_KINDS, MAX_V_PREF_M_S, AgentMotion, AgentSpec, Crowd
from swarmnav.models.errors import ConfigError
from swarmnav.models.obstacle_motion import WALK_STEPS, LinearMotion, RandomWalkMotion, Stationary, WaypointMotion
from swarmnav.models.scenario_limits import (MAX_MOVING_OBSTACLES, MAX_STATIC_OBSTACLES, MAX_TRACK_SAMPLES,
                                             MAX_WALK_STEPS, MIN_LENGTH_M)
from swarmnav.models.toml_table import NON_NEGATIVE, POSITIVE, TomlTable, above, within
from swarmnav.models.world import Box

MOTION_KINDS = ("linear", "random_walk", "waypoints") + AGENT_KINDS


@dataclass(frozen=True)
class Obstacle:
    """A cylinder; ``motion`` is None for static obstacles."""

    x_m: float
    y_m: float
    radius_m: float
    height_m: float
    motion: LinearMotion | RandomWalkMotion | WaypointMotion | AgentMotion | None = None

    @property
    def moving(self) -> bool:
        return self.motion is not None

    def trajectory(self):
        return self.motion if self.motion is not None else Stationary((self.x_m, self.y_m))


@dataclass(frozen=True)
class ObstacleWorld:
    """What an obstacle's motion is read against: the arena, the run's length and the static map."""

    width_m: float
    height_m: float
    walls: bool
    seed: int
    time_limit_s: float
    control_hz: float
    boxes: tuple[Box, ...]
    on_map: bool  # the scenario has a [map]: random walks take the map's grid steps by default
    timestep_s: float = 0.002  # the physics step: agents are stepped once per whole control period of them


@dataclass(frozen=True)
class _Placed:
    """An obstacle's table and its static fields, read before any motion is."""

    table: TomlTable
    x_m: float
    y_m: float
    radius_m: float
    height_m: float
    motion: object  # the raw ``motion`` value (None: static)


def read_obstacles(top: TomlTable, world: ObstacleWorld) -> tuple[Obstacle, ...]:
    """Every ``[[obstacles]]`` entry: the static fields of all, then the run's size, then each motion.

    Raises:
        ConfigError: a field of the wrong type or range, a centre outside the arena, or more precomputed
            motion than the stated maxima allow (checked before any of it is drawn).
    """
    tables = top.tables("obstacles", [])
    if len(tables) > MAX_STATIC_OBSTACLES + MAX_MOVING_OBSTACLES:
        top.fail("obstacles", f"{len(tables):,} entries, at most {MAX_STATIC_OBSTACLES + MAX_MOVING_OBSTACLES:,}")
    placed = [_place(t, world) for t in tables]
    static = [p for p in placed if p.motion is None]
    if len(placed) - len(static) > MAX_MOVING_OBSTACLES:
        top.fail("obstacles", f"{len(placed) - len(static):,} moving obstacles, at most {MAX_MOVING_OBSTACLES:,} "
                              "(MAX_MOVING_OBSTACLES)")
    if len(static) > MAX_STATIC_OBSTACLES:
        top.fail("obstacles", f"{len(static):,} static obstacles, at most {MAX_STATIC_OBSTACLES:,} "
                              "(MAX_STATIC_OBSTACLES: a run's exact reference path grows about as n^3)")
    static_centres = np.array([(p.x_m, p.y_m) for p in static], dtype=float).reshape(-1, 2)
    static_radii = np.array([p.radius_m for p in static], dtype=float)
    _check_motion_size(placed, world, top.source)
    box_array_m = np.array([[b.x_min_m, b.y_min_m, b.x_max_m, b.y_max_m] for b in world.boxes],
                           dtype=float).reshape(-1, 4)
    motions: list = []
    agents: list[tuple[int, AgentSpec]] = []
    for i, p in enumerate(placed):
        motion = None
        if p.motion is not None:
            m = p.table.table("motion")
            motion = _motion(m, p, i, world, static_centres, static_radii, box_array_m)
            if isinstance(motion, AgentSpec):
                agents.append((i, motion))
            m.close()
        p.table.close()
        motions.append(motion)
    if agents:
        _bind_crowd(motions, agents, world, np.column_stack([static_centres, static_radii]), box_array_m,
                    top.source)
    return tuple(Obstacle(p.x_m, p.y_m, p.radius_m, p.height_m, motion) for p, motion in zip(placed, motions))


def _bind_crowd(motions: list, agents: list[tuple[int, AgentSpec]], world: ObstacleWorld, discs: np.ndarray,
                boxes: np.ndarray, source: str | None) -> None:
    """One :class:`Crowd` for every agent of the scenario; each agent's motion becomes its place in it."""
    seen = {spec.sees_robot for _, spec in agents}
    if len(seen) > 1:
        first = next(i for i, spec in agents if spec.sees_robot != agents[0][1].sees_robot)
        raise ConfigError(f"obstacles[{first}].motion.sees_robot", "must be the same for every agent of a "
                          f"scenario (obstacles[{agents[0][0]}] has {str(agents[0][1].sees_robot).lower()})", source)
    k = max(int(round(1.0 / (world.control_hz * world.timestep_s))), 1)
    dt_s = k * world.timestep_s
    steps = int(math.floor(world.time_limit_s / dt_s + 1e-9))
    crowd = Crowd(tuple(spec for _, spec in agents), discs, boxes, (world.width_m, world.height_m), world.walls,
                  dt_s, steps, world.seed)
    for k_agent, (i, _) in enumerate(agents):
        motions[i] = AgentMotion(crowd, k_agent)


def _place(t: TomlTable, world: ObstacleWorld) -> _Placed:
    x, y = t.number("x"), t.number("y")
    if not (0.0 <= x <= world.width_m and 0.0 <= y <= world.height_m):
        t.fail("x" if not 0.0 <= x <= world.width_m else "y",
               f"the centre ({x:g}, {y:g}) must lie in the arena [0, {world.width_m:g}] x [0, {world.height_m:g}]")
    radius = t.number("radius_m", bounds=within(MIN_LENGTH_M))
    height = t.number("height_m", 0.5, bounds=within(MIN_LENGTH_M))
    return _Placed(t, x, y, radius, height, t.raw("motion", None))


def _motion(m: TomlTable, p: _Placed, index: int, world: ObstacleWorld, static_centres: np.ndarray,
            static_radii: np.ndarray, box_array_m: np.ndarray):
    kind = m.string("kind", choices=MOTION_KINDS)
    # Centres stay inside the arena: Abdulla & Hadi (2025) places obstacles on its edge.
    lower, upper = (0.0, 0.0), (world.width_m, world.height_m)
    start_s = m.number("start_s", 0.0, bounds=NON_NEGATIVE)  # held at its start until then
    if kind == "linear":
        return LinearMotion((p.x_m, p.y_m), m.number("speed_m_s", bounds=NON_NEGATIVE),
                            math.radians(m.number("heading_deg")),
                            m.string("at_edge", choices=("reflect", "stop")), lower, upper, start_s)
    if kind == "random_walk":
        # A walker's disc stays inside the walls and off the map's boxes; on a map it walks the
        # paper's grid (Hasan et al. (2023)) by default, elsewhere compass steps (obstacle_motion's docstring).
        if world.walls:
            r = p.radius_m
            lower, upper = (r, r), (world.width_m - r, world.height_m - r)
        return RandomWalkMotion(
            (p.x_m, p.y_m), p.radius_m, m.number("step_m", bounds=POSITIVE), m.number("period_s", bounds=POSITIVE),
            world.time_limit_s, lower, upper, static_centres, static_radii, stream=index, world_seed=world.seed,
            static_boxes_m=box_array_m,
            steps=m.string("steps", "grid" if world.on_map else "compass", choices=WALK_STEPS), start_s=start_s)
    if kind in AGENT_KINDS:
        return _agent(m, p, kind, world, start_s)
    points = _points(m, world)
    return WaypointMotion(np.vstack([[p.x_m, p.y_m], points]), m.number("speed_m_s", bounds=POSITIVE), start_s)


def _agent(m: TomlTable, p: _Placed, kind: str, world: ObstacleWorld, start_s: float) -> AgentSpec:
    """An agent's ``goal = [x, y]`` (walks there and stays) or ``goals`` (a loop of two or more points)."""
    if m.has("goal") == m.has("goals"):
        m.fail("goal", "an agent needs exactly one of goal = [x, y] and goals = [[x, y], ...] (a loop)")
    if m.has("goal"):
        goals = _points(m, world, "goal", [m.raw("goal")])
    else:
        goals = _points(m, world, "goals")
        if len(goals) < 2:
            m.fail("goals", "a loop needs at least two points (one goal: goal = [x, y])")
    v_pref = m.number("v_pref_m_s", 1.0, bounds=above(0.0, MAX_V_PREF_M_S))
    return AgentSpec(kind, (p.x_m, p.y_m), p.radius_m, tuple((float(x), float(y)) for x, y in goals), v_pref,
                     m.boolean("sees_robot", False), start_s)


def _points(m: TomlTable, world: ObstacleWorld, key: str = "points", points=None) -> np.ndarray:
    """A motion's ``points`` (or ``key``): [x, y] pairs inside the arena."""
    points = m.raw(key) if points is None else points
    if (not isinstance(points, list) or not points
            or not all(isinstance(p, list) and len(p) == 2 and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for v in p) for p in points)):
        m.fail(key, "expected [x, y]" if key == "goal" else "expected a non-empty array of [x, y] number pairs")
    arr = np.array(points, dtype=float)
    if not np.all(np.isfinite(arr)):
        m.fail(key, "must be finite")
    outside = np.flatnonzero((arr < 0.0).any(axis=1) | (arr[:, 0] > world.width_m) | (arr[:, 1] > world.height_m))
    if len(outside):
        m.fail(key if key == "goal" else f"{key}[{outside[0]}]", f"({arr[outside[0], 0]:g}, {arr[outside[0], 1]:g}) must lie "
                                        f"in the arena [0, {world.width_m:g}] x [0, {world.height_m:g}]")
    return arr


def _check_motion_size(placed: list[_Placed], world: ObstacleWorld, source: str | None) -> None:
    """Precomputed obstacle motion against :data:`MAX_TRACK_SAMPLES` and :data:`MAX_WALK_STEPS`.

    Only the raw ``kind`` and ``period_s`` are looked at here; their types are
    checked (with the same field names) when the motion is parsed.
    """
    moving = [(i, p.motion) for i, p in enumerate(placed) if p.motion is not None]
    time_limit_s = world.time_limit_s
    control_steps = math.floor(time_limit_s * world.control_hz + 1e-9) + 1
    if moving and control_steps * len(moving) > MAX_TRACK_SAMPLES:
        raise ConfigError("time_limit_s", f"{len(moving)} moving obstacles over {control_steps:,} control steps "
                          f"need {control_steps * len(moving):,} precomputed positions "
                          f"(at most {MAX_TRACK_SAMPLES:,})", source)
    walk_steps = 0
    for i, raw in moving:
        if not isinstance(raw, dict) or raw.get("kind") != "random_walk":
            continue
        period = raw.get("period_s")
        if isinstance(period, bool) or not isinstance(period, (int, float)) or not period > 0 \
                or not math.isfinite(period):
            continue  # reported as a type or range error when the motion is parsed
        walk_steps += math.ceil(min(time_limit_s / period, 1e300)) + 2
        if walk_steps > MAX_WALK_STEPS:
            raise ConfigError(f"obstacles[{i}].motion.period_s",
                              f"random walks with periods down to {period:g} s over {time_limit_s:g} s need "
                              f"{walk_steps:.4g} steps drawn up front (at most {MAX_WALK_STEPS:,} over all walks)",
                              source)
