"""Dynamic scenarios from a kind and a seed: ``swarmnav scenarios generate KIND --seed N``.

A pure function of its options: the same kind, seed and options give the same
TOML text, in the documented scenario format, with the command that made it in
its description.  The robot starts on the left, one metre in from the arena's
edge, facing the goal on the right at the same height; the start-goal line is
where the obstacles are put in the way.  Kinds:

* ``crossing``: cylinders crossing the start-goal line at right angles, spread
  along it, each timed to reach the line about when the robot (at its top
  speed) gets there.
* ``head_on``: cylinders on the line, in its far half, driving at the robot.
* ``overtake``: slower cylinders ahead on the line, driving toward the goal
  (they stop at the arena's edge).
* ``crowd``: random walks (Hasan et al. 2023's dynamic obstacles) scattered over
  the arena, clear of the start and the goal; they depend on the run's world seed.
* ``fast_crossing``: ``crossing`` with obstacles faster than the robot (``speed_ratio`` above 1).
* ``dense_crowd``: ``crowd`` packed closer (0.1 m apart instead of 0.3, 0.8 m clear of the ends).
* ``door_patrol``: a wall of static discs across the arena, half-way, with one door (1.2 m clear) near the
  line; the cylinders patrol back and forth through the door (waypoint loops, staggered starts).
* ``corridor``: a corridor 1.6 m wide of static discs along the line; the cylinders drive at the robot in
  two lanes (head-on traffic).
* ``mixed``: about a third crossing, the rest random walkers.
* ``crowdnav_circle``, ``crowdnav_square``: CrowdNav's test cases (Chen et al. 2019), ``--humans N`` ORCA
  humans, seen by them with ``--robot-visible``; their own arena, robot and sensing
  (:mod:`swarmnav.models.crowdnav_scenarios`).

Speeds are ``speed_ratio`` times the robot's top speed, radii are drawn in
``[radius_min_m, radius_max_m]``.  A request that cannot be met (more
obstacles than fit) is a :class:`ConfigError` naming the option.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from swarmnav.models.crowdnav_scenarios import CROWDNAV_KINDS, MAX_HUMANS, crowdnav_lines
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario_limits import MAX_MOVING_OBSTACLES, MAX_NAME_CHARS, MAX_SENSORS, MIN_LENGTH_M
from swarmnav.models.toml_table import above, check_integer, check_number, check_string, within

KINDS = ("crossing", "head_on", "overtake", "crowd", "fast_crossing", "dense_crowd", "door_patrol", "corridor",
         "mixed") + CROWDNAV_KINDS
ENDPOINT_INSET_M = 1.0
SOURCE = "scenarios generate"


@dataclass(frozen=True)
class GeneratorOptions:
    """What can be asked of the generator (the CLI's options, ``--speed-ratio`` for ``speed_ratio``)."""

    obstacles: int = 4
    speed_ratio: float = 0.5
    radius_min_m: float = 0.2
    radius_max_m: float = 0.35
    arena_m: float = 8.0
    sensor_model: str = "rangefinder"
    range_m: float = 1.0
    sensor_count: int = 12
    robot_speed_m_s: float = 0.2
    time_limit_s: float = 0.0  # 0: three times the straight drive, plus 20 s
    planner: str = "astar"
    navigator: str = "replan"
    name: str = ""
    humans: int = 5  # crowdnav_* kinds only
    robot_visible: bool = False  # crowdnav_* kinds only: the humans see the robot

    def check(self, kind: str) -> None:
        def bad(option: str, problem: str) -> None:
            raise ConfigError(f"--{option.replace('_', '-')}", problem, SOURCE)
        if kind not in KINDS:
            raise ConfigError("KIND", f"unknown kind {kind!r} (expected one of: {', '.join(KINDS)})", SOURCE)
        for f in fields(self):  # every option against its declared range first (NaN, inf, huge counts)
            option, value = f"--{f.name.replace('_', '-')}", getattr(self, f.name)
            if f.type in ("bool", bool):
                if not isinstance(value, bool):
                    bad(f.name, f"expected true or false, got {value!r}")
            elif f.name in OPTION_RANGES and f.type in ("int", int):
                check_integer(value, option, SOURCE, OPTION_RANGES[f.name])
            elif f.name in OPTION_RANGES:
                check_number(value, option, SOURCE, OPTION_RANGES[f.name])
            else:
                check_string(value, option, SOURCE)
                if len(value) > MAX_NAME_CHARS:
                    bad(f.name, f"at most {MAX_NAME_CHARS} characters, got {len(value):,}")
        if self.obstacles < 1:
            bad("obstacles", f"must be at least 1, got {self.obstacles}")
        for key in ("speed_ratio", "radius_min_m", "arena_m", "range_m", "robot_speed_m_s"):
            if not getattr(self, key) > 0:
                bad(key, f"must be positive, got {getattr(self, key)!r}")
        if self.radius_max_m < self.radius_min_m:
            bad("radius_max_m", f"must be at least --radius-min-m ({self.radius_min_m:g}), got {self.radius_max_m:g}")
        if kind == "fast_crossing" and self.speed_ratio <= 1.0:
            bad("speed_ratio", f"fast crossers need a ratio above 1, got {self.speed_ratio:g}")
        if kind == "overtake" and self.speed_ratio >= 1.0:
            bad("speed_ratio", f"overtaking needs slower obstacles (a ratio below 1), got {self.speed_ratio:g}")
        if self.sensor_model not in ("rangefinder", "detector"):
            bad("sensor_model", f"unknown sensing model {self.sensor_model!r} (expected rangefinder or detector)")
        if self.sensor_count < 1:
            bad("sensor_count", f"must be at least 1, got {self.sensor_count}")
        if not self.time_limit_s >= 0:  # NaN too
            bad("time_limit_s", f"must be a number not below 0, got {self.time_limit_s:g}")
        if self.time_limit_s > 0:  # the file must load: whole control periods of the default sim settings
            from swarmnav.models.scenario import SimSettings, check_run_size
            try:
                check_run_size(self.time_limit_s, SimSettings(), SOURCE)
            except ConfigError as exc:
                bad("time_limit_s", exc.problem)
        if self.arena_m <= 2 * ENDPOINT_INSET_M + 1.0:
            bad("arena_m", f"must exceed {2 * ENDPOINT_INSET_M + 1.0:g} m (start and goal sit "
                           f"{ENDPOINT_INSET_M:g} m in from the edges), got {self.arena_m:g}")


# The declared range of every numeric option (checked before anything is drawn).
OPTION_RANGES = {
    "obstacles": within(1, MAX_MOVING_OBSTACLES), "speed_ratio": above(0, 100),
    "radius_min_m": within(MIN_LENGTH_M, 100), "radius_max_m": within(MIN_LENGTH_M, 100),
    "arena_m": above(0, 200), "range_m": within(MIN_LENGTH_M, 1000), "sensor_count": within(1, MAX_SENSORS),
    "robot_speed_m_s": above(0, 100), "time_limit_s": within(0, 1e6), "humans": within(1, MAX_HUMANS),
}


def command_line(kind: str, seed: int, options: GeneratorOptions) -> str:
    """The ``swarmnav scenarios generate`` command that reproduces a file (non-default options only)."""
    parts = [f"swarmnav scenarios generate {kind} --seed {seed}"]
    default = GeneratorOptions()
    for f in fields(options):
        value = getattr(options, f.name)
        if isinstance(value, bool):
            if value:
                parts.append(f"--{f.name.replace('_', '-')}")
        elif value != getattr(default, f.name):
            parts.append(f"--{f.name.replace('_', '-')} {value:g}" if isinstance(value, float)
                         else f"--{f.name.replace('_', '-')} {value}")
    return " ".join(parts)


def generate(kind: str, seed: int, options: GeneratorOptions | None = None) -> str:
    """The TOML text of a generated scenario.

    Raises:
        ConfigError: an unknown kind, a bad option, or more obstacles than fit (naming the option).
    """
    options = options or GeneratorOptions()
    options.check(kind)
    if seed < 0:
        raise ConfigError("--seed", f"must not be negative, got {seed}", SOURCE)
    if kind in CROWDNAV_KINDS:
        head, obstacles = crowdnav_lines(kind, seed, options.humans, options.robot_visible, options.time_limit_s,
                                         options.planner, options.navigator)
        name = options.name or f"{kind.replace('_', '-')}-{seed}"
        return _text([f'name = "{name}"', f'description = "Generated: {command_line(kind, seed, options)}"',
                      f"seed = {seed}"] + head, obstacles)
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(KINDS.index(kind),)))
    w = options.arena_m
    y_line = w / 2.0
    start = (ENDPOINT_INSET_M, y_line)
    goal = (w - ENDPOINT_INSET_M, y_line)
    radii = rng.uniform(options.radius_min_m, options.radius_max_m, options.obstacles)
    speed = options.speed_ratio * options.robot_speed_m_s
    obstacles = {"crossing": _crossing, "head_on": _head_on, "overtake": _overtake, "crowd": _crowd,
                 "fast_crossing": _crossing, "dense_crowd": _dense_crowd, "door_patrol": _door_patrol,
                 "corridor": _corridor, "mixed": _mixed}[kind](rng, options, radii, speed, start, goal)
    straight_s = (goal[0] - start[0]) / options.robot_speed_m_s
    time_limit = options.time_limit_s or round(3.0 * straight_s + 20.0)
    name = options.name or f"dyn-{kind.replace('_', '-')}-{seed}"
    lines = [
        f'name = "{name}"',
        f'description = "Generated: {command_line(kind, seed, options)}"',
        f"seed = {seed}",
        f"time_limit_s = {time_limit:.12g}",
        f"arena = {{ width_m = {w:g}, height_m = {w:g}, walls = false }}",
        f"robot = {{ radius_m = 0.15, max_speed_m_s = {options.robot_speed_m_s:g} }}",
        f"start = {{ x = {start[0]:g}, y = {start[1]:g}, heading_deg = 0.0 }}",
        f"goal = {{ x = {goal[0]:g}, y = {goal[1]:g}, tolerance_m = 0.1 }}",
        f'sensors = {{ model = "{options.sensor_model}", count = {options.sensor_count}, range_m = {options.range_m:g} }}',
        f'planner = {{ name = "{options.planner}", params = {{}} }}',
        f'navigator = {{ name = "{options.navigator}", params = {{}} }}',
        "sim = { cell_m = 0.1 }",
    ]
    return _text(lines, obstacles)


def _text(lines: list[str], obstacles) -> str:
    for x, y, r, motion in obstacles:
        lines += ["", "[[obstacles]]", f"x = {x:.4f}", f"y = {y:.4f}", f"radius_m = {r:.4f}"]
        if motion is not None:  # None: a static disc (the walls of doors and corridors)
            lines.append(f"motion = {motion}")
    return "\n".join(lines) + "\n"


def _linear(speed: float, heading_deg: float, at_edge: str) -> str:
    return f'{{ kind = "linear", speed_m_s = {speed:.4f}, heading_deg = {heading_deg:g}, at_edge = "{at_edge}" }}'


def _too_many(options: GeneratorOptions, fit: int, why: str) -> ConfigError:
    return ConfigError("--obstacles", f"{options.obstacles} obstacles do not fit ({why}: at most {fit})", SOURCE)


def _spread(rng, options, radii, lo: float, hi: float, why: str) -> np.ndarray:
    """Positions along [lo, hi] for discs of the given radii, a robot's width (0.3 m) apart, jittered."""
    gap = 0.3
    need = float(np.sum(2 * radii)) + gap * (len(radii) - 1)
    if need > hi - lo:
        per = 2 * options.radius_max_m + gap
        raise _too_many(options, max(int((hi - lo + gap) // per), 0), why)
    slack = (hi - lo) - need
    cuts = np.sort(rng.uniform(0.0, slack, len(radii)))
    cursor, out = lo, []
    for k, r in enumerate(radii):
        offset = cuts[k] - (cuts[k - 1] if k else 0.0)
        cursor += offset
        out.append(cursor + r)
        cursor += 2 * r + gap
    return np.array(out)


def _crossing(rng, options, radii, speed, start, goal):
    xs = _spread(rng, options, radii, start[0] + 1.0, goal[0] - 0.5, "crossing points along the start-goal line")
    out = []
    for x, r in zip(xs, radii):
        v = speed * rng.uniform(0.7, 1.0)
        arrive_s = (x - start[0]) / options.robot_speed_m_s
        side = 1.0 if rng.random() < 0.5 else -1.0
        offset = min(v * arrive_s * rng.uniform(0.8, 1.2), options.arena_m / 2.0)
        out.append((x, start[1] + side * offset, r, _linear(v, -90.0 * side, "reflect")))
    return out


def _head_on(rng, options, radii, speed, start, goal):
    mid = 0.5 * (start[0] + goal[0])
    xs = _spread(rng, options, radii, mid, goal[0] - 0.6, "places on the far half of the line, short of the goal")
    return [(x, start[1] + rng.uniform(-0.05, 0.05), r, _linear(speed * rng.uniform(0.8, 1.0), 180.0, "stop"))
            for x, r in zip(xs, radii)]


def _overtake(rng, options, radii, speed, start, goal):
    xs = _spread(rng, options, radii, start[0] + 0.8, goal[0] - 1.0, "places ahead of the robot on the line")
    return [(x, start[1] + rng.uniform(-0.05, 0.05), r, _linear(speed * rng.uniform(0.8, 1.0), 0.0, "stop"))
            for x, r in zip(xs, radii)]


def _crowd(rng, options, radii, speed, start, goal, gap_m: float = 0.3, ends_m: float = 1.0, placed=None):
    w = options.arena_m
    placed = list(placed or [])
    first = len(placed)
    for r in radii:
        for _ in range(200):
            x, y = rng.uniform(r, w - r, 2)
            clear_of_ends = all(math.hypot(x - px, y - py) > ends_m + r for px, py in (start, goal))
            if clear_of_ends and all(math.hypot(x - px, y - py) > r + pr + gap_m for px, py, pr in placed):
                placed.append((float(x), float(y), float(r)))
                break
        else:
            raise _too_many(options, len(placed), f"no free place for obstacle {len(placed)} in the "
                                                  f"{w:g} x {w:g} m arena")
    step_m = 0.5
    period_s = step_m / speed
    motion = f'{{ kind = "random_walk", step_m = {step_m:g}, period_s = {period_s:.4f} }}'
    return [(x, y, r, motion) for x, y, r in placed[first:]]


def _dense_crowd(rng, options, radii, speed, start, goal):
    return _crowd(rng, options, radii, speed, start, goal, gap_m=0.1, ends_m=0.8)


WALL_RADIUS_M = 0.12   # the static discs of walls, WALL_SPACING_M apart (they overlap: a wall with no gap)
WALL_SPACING_M = 0.2


def _wall(a: tuple[float, float], b: tuple[float, float]) -> list:
    """Static discs from a to b (centres), WALL_SPACING_M apart."""
    length = math.hypot(b[0] - a[0], b[1] - a[1])
    count = max(int(math.ceil(length / WALL_SPACING_M)), 1) + 1
    return [(a[0] + (b[0] - a[0]) * k / (count - 1), a[1] + (b[1] - a[1]) * k / (count - 1), WALL_RADIUS_M, None)
            for k in range(count)]


def _waypoints(points: list[tuple[float, float]], speed: float, start_s: float) -> str:
    pts = ", ".join(f"[{x:.4f}, {y:.4f}]" for x, y in points)
    return f'{{ kind = "waypoints", points = [{pts}], speed_m_s = {speed:.4f}, start_s = {start_s:.3f} }}'


def _door_patrol(rng, options, radii, speed, start, goal):
    w = options.arena_m
    x_wall = w / 2.0
    door_y = start[1] + rng.uniform(-1.0, 1.0)
    half = 0.6 + WALL_RADIUS_M  # 1.2 m clear between the wall discs' surfaces
    out = _wall((x_wall, 0.0), (x_wall, door_y - half)) + _wall((x_wall, door_y + half), (x_wall, w))
    for r in radii:
        if r > 0.6:
            raise ConfigError("--radius-max-m", f"a patroller must fit the 1.2 m door (radius at most 0.6), "
                                                f"got {r:.3g}", SOURCE)
        reach = rng.uniform(1.0, x_wall - start[0] - 0.8)
        y = door_y + rng.uniform(-1.0, 1.0) * max(0.6 - r - 0.05, 0.0)
        v = speed * rng.uniform(0.8, 1.0)
        period = 4.0 * reach / v
        out.append((x_wall - reach, y, r, _waypoints([(x_wall - reach, y), (x_wall + reach, y)], v,
                                                     rng.uniform(0.0, 0.5 * period))))
    return out


def _corridor(rng, options, radii, speed, start, goal):
    half = 0.8 + WALL_RADIUS_M  # 1.6 m clear between the walls' surfaces
    x0, x1 = start[0] + 0.6, goal[0] - 0.6
    out = _wall((x0, start[1] - half), (x1, start[1] - half)) + _wall((x0, start[1] + half), (x1, start[1] + half))
    mid = 0.5 * (start[0] + goal[0])
    xs = _spread(rng, options, radii, mid - 1.0, goal[0] - 0.6, "places in the corridor, short of the goal")
    for k, (x, r) in enumerate(zip(xs, radii)):
        lane = (1.0 if k % 2 == 0 else -1.0) * min(0.4, 0.8 - r - 0.02)
        out.append((x, start[1] + lane, r, _linear(speed * rng.uniform(0.8, 1.0), 180.0, "stop")))
    return out


def _mixed(rng, options, radii, speed, start, goal):
    crossers = max(1, len(radii) // 3)
    out = _crossing(rng, options, radii[:crossers], speed, start, goal)
    placed = [(x, y, r) for x, y, r, _ in out]
    return out + _crowd(rng, options, radii[crossers:], speed, start, goal, placed=placed)
