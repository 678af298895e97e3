"""Scenarios are data: TOML files under ``models/scenarios/``, validated on load.

Every problem in a file raises :class:`models.errors.ConfigError` naming the
file, the field (a dotted path such as ``obstacles[3].motion.kind``) and what is
wrong.  The schema is documented in the README; units are in the field names.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path as FilePath
from typing import Any

import numpy as np

from swarmnav.models.contained_files import is_input_path, name_problem  # noqa: F401 (name_problem: re-exported)
from swarmnav.models.crowd_agents import reseed_agents
from swarmnav.models.errors import ConfigError
from swarmnav.models.obstacle_motion import RandomWalkMotion
from swarmnav.models.scenario_limits import (MAX_CONTROL_STEPS, MAX_GRID_CELLS, MAX_NAME_CHARS,  # noqa: F401
                                             MAX_PHYSICS_STEPS, MAX_SENSORS, MAX_TRACK_SAMPLES, MAX_WALK_STEPS,
                                             MIN_LENGTH_M, MIN_ROBOT_RADIUS_M, MIN_TIMESTEP_S)
from swarmnav.models.scenario_boxes import read_boxes
from swarmnav.models.scenario_map import check_grid_size, read_map_section
from swarmnav.models.scenario_obstacles import MOTION_KINDS, Obstacle, ObstacleWorld, read_obstacles  # noqa: F401
from swarmnav.models.seeds import Seeds
from swarmnav.models.occupancy import MAX_MAP_CELLS
from swarmnav.models.robots import ROBOTS
from swarmnav.models.toml_table import NON_NEGATIVE, POSITIVE, TomlTable, above, parse_toml, read_text, within
from swarmnav.models.world import Box, Disc, OccupancyGrid, Pose2D, Rect, endpoint_problem

SCENARIO_DIR = FilePath(__file__).resolve().parent / "scenarios"
#: Folders of scenario files that installed packages declare (entry-point group ``swarmnav.scenarios``, added by
#: ``swarmnav.sim.plugins``): their names resolve after the bundled ones.
EXTRA_SCENARIO_DIRS: list[FilePath] = []


@dataclass(frozen=True)
class SimSettings:
    timestep_s: float = 0.002
    control_hz: float = 50.0
    stop_on_collision: bool = False
    danger_m: float = 0.1  # clearance below which time counts as "in danger" (navigation metrics)


SENSOR_MODELS = ("rangefinder", "detector")
MAP_KNOWLEDGE = ("known", "unknown")
POSE_SOURCES = ("truth", "odometry")


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
    # The robot of the catalogue (models.robots): ``robot.model``; its footprint collides in physics, and
    # robot_radius_m (its circumscribed circle unless the file gives radius_m) is what planners plan for.
    robot_model: str = "diff_drive"
    # The rangefinders' field of view (degrees): 360 is a full ring, less a laser's fan centred ahead.
    sensor_fov_deg: float = 360.0
    # [knowledge]: what the robot is given.  map "known" (the static obstacles, in advance) or "unknown"
    # (mapped online from the laser at map_cell_m, controllers.world_map); pose "truth" (the simulator's)
    # or "odometry" (integrated wheel speeds, with encoder_noise: the relative standard deviation of each
    # measured wheel speed, drawn from the world seed's streams); unknown_cost: with the map unknown, the extra
    # weight of a move through a never-seen cell for the grid searches (0: unknown cells are free).
    map_knowledge: str = "known"
    pose_source: str = "truth"
    map_cell_m: float = 0.05
    encoder_noise: float = 0.0
    unknown_cost: float = 0.0
    # with_knowledge gave map or pose (--map / --pose, a study axis): the run logs them, so a replay has them.
    knowledge_overridden: bool = False

    def with_knowledge(self, map_knowledge: str | None = None, pose_source: str | None = None) -> "Scenario":
        """This scenario with the map or the pose source overridden (``--map`` / ``--pose``, a study axis).

        Raises:
            ConfigError: a value that is not one of :data:`MAP_KNOWLEDGE` / :data:`POSE_SOURCES`.
        """
        for name, value, choices in (("map", map_knowledge, MAP_KNOWLEDGE), ("pose", pose_source, POSE_SOURCES)):
            if value is not None and value not in choices:
                raise ConfigError(f"knowledge.{name}", f"must be one of {', '.join(choices)}, got {value!r}",
                                  self.source_path)
        return replace(self, map_knowledge=map_knowledge or self.map_knowledge,
                       pose_source=pose_source or self.pose_source,
                       knowledge_overridden=self.knowledge_overridden or bool(map_knowledge or pose_source))

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
        obstacles = reseed_agents(tuple(replace(ob, motion=ob.motion.reseeded(world_seed))
                                        if isinstance(ob.motion, RandomWalkMotion) else ob
                                        for ob in self.obstacles), world_seed)
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



def list_scenarios() -> list[str]:
    """Names of the bundled scenarios (file stems under models/scenarios/), then those of installed packages."""
    names = {p.stem for p in SCENARIO_DIR.glob("*.toml")}
    for folder in EXTRA_SCENARIO_DIRS:
        names.update(p.stem for p in folder.glob("*.toml"))
    return sorted(names)


def resolve_scenario_path(name_or_path: str) -> FilePath:
    """A bundled scenario name, or a path to a .toml file."""
    candidate = FilePath(name_or_path)
    if candidate.suffix == ".toml" or is_input_path(candidate) or "/" in name_or_path:
        return candidate  # read_text says what is wrong with anything but a regular file
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
    return parse_scenario(read_text(path, "scenario"), str(path), trust_code)


def parse_scenario(text: str, source: str = "<string>", trust_code: bool = False) -> Scenario:
    """Validate scenario TOML text (see :func:`load_scenario`), one table at a time with the one reader."""
    top = parse_toml(text, source)
    name = top.string("name")
    problem = name_problem(name)
    if problem:
        top.fail("name", problem)
    description = top.string("description", "")
    seed = top.integer("seed", 0, bounds=NON_NEGATIVE)
    time_limit_s = top.number("time_limit_s", 150.0, bounds=POSITIVE)
    arena = top.table("arena")
    width_m, height_m = arena.number("width_m", bounds=POSITIVE), arena.number("height_m", bounds=POSITIVE)
    walls = arena.boolean("walls", False)
    arena.close()
    robot_model, robot_radius_m, max_speed_m_s, clearance_m = _robot(top.table("robot", {}))
    start, goal, tolerance_m = _endpoints(top)
    sensors = top.table("sensors", {})
    sensor_count = sensors.integer("count", 12, bounds=within(1, MAX_SENSORS))
    sensor_fov_deg = sensors.number("fov_deg", 360.0, bounds=above(0, 360))
    sensor_range_m = sensors.number("range_m", ROBOTS[robot_model].default_range_m, bounds=within(MIN_LENGTH_M))
    sensor_model = sensors.string("model", "rangefinder", choices=SENSOR_MODELS)
    sensors.close()
    knowledge = top.table("knowledge", {})
    map_knowledge = knowledge.string("map", "known", choices=MAP_KNOWLEDGE)
    pose_source = knowledge.string("pose", "truth", choices=POSE_SOURCES)
    map_cell_m = knowledge.number("map_cell_m", 0.05, bounds=within(MIN_LENGTH_M))
    encoder_noise = knowledge.number("encoder_noise", 0.0, bounds=within(0.0, 1.0))
    unknown_cost = knowledge.number("unknown_cost", 0.0, bounds=within(0.0, 1000.0))
    knowledge.close()
    if map_knowledge == "unknown":
        check_grid_size(width_m, height_m, map_cell_m, "knowledge.map_cell_m", source, MAX_MAP_CELLS)
    planner_name, planner_params = _component(top.table("planner", {}), "astar")
    navigator_name, navigator_params = _component(top.table("navigator", {}), "follow")
    sim, cell_m, cell_given = _sim(top.table("sim", {}))
    check_run_size(time_limit_s, sim, source)

    section = read_map_section(top, SCENARIO_DIR, width_m, height_m)
    if section is None:
        check_grid_size(width_m, height_m, cell_m, "sim.cell_m" if cell_given else "arena", source)
    boxes = (section.boxes if section is not None else ()) + read_boxes(top, width_m, height_m)
    obstacles = read_obstacles(top, ObstacleWorld(width_m, height_m, walls, seed, time_limit_s, sim.control_hz,
                                                  boxes, section is not None, sim.timestep_s))
    top.close()
    map_grid = None
    if section is not None:
        cell_m = section.cell_m
        if all(ob.moving for ob in obstacles):
            # Only moving obstacles (Hasan et al. (2023); Gong et al. (2022)): plan on the static map, as the
            # papers do.  Static discs beside a map are rasterised with it at the map's resolution (map_grid None).
            from swarmnav.models.grid_map import inflated_map_grid
            map_grid = inflated_map_grid(section.grid.occupied, section.cell_m, robot_radius_m + clearance_m, boxes)

    scenario = Scenario(
        name=name, description=description, seed=seed, time_limit_s=time_limit_s,
        arena_width_m=width_m, arena_height_m=height_m, walls=walls,
        robot_radius_m=robot_radius_m, max_speed_m_s=max_speed_m_s, clearance_m=clearance_m,
        start=start, goal=goal, goal_tolerance_m=tolerance_m,
        sensor_count=sensor_count, sensor_range_m=sensor_range_m,
        planner_name=planner_name, planner_params=planner_params,
        navigator_name=navigator_name, navigator_params=navigator_params, obstacles=obstacles,
        sim=sim, cell_m=cell_m, source_text=text, source_path=source, boxes=boxes, world_seed=seed,
        map_grid=map_grid, map_pairs=section.pairs if section is not None else (), sensor_model=sensor_model,
        trust_code=bool(trust_code), robot_model=robot_model, sensor_fov_deg=sensor_fov_deg,
        map_knowledge=map_knowledge, pose_source=pose_source, map_cell_m=map_cell_m, encoder_noise=encoder_noise,
        unknown_cost=unknown_cost)
    _check_endpoints(scenario, source)
    return scenario


def _robot(robot: TomlTable) -> tuple[str, float, float, float]:
    """``[robot]``: the catalogue model (:mod:`models.robots`), then its planning radius, top speed and
    planning clearance (metres, metres per second, metres), the model's defaults where the file gives none."""
    model_name = robot.string("model", "diff_drive", choices=tuple(ROBOTS))
    model = ROBOTS[model_name]
    radius_m = robot.number("radius_m", model.planning_radius_m, bounds=POSITIVE)
    if radius_m < MIN_ROBOT_RADIUS_M:
        robot.fail("radius_m", f"must be at least {MIN_ROBOT_RADIUS_M:g} m (the smallest base modelled), "
                               f"got {radius_m:g}")
    max_speed_m_s = robot.number("max_speed_m_s", model.max_speed_m_s, bounds=POSITIVE)
    clearance_m = robot.number("clearance_m", 0.05, bounds=NON_NEGATIVE)
    robot.close()
    return model_name, radius_m, max_speed_m_s, clearance_m


def _endpoints(top: TomlTable) -> tuple[Pose2D, Pose2D, float]:
    """``start`` and ``goal`` poses (``heading_deg`` read in degrees) and the goal's ``tolerance_m``."""
    poses = []
    for key in ("start", "goal"):
        t = top.table(key)
        x, y = t.number("x"), t.number("y")
        poses.append((Pose2D(x, y, math.radians(t.number("heading_deg", 0.0))), t))
    (start, start_t), (goal, goal_t) = poses
    start_t.close()
    tolerance_m = goal_t.number("tolerance_m", 0.1, bounds=POSITIVE)
    goal_t.close()
    return start, goal, tolerance_m


def _component(t: TomlTable, default_name: str) -> tuple[str, dict[str, Any]]:
    """``[planner]`` or ``[navigator]``: a registry name and its ``params`` table (checked when it is built)."""
    name = t.string("name", default_name)
    params = dict(t.table("params", {}).data)
    t.close()
    return name, params


def _sim(t: TomlTable) -> tuple[SimSettings, float, bool]:
    """``[sim]``: the physics and control settings, the planning cell size and whether the file gave it."""
    sim = SimSettings(timestep_s=t.number("timestep_s", 0.002, bounds=within(MIN_TIMESTEP_S)),
                      control_hz=t.number("control_hz", 50.0, bounds=POSITIVE),
                      stop_on_collision=t.boolean("stop_on_collision", False),
                      danger_m=t.number("danger_m", 0.1, bounds=NON_NEGATIVE))
    cell_m = t.number("cell_m", 0.05, bounds=POSITIVE)
    t.close()
    return sim, cell_m, t.has("cell_m")


def check_run_size(time_limit_s: float, sim: SimSettings, source: str | None) -> None:
    """The physics and control step counts of a run, against their stated maxima, and its time limit a whole
    number of control periods (a study's ``time_limit_s`` override is checked against each scenario with it)."""
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
