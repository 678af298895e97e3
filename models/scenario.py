"""Scenarios are data: TOML files under ``models/scenarios/``, validated on load.

Every problem in a file raises :class:`models.errors.ConfigError` naming the
file, the field (a dotted path such as ``obstacles[3].motion.kind``) and what is
wrong.  The schema is documented in the README; units are in the field names.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path as FilePath
from typing import Any

import numpy as np

from swarmnav.models.obstacle_motion import WALK_STEPS, LinearMotion, RandomWalkMotion, Stationary, WaypointMotion
from swarmnav.models.errors import ConfigError
from swarmnav.models.seeds import Seeds
from swarmnav.models.world import Box, Disc, OccupancyGrid, Pose2D, Rect, endpoint_problem

SCENARIO_DIR = FilePath(__file__).resolve().parent / "scenarios"
#: Folders of scenario files that installed packages declare (entry-point group ``swarmnav.scenarios``, added by
#: ``swarmnav.sim.plugins``): their names resolve after the bundled ones.
EXTRA_SCENARIO_DIRS: list[FilePath] = []
MOTION_KINDS = ("linear", "random_walk", "waypoints")

# Stated maxima (README "Limits"), each checked before anything of that size is
# allocated, so an oversized request is a ConfigError naming the field, not an
# exhausted memory.
MAX_NAME_CHARS = 64            # ``name`` becomes part of the default log file name
MAX_SENSORS = 360              # rangefinders, evenly spaced (1 degree apart at most)
MIN_ROBOT_RADIUS_M = 0.05      # smaller robots than the base scaled to 1/3 of its size are not modelled
MAX_GRID_CELLS = 16_000_000    # the planning grid: 200 x 200 m at 0.05 m per cell
MAX_CONTROL_STEPS = 1_000_000  # time_limit_s x control_hz (the runner keeps every pose): 5.5 h at 50 Hz
MAX_PHYSICS_STEPS = 200_000_000  # time_limit_s / timestep_s: 111 h at 500 Hz
MAX_TRACK_SAMPLES = 20_000_000   # control steps x moving obstacles (positions computed up front)
MIN_LENGTH_M = 0.001           # obstacle radii and heights, map cells, sensor range: MuJoCo's XML keeps ~6 digits
MIN_TIMESTEP_S = 1e-6
MAX_WALK_STEPS = 100_000       # random-walk periods over all walks, drawn up front (about 3 s of work)


@dataclass(frozen=True)
class Obstacle:
    """A cylinder; ``motion`` is None for static obstacles."""

    x_m: float
    y_m: float
    radius_m: float
    height_m: float
    motion: LinearMotion | RandomWalkMotion | WaypointMotion | None = None

    @property
    def moving(self) -> bool:
        return self.motion is not None

    def trajectory(self):
        return self.motion if self.motion is not None else Stationary((self.x_m, self.y_m))


@dataclass(frozen=True)
class SimSettings:
    timestep_s: float = 0.002
    control_hz: float = 50.0
    stop_on_collision: bool = False
    danger_m: float = 0.1  # clearance below which time counts as "in danger" (navigation metrics)


SENSOR_MODELS = ("rangefinder", "detector")


@dataclass(frozen=True, eq=False)
class Scenario:
    """A validated scenario.  ``source_text`` is the TOML as read (logged with every run)."""

    name: str
    description: str
    seed: int
    time_limit_s: float
    arena_width_m: float
    arena_height_m: float
    walls: bool
    robot_radius_m: float
    max_speed_m_s: float
    clearance_m: float
    start: Pose2D
    goal: Pose2D
    goal_tolerance_m: float
    sensor_count: int
    sensor_range_m: float
    planner_name: str
    planner_params: dict[str, Any]
    navigator_name: str
    navigator_params: dict[str, Any]
    obstacles: tuple[Obstacle, ...]
    sim: SimSettings
    cell_m: float
    source_text: str
    source_path: str
    boxes: tuple[Box, ...] = ()
    world_seed: int = 0  # random obstacle motions are drawn from it; the file's ``seed`` by default
    map_grid: OccupancyGrid | None = field(default=None, repr=False)
    # [map].pairs: start/goal cells (column, row from the bottom) as [x0, y0, x1, y1], for `bench grid`
    map_pairs: tuple[tuple[int, int, int, int], ...] = ()
    # How moving obstacles are sensed: "rangefinder" (rays, tracked) or "detector" (true state within range_m).
    sensor_model: str = "rangefinder"
    # The user vouched for the file's code parameters (--trust-code): see models.parameters.refuse_code.
    trust_code: bool = False

    @property
    def bounds(self) -> Rect:
        """The arena, [0, width] x [0, height]."""
        return Rect(0.0, 0.0, self.arena_width_m, self.arena_height_m)

    def planning_bounds(self, inflation_m: float) -> Rect:
        """Where the robot's centre may go: the arena, shrunk by ``inflation_m`` when it has walls."""
        if not self.walls:
            return self.bounds
        return Rect(inflation_m, inflation_m, self.arena_width_m - inflation_m,
                    self.arena_height_m - inflation_m)

    @property
    def seeds(self) -> Seeds:
        """The scenario's seeds: the file's ``seed`` for the planner, ``world_seed`` for the world."""
        return Seeds(self.seed, self.world_seed)

    def with_world_seed(self, world_seed: int) -> "Scenario":
        """This scenario with every random obstacle motion drawn from ``world_seed``."""
        obstacles = tuple(replace(ob, motion=ob.motion.reseeded(world_seed))
                          if isinstance(ob.motion, RandomWalkMotion) else ob for ob in self.obstacles)
        return replace(self, obstacles=obstacles, world_seed=int(world_seed))

    def with_clearance(self, clearance_m: float, field_name: str = "clearance_m") -> "Scenario":
        """This scenario with the planning clearance beyond the robot radius set to ``clearance_m``.

        Raises:
            ConfigError: negative, or the scenario plans on a map inflated when it was read (a map with
                only moving obstacles): its clearance is part of that map.
        """
        clearance_m = float(clearance_m)
        if not 0.0 <= clearance_m < math.inf:
            raise ConfigError(field_name, f"must be a finite non-negative number, got {clearance_m:g}",
                              self.source_path)
        if clearance_m == self.clearance_m:
            return self
        if self.map_grid is not None:
            raise ConfigError(field_name, f"cannot be changed for scenario {self.name!r}: it plans on a map "
                                          "inflated by its own robot.clearance_m when it was read",
                              self.source_path)
        return replace(self, clearance_m=clearance_m)

    def discs_at(self, time_s: float = 0.0) -> tuple[Disc, ...]:
        """Every obstacle's footprint at a given time."""
        out = []
        for ob in self.obstacles:
            x, y = ob.trajectory().positions_at(np.array([time_s]))[0]
            out.append(Disc(float(x), float(y), ob.radius_m))
        return tuple(out)



class _Table:
    """Typed access to one TOML table that remembers where it is, for error messages."""

    def __init__(self, data: Any, where: str, source: str):
        self.where = where
        self.source = source
        if not isinstance(data, dict):
            self.fail("", f"expected a table, got {type(data).__name__}")
        self.data = data
        self.used: set[str] = set()

    def path(self, key: str) -> str:
        return f"{self.where}.{key}" if self.where and key else (self.where or key)

    def fail(self, key: str, problem: str):
        raise ConfigError(self.path(key), problem, self.source)

    def has(self, key: str) -> bool:
        return key in self.data

    def raw(self, key: str, default: Any = ..., ) -> Any:
        self.used.add(key)
        if key not in self.data:
            if default is ...:
                self.fail(key, "is required")
            return default
        return self.data[key]

    def number(self, key: str, default: Any = ..., *, positive: bool = False,
               non_negative: bool = False, minimum: float | None = None) -> float:
        value = self.raw(key, default)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(key, f"expected a number, got {value!r}")
        value = float(value)
        if not math.isfinite(value):
            self.fail(key, f"must be finite, got {value}")
        if positive and value <= 0:
            self.fail(key, f"must be positive, got {value:g}")
        if non_negative and value < 0:
            self.fail(key, f"must not be negative, got {value:g}")
        if minimum is not None and value < minimum:
            self.fail(key, f"must be at least {minimum:g}, got {value:g}")
        return value

    def integer(self, key: str, default: Any = ..., *, minimum: int | None = None,
                maximum: int | None = None) -> int:
        value = self.raw(key, default)
        if isinstance(value, bool) or not isinstance(value, int):
            self.fail(key, f"expected an integer, got {value!r}")
        if minimum is not None and value < minimum:
            self.fail(key, f"must be at least {minimum}, got {value}")
        if maximum is not None and value > maximum:
            self.fail(key, f"must be at most {maximum}, got {value}")
        return int(value)

    def boolean(self, key: str, default: Any = ...) -> bool:
        value = self.raw(key, default)
        if not isinstance(value, bool):
            self.fail(key, f"expected true or false, got {value!r}")
        return value

    def string(self, key: str, default: Any = ..., choices: tuple[str, ...] | None = None) -> str:
        value = self.raw(key, default)
        if not isinstance(value, str):
            self.fail(key, f"expected a string, got {value!r}")
        if choices is not None and value not in choices:
            self.fail(key, f"unknown value {value!r} (expected one of: {', '.join(choices)})")
        return value

    def table(self, key: str, default: Any = ...) -> "_Table":
        return _Table(self.raw(key, default), self.path(key), self.source)

    def close(self) -> None:
        """Reject keys that were never read."""
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            key = unknown[0]
            # A key that would not read as one (empty, control characters) is shown quoted.
            self.fail(key if key.isprintable() and key.strip() else repr(key), "unknown key")


def list_scenarios() -> list[str]:
    """Names of the bundled scenarios (file stems under models/scenarios/), then those of installed packages."""
    names = {p.stem for p in SCENARIO_DIR.glob("*.toml")}
    for folder in EXTRA_SCENARIO_DIRS:
        names.update(p.stem for p in folder.glob("*.toml"))
    return sorted(names)


def resolve_scenario_path(name_or_path: str) -> FilePath:
    """A bundled scenario name, or a path to a .toml file."""
    candidate = FilePath(name_or_path)
    if candidate.suffix == ".toml" or candidate.exists() or "/" in name_or_path:
        if not candidate.is_file():
            raise ConfigError("scenario", "file does not exist", str(candidate))
        return candidate
    bundled = next((folder / f"{name_or_path}.toml" for folder in (SCENARIO_DIR, *EXTRA_SCENARIO_DIRS)
                    if (folder / f"{name_or_path}.toml").is_file()), SCENARIO_DIR / f"{name_or_path}.toml")
    if not bundled.is_file():
        raise ConfigError("scenario", f"no bundled scenario named {name_or_path!r} "
                          f"(see `swarmnav scenarios`)", name_or_path)
    return bundled


def load_scenario(name_or_path: str, trust_code: bool = False) -> Scenario:
    """Read and validate a scenario (``trust_code``: its planner or navigator may name code to run).

    Raises:
        ConfigError: the file is missing, is not valid TOML, or breaks the schema.
    """
    path = resolve_scenario_path(str(name_or_path))
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError("scenario", f"cannot be read ({exc})", str(path)) from None
    return parse_scenario(text, str(path), trust_code)


def parse_scenario(text: str, source: str = "<string>", trust_code: bool = False) -> Scenario:
    """Validate scenario TOML text (see :func:`load_scenario`)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError("toml", f"malformed TOML ({exc})", source) from None
    top = _Table(data, "", source)

    name = top.string("name")
    problem = name_problem(name)
    if problem:
        top.fail("name", problem)
    description = top.string("description", "")
    seed = top.integer("seed", 0, minimum=0)
    time_limit_s = top.number("time_limit_s", 150.0, positive=True)

    arena = top.table("arena")
    width_m = arena.number("width_m", positive=True)
    height_m = arena.number("height_m", positive=True)
    walls = arena.boolean("walls", False)
    arena.close()

    robot = top.table("robot", {})
    robot_radius_m = robot.number("radius_m", 0.15, positive=True)
    if robot_radius_m < MIN_ROBOT_RADIUS_M:
        robot.fail("radius_m", f"must be at least {MIN_ROBOT_RADIUS_M:g} m (the smallest base modelled), "
                               f"got {robot_radius_m:g}")
    max_speed_m_s = robot.number("max_speed_m_s", 0.2, positive=True)
    clearance_m = robot.number("clearance_m", 0.05, non_negative=True)
    robot.close()

    def pose(key: str) -> tuple[Pose2D, _Table]:
        t = top.table(key)
        x, y = t.number("x"), t.number("y")
        return Pose2D(x, y, math.radians(t.number("heading_deg", 0.0))), t

    start, start_t = pose("start")
    start_t.close()
    goal, goal_t = pose("goal")
    tolerance_m = goal_t.number("tolerance_m", 0.1, positive=True)
    goal_t.close()

    sensors = top.table("sensors", {})
    sensor_count = sensors.integer("count", 12, minimum=1, maximum=MAX_SENSORS)
    sensor_range_m = sensors.number("range_m", 0.4, positive=True, minimum=MIN_LENGTH_M)
    sensor_model = sensors.string("model", "rangefinder", choices=SENSOR_MODELS)
    sensors.close()

    planner = top.table("planner", {})
    planner_name = planner.string("name", "astar")
    params = planner.raw("params", {})
    if not isinstance(params, dict):
        planner.fail("params", "expected a table")
    planner.close()

    navigator = top.table("navigator", {})
    navigator_name = navigator.string("name", "follow")
    navigator_params = navigator.raw("params", {})
    if not isinstance(navigator_params, dict):
        navigator.fail("params", "expected a table")
    navigator.close()

    sim_t = top.table("sim", {})
    sim = SimSettings(timestep_s=sim_t.number("timestep_s", 0.002, positive=True, minimum=MIN_TIMESTEP_S),
                      control_hz=sim_t.number("control_hz", 50.0, positive=True),
                      stop_on_collision=sim_t.boolean("stop_on_collision", False),
                      danger_m=sim_t.number("danger_m", 0.1, non_negative=True))
    cell_m = sim_t.number("cell_m", 0.05, positive=True)
    sim_t.close()
    _check_run_size(time_limit_s, sim, source)

    boxes, map_grid, map_cell_m, map_pairs = _parse_map(top, source, width_m, height_m)
    if map_cell_m is None:
        _check_grid_size(width_m, height_m, cell_m, "sim.cell_m" if sim_t.has("cell_m") else "arena", source)

    raw_obstacles = top.raw("obstacles", [])
    if not isinstance(raw_obstacles, list):
        top.fail("obstacles", "expected an array of tables ([[obstacles]])")
    static_tables = []
    for i, raw in enumerate(raw_obstacles):
        t = _Table(raw, f"obstacles[{i}]", source)
        static_tables.append(t)
    static_centres = []
    static_radii = []
    parsed = []
    for i, t in enumerate(static_tables):
        x, y = t.number("x"), t.number("y")
        if not (0.0 <= x <= width_m and 0.0 <= y <= height_m):
            t.fail("x" if not 0.0 <= x <= width_m else "y",
                   f"the centre ({x:g}, {y:g}) must lie in the arena [0, {width_m:g}] x [0, {height_m:g}]")
        radius = t.number("radius_m", positive=True, minimum=MIN_LENGTH_M)
        height = t.number("height_m", 0.5, positive=True, minimum=MIN_LENGTH_M)
        motion_raw = t.raw("motion", None)
        parsed.append((t, x, y, radius, height, motion_raw))
        if motion_raw is None:
            static_centres.append((x, y))
            static_radii.append(radius)
    static_centres_arr = np.array(static_centres, dtype=float).reshape(-1, 2)
    static_radii_arr = np.array(static_radii, dtype=float)

    _check_motion_size(parsed, time_limit_s, sim, source)
    box_array_m = np.array([[b.x_min_m, b.y_min_m, b.x_max_m, b.y_max_m] for b in boxes], dtype=float).reshape(-1, 4)
    obstacles = []
    for i, (t, x, y, radius, height, motion_raw) in enumerate(parsed):
        motion = None
        if motion_raw is not None:
            m = _Table(motion_raw, f"obstacles[{i}].motion", source)
            kind = m.string("kind", choices=MOTION_KINDS)
            # Centres stay inside the arena: Abdulla & Hadi (2025) places obstacles on its edge.
            lower = (0.0, 0.0)
            upper = (width_m, height_m)
            start_s = m.number("start_s", 0.0, non_negative=True)  # held at its start until then
            if kind == "linear":
                motion = LinearMotion((x, y), m.number("speed_m_s", non_negative=True),
                                      math.radians(m.number("heading_deg")),
                                      m.string("at_edge", choices=("reflect", "stop")), lower, upper, start_s)
            elif kind == "random_walk":
                # A walker's disc stays inside the walls and off the map's boxes; on a map it walks the
                # paper's grid (Hasan et al. (2023)) by default, elsewhere compass steps (obstacle_motion's docstring).
                if walls:
                    lower, upper = (radius, radius), (width_m - radius, height_m - radius)
                motion = RandomWalkMotion(
                    (x, y), radius, m.number("step_m", positive=True), m.number("period_s", positive=True),
                    time_limit_s, lower, upper, static_centres_arr, static_radii_arr, stream=i, world_seed=seed,
                    static_boxes_m=box_array_m,
                    steps=m.string("steps", "grid" if map_cell_m is not None else "compass", choices=WALK_STEPS),
                    start_s=start_s)
            else:
                points = m.raw("points")
                if (not isinstance(points, list) or not points
                        or not all(isinstance(p, list) and len(p) == 2 and all(
                            isinstance(v, (int, float)) and not isinstance(v, bool) for v in p) for p in points)):
                    m.fail("points", "expected a non-empty array of [x, y] number pairs")
                arr = np.array(points, dtype=float)
                if not np.all(np.isfinite(arr)):
                    m.fail("points", "must be finite")
                outside = np.flatnonzero((arr < 0.0).any(axis=1) | (arr[:, 0] > width_m) | (arr[:, 1] > height_m))
                if len(outside):
                    m.fail(f"points[{outside[0]}]", f"({arr[outside[0], 0]:g}, {arr[outside[0], 1]:g}) must lie "
                                                    f"in the arena [0, {width_m:g}] x [0, {height_m:g}]")
                motion = WaypointMotion(np.vstack([[x, y], arr]), m.number("speed_m_s", positive=True), start_s)
            m.close()
        t.close()
        obstacles.append(Obstacle(x, y, radius, height, motion))

    top.close()
    if map_cell_m is not None:
        cell_m = map_cell_m
        if any(not ob.moving for ob in obstacles):
            # Static discs beside a map: rasterise both at the map's resolution (conservative margin).
            map_grid = None
        else:
            # Only moving obstacles (seeds 000 and 003): plan on the static map, as the papers do.
            from swarmnav.models.grid_map import inflated_map_grid
            map_grid = inflated_map_grid(map_grid.occupied, map_cell_m, robot_radius_m + clearance_m, boxes)

    scenario = Scenario(
        name=name, description=description, seed=seed, time_limit_s=time_limit_s,
        arena_width_m=width_m, arena_height_m=height_m, walls=walls,
        robot_radius_m=robot_radius_m, max_speed_m_s=max_speed_m_s, clearance_m=clearance_m,
        start=start, goal=goal, goal_tolerance_m=tolerance_m,
        sensor_count=sensor_count, sensor_range_m=sensor_range_m,
        planner_name=planner_name, planner_params=dict(params),
        navigator_name=navigator_name, navigator_params=dict(navigator_params), obstacles=tuple(obstacles),
        sim=sim, cell_m=cell_m, source_text=text, source_path=source, boxes=boxes, world_seed=seed,
        map_grid=map_grid, map_pairs=map_pairs, sensor_model=sensor_model, trust_code=bool(trust_code))
    _check_endpoints(scenario, source)
    return scenario


def name_problem(name: str) -> str | None:
    """Why a scenario name cannot be part of a file name, or None.

    The name is used in the default log path, so it must be a plain file-name
    part: printable, no path separator, not ``.`` or ``..``, at most
    :data:`MAX_NAME_CHARS` characters.
    """
    if not name.strip():
        return "must not be empty"
    if len(name) > MAX_NAME_CHARS:
        return f"must be at most {MAX_NAME_CHARS} characters, got {len(name)}"
    bad = next((ch for ch in name if not ch.isprintable()), None)
    if bad is not None:
        return f"must be printable, has {bad!r}"
    if "/" in name or "\\" in name:
        return f"must not contain a path separator ('/' or '\\'), got {name!r}"
    if name in (".", ".."):
        return f"must name a file, got {name!r}"
    return None


def _check_run_size(time_limit_s: float, sim: SimSettings, source: str) -> None:
    """The physics and control step counts of a run, against their stated maxima."""
    physics_steps = time_limit_s / sim.timestep_s
    if not physics_steps <= MAX_PHYSICS_STEPS:
        raise ConfigError("time_limit_s", f"{time_limit_s:g} s at a {sim.timestep_s:g} s timestep needs "
                          f"{physics_steps:.4g} physics steps (at most {MAX_PHYSICS_STEPS:,})", source)
    steps_per_control = 1.0 / (sim.control_hz * sim.timestep_s)
    if not math.isfinite(steps_per_control) or abs(steps_per_control - round(steps_per_control)) > 1e-9 \
            or round(steps_per_control) < 1:
        raise ConfigError("sim.control_hz", "the control period must be a whole number of physics "
                          f"timesteps (got {steps_per_control:g} steps)", source)
    periods = time_limit_s / (round(steps_per_control) * sim.timestep_s)  # the runner's whole control periods
    if round(periods) < 1 or abs(periods - round(periods)) > 1e-9 * max(1.0, periods):
        raise ConfigError("time_limit_s", f"{time_limit_s:g} s is not a whole number of control periods "
                          f"({round(steps_per_control) * sim.timestep_s:g} s)", source)
    control_steps = time_limit_s * sim.control_hz
    if not control_steps <= MAX_CONTROL_STEPS:
        raise ConfigError("time_limit_s", f"{time_limit_s:g} s at {sim.control_hz:g} Hz needs {control_steps:.4g} "
                          f"control steps (at most {MAX_CONTROL_STEPS:,})", source)


def _check_grid_size(width_m: float, height_m: float, cell_m: float, field_name: str, source: str) -> None:
    """The planning grid of the arena at ``cell_m``, against :data:`MAX_GRID_CELLS`."""
    cells = math.ceil(min(width_m / cell_m, 1e300)) * math.ceil(min(height_m / cell_m, 1e300))
    if cells > MAX_GRID_CELLS:
        smallest = math.sqrt(width_m * height_m / MAX_GRID_CELLS)
        raise ConfigError(field_name, f"a {width_m:g} x {height_m:g} m arena at {cell_m:g} m per cell needs "
                          f"{min(cells, 1e300):.4g} grid cells (at most {MAX_GRID_CELLS:,}; a cell of about "
                          f"{smallest:.3g} m or more fits)", source)


def _check_motion_size(parsed: list, time_limit_s: float, sim: SimSettings, source: str) -> None:
    """Precomputed obstacle motion against :data:`MAX_TRACK_SAMPLES` and :data:`MAX_WALK_STEPS`.

    Only the raw ``kind`` and ``period_s`` are looked at here; their types are
    checked (with the same field names) when the motion is parsed.
    """
    moving = [(i, raw) for i, (_t, _x, _y, _r, _h, raw) in enumerate(parsed) if raw is not None]
    control_steps = math.floor(time_limit_s * sim.control_hz + 1e-9) + 1
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


def _parse_map(top: _Table, source: str, width_m: float, height_m: float
               ) -> tuple[tuple[Box, ...], OccupancyGrid | None, float | None, tuple[tuple[int, ...], ...]]:
    """The optional ``[map]`` table: a Moving AI ``.map`` file and its cell size.

    ``file`` is looked up beside the scenario, then under ``models/maps/``.  The
    map must span the arena exactly (map cell (0, 0) of the file is the top-left
    corner).  Occupied cells become merged box obstacles.  ``pairs`` optionally
    lists [x0, y0, x1, y1] start/goal cells (column, row counted from the bottom)
    for ``swarmnav bench grid``.

    Returns:
        (boxes, the map's world grid before inflation or None, cell_m or None, the start/goal pairs).
    """
    if not top.has("map"):
        return (), None, None, ()
    from swarmnav.models.grid_map import map_to_grid, merge_boxes, read_map

    t = top.table("map")
    name = t.string("file")
    cell_m = t.number("cell_m", positive=True, minimum=MIN_LENGTH_M)
    pairs = t.raw("pairs", [])
    t.close()
    if not isinstance(pairs, list) or not all(
            isinstance(p, list) and len(p) == 4 and all(isinstance(v, int) and not isinstance(v, bool) for v in p)
            for p in pairs):
        raise ConfigError("map.pairs", "expected an array of [x0, y0, x1, y1] integer cells", source)
    here = FilePath(source).resolve().parent if source and not source.startswith("<") else SCENARIO_DIR
    candidates = [here / name, SCENARIO_DIR.parent / "maps" / name]
    path = next((c for c in candidates if c.is_file()), None)
    if path is None:
        raise ConfigError("map.file", f"no map file {name!r} beside the scenario or under models/maps/", source)
    try:
        occupied = read_map(path, MAX_GRID_CELLS)
    except ConfigError as exc:
        raise ConfigError("map.file", f"{path.name}: {exc.field}: {exc.problem}", source) from None
    rows, cols = occupied.shape
    if rows * cols > MAX_GRID_CELLS:
        raise ConfigError("map.file", f"a {cols} x {rows} map has {rows * cols:,} cells "
                          f"(at most {MAX_GRID_CELLS:,})", source)
    if abs(cols * cell_m - width_m) > 1e-6 or abs(rows * cell_m - height_m) > 1e-6:
        raise ConfigError("map.cell_m", f"a {cols} x {rows} map at {cell_m:g} m per cell spans "
                          f"{cols * cell_m:g} x {rows * cell_m:g} m, not the arena's {width_m:g} x {height_m:g} m",
                          source)
    for i, (x0, y0, x1, y1) in enumerate(pairs):
        for x, y in ((x0, y0), (x1, y1)):
            if not (0 <= x < cols and 0 <= y < rows):
                raise ConfigError(f"map.pairs[{i}]", f"cell ({x}, {y}) is outside the {cols} x {rows} map", source)
    grid = map_to_grid(occupied, cell_m)
    return merge_boxes(grid.occupied, cell_m), grid, cell_m, tuple(tuple(p) for p in pairs)


def _check_endpoints(scenario: Scenario, source: str) -> None:
    """Start and goal must lie in the arena and outside every obstacle grown by the robot radius."""
    bounds = scenario.planning_bounds(scenario.robot_radius_m)
    discs = scenario.discs_at(0.0)
    centres = np.array([[d.x_m, d.y_m] for d in discs], dtype=float).reshape(-1, 2)
    radii = np.array([d.radius_m for d in discs], dtype=float)
    boxes = np.array([[b.x_min_m, b.y_min_m, b.x_max_m, b.y_max_m] for b in scenario.boxes],
                     dtype=float).reshape(-1, 4)
    for key, pose in (("start", scenario.start), ("goal", scenario.goal)):
        why = endpoint_problem(pose, bounds, centres, radii, boxes, scenario.robot_radius_m)
        if why is not None:
            raise ConfigError(key, f"{why} (walls keep the robot's centre a radius away)"
                              if "outside" in why and scenario.walls else why, source)
