"""The one run composition: an episode spec in, a plan and a simulated run out.

Everything that plans and simulates a scenario (the CLI's ``plan`` and ``run``,
the API, ``replay --verify``, the benchmarks, studies, given paths, the environment's
path, the tests) goes through :func:`compose` and :func:`plan_episode` (or
:func:`given_episode`) and :func:`run_episode`; nothing else resolves a spec, builds a
run's components or an :class:`Episode`.

The flow of one run: an :class:`EpisodeSpec` (what the user named) is resolved once
(:meth:`EpisodeSpec.resolved`), its components are built once (:func:`compose`: the
planner under its budget, the navigator and the safety layer after it), the path is
planned (or given), and :func:`run_episode` hands the same components to the stepper's
closed loop (:meth:`sim.simulation.Simulation.run`).

Parameters resolve in one place (:meth:`EpisodeSpec.resolved`): a scenario's own
planner (navigator) parameters apply when the spec names the same planner
(navigator) as the scenario or none; the spec's parameters override them.

Two seeds say what they seed (:class:`models.scenario.Seeds`): ``seed`` the
planner's and the navigator's randomness, ``world_seed`` every random obstacle
motion; each falls back to the scenario's (``Scenario.seeds``: the file's ``seed``,
or the world seed :meth:`Scenario.with_world_seed` set).  The planner draws from
``default_rng(seed)``; the navigator from its own stream,
``SeedSequence(seed, spawn_key=(1,))``, so a navigator's draws never shift the plan.

:func:`compose` builds the planner, the navigator and its safety layer once (a bad
parameter of any fails before planning); :func:`plan_episode` plans with them;
:func:`run_episode` runs that planned episode with them, on a
:class:`~sim.simulation.Simulation` compiled once per episode.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field, replace
from typing import Any, Sequence

import numpy as np

from swarmnav.controllers.navigator import NavigationSetup, Navigator
from swarmnav.controllers.navigators import NAVIGATORS, make_driver
from swarmnav.controllers.point_to_point import PointToPointController
from swarmnav.controllers.safety_layer import SafetyLayer
from swarmnav.controllers.world_map import SensedMap
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import Scenario
from swarmnav.models.parameters import refuse_code
from swarmnav.models.seeds import Seeds
from swarmnav.planners.registry import PLANNERS, make_planner
from swarmnav.planners.problem import Path, Planner, Problem, scenario_problem
from swarmnav.planners.swarm import Budget, apply_budget
from swarmnav.sim.recording import Recorder, RecorderGroup
from swarmnav.sim.reference import reference_length_m, static_problem
from swarmnav.sim.simulation import Simulation
from swarmnav.sim.scene import CompiledScene
from swarmnav.sim.run_result import RunResult

def json_safe(value: Any) -> Any:
    """A planner's extra statistics as JSON values (NumPy scalars and arrays to numbers and lists)."""
    if isinstance(value, dict):
        return {str(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_safe(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and not np.isfinite(value):
        return None
    if isinstance(value, (str, int, float, bool)) or value is None:
        return value
    return repr(value)


def _not_in(params: dict[str, Any], overrides: dict[str, Any] | None) -> dict[str, Any]:
    return {k: v for k, v in params.items() if k not in (overrides or {})}


NAVIGATOR_STREAM = 1  # spawn key of the navigator's generator under the run's seed


@dataclass(frozen=True, eq=False)
class EpisodeSpec:
    """What to run: a scenario, a planner and a navigator with their parameters, and two seeds.

    ``None`` means "the scenario's": its planner, navigator, seeds (``Scenario.seeds``), ``robot.clearance_m``.
    Parameters given here override the scenario's own for the same planner or navigator.
    """

    scenario: Scenario
    planner: str | None = None
    planner_params: dict[str, Any] | None = None
    navigator: str | None = None
    navigator_params: dict[str, Any] | None = None
    seed: int | None = None
    world_seed: int | None = None
    clearance_m: float | None = None  # the planning clearance beyond the robot radius; None = the scenario's
    budget: Budget | None = None  # a study's budget for the planner (planners.swarm.Budget); None = none

    def resolved(self) -> "EpisodeSpec":
        """Every field filled in; the scenario carries the world seed."""
        scenario = self.scenario
        planner = self.planner or scenario.planner_name
        navigator = self.navigator or scenario.navigator_name
        from_file = (scenario.planner_params if planner == scenario.planner_name else {},
                     scenario.navigator_params if navigator == scenario.navigator_name else {})
        if not scenario.trust_code:  # the file's own code parameters, unless this spec names them itself
            refuse_code(PLANNERS, "planner", planner, _not_in(from_file[0], self.planner_params), scenario.source_path)
            refuse_code(NAVIGATORS, "navigator", navigator, _not_in(from_file[1], self.navigator_params),
                        scenario.source_path)
        planner_params = {**from_file[0], **(self.planner_params or {})}
        navigator_params = {**from_file[1], **(self.navigator_params or {})}
        seeds = self.seeds
        seed, world_seed = seeds.planner, seeds.world
        if world_seed != scenario.world_seed:
            scenario = scenario.with_world_seed(world_seed)
        if self.clearance_m is not None:
            scenario = scenario.with_clearance(self.clearance_m)
        return EpisodeSpec(scenario, planner, planner_params, navigator, navigator_params, seed, world_seed,
                           scenario.clearance_m, self.budget)

    @property
    def seeds(self) -> Seeds:
        """The run's seeds, the scenario's where this spec names none (the one place of that fallback)."""
        fallback = self.scenario.seeds
        return Seeds(fallback.planner if self.seed is None else int(self.seed),
                     fallback.world if self.world_seed is None else int(self.world_seed))


@dataclass(eq=False)
class Episode:
    """A planned (and, once run, simulated) episode: the resolved spec, its problem and path, and the
    planner, navigator and safety layer built for it (once: :func:`run_episode` uses these)."""

    spec: EpisodeSpec  # resolved
    problem: Problem
    path: Path
    planner: Planner
    navigator: Navigator | None  # None: planned only (plan_episode(drive=False)), never run
    scene: CompiledScene | None = field(default=None, repr=False)  # the scene to run; None: the scenario's
    result: RunResult | None = None
    _simulation: Simulation | None = field(default=None, repr=False)
    planner_params: dict[str, Any] = field(default_factory=dict)  # every parameter of the planner, resolved
    budgeted: bool = False  # the planner runs under ``spec.budget``
    safety: SafetyLayer | None = None  # the layer after the navigator (controllers.safety_layer); None: none

    @property
    def simulation(self) -> Simulation:
        """The compiled scene the episode runs on, built on first use and kept (runs of it reuse it)."""
        if self._simulation is None:
            self._simulation = Simulation(self.spec.scenario, self.scene)
        return self._simulation

    def plan_summary(self) -> dict[str, Any]:
        """The object ``swarmnav plan --json`` prints."""
        spec, stats = self.spec, self.path.stats
        return {"scenario": spec.scenario.name, "planner": spec.planner, "seed": spec.seed,
                "waypoints": [[float(x), float(y)] for x, y in self.path.waypoints],
                "length_m": stats.length_m, "plan_time_s": stats.plan_time_s,
                "iterations": stats.iterations, "evaluations": stats.evaluations,
                "collision_free": bool(self.problem.is_collision_free(self.path.waypoints)),
                "planner_params": self.planner_params,
                "budget": spec.budget.as_dict() if spec.budget is not None else None, "budgeted": self.budgeted,
                "details": json_safe(stats.extra)}

    def summary(self) -> dict[str, Any]:
        """The object ``swarmnav run --json`` prints (without the log and video paths)."""
        spec = self.spec
        out = {"scenario": spec.scenario.name, "planner": spec.planner, "navigator": spec.navigator,
               "seed": spec.seed, "world_seed": spec.world_seed}
        if self.result is not None:
            out.update(self.result.summary())
        out["plan"] = self.plan_summary()
        return out


@dataclass(frozen=True, eq=False)
class Composition:
    """A resolved spec and the components built from it, each once: what :func:`plan_episode` plans with
    and :func:`run_episode` runs."""

    spec: EpisodeSpec  # resolved
    planner: Planner
    budgeted: bool  # the planner runs under ``spec.budget``
    navigator: Navigator | None  # None: composed to plan only (the environment's path)
    safety: SafetyLayer | None

    def episode(self, problem: Problem, path: Path, scene: CompiledScene | None = None) -> Episode:
        """The :class:`Episode` of this composition with its first path."""
        return Episode(self.spec, problem, path, self.planner, self.navigator, scene,
                       planner_params=resolved_params(self.planner), budgeted=self.budgeted, safety=self.safety)


def compose(spec: EpisodeSpec | Composition, drive: bool = True) -> Composition:
    """Resolve the spec and build its components once: the planner (under the spec's budget) and, with
    ``drive``, the navigator and its safety layer (a composition given is returned as it is).

    Raises:
        ConfigError: unknown planner or navigator, or a bad parameter (naming the field).
    """
    if isinstance(spec, Composition):
        return spec
    spec = spec.resolved()
    planner, budgeted = build_planner(spec)
    navigator, safety = make_driver(spec.navigator, spec.navigator_params, spec.scenario.source_path) \
        if drive else (None, None)
    return Composition(spec, planner, budgeted, navigator, safety)


def plan_episode(spec: EpisodeSpec | Composition, scene: CompiledScene | None = None,
                 drive: bool = True) -> Episode:
    """Compose the spec (:func:`compose`) and plan on the scenario's obstacles at t = 0.

    Args:
        scene: a compiled scene to run instead of compiling the scenario (replay runs the MJCF
            its log carries).
        drive: build the navigator and its layer too (False: a path only, e.g. the environment's).

    Raises:
        ConfigError: unknown planner or navigator, or a bad parameter (naming the field).
        PlanningError: the planner found no path.
    """
    parts = compose(spec, drive)  # a bad parameter fails before planning
    scenario = parts.spec.scenario
    # With the map unknown the first plan sees no static obstacle (moving ones neither: nothing is sensed yet).
    problem = scenario_problem(scenario) if scenario.map_knowledge == "known" else unknown_map_problem(scenario)
    try:
        path = parts.planner.plan(problem, np.random.default_rng(parts.spec.seed))
    except ConfigError as exc:  # a limit the planner met on this scenario: name the file too
        if exc.source is not None:
            raise
        raise ConfigError(exc.field, exc.problem, scenario.source_path) from None
    return parts.episode(problem, path, scene)


def given_episode(spec: EpisodeSpec | Composition, waypoints: np.ndarray, source: str) -> Episode:
    """An episode whose path is the given waypoints instead of a plan (``run --waypoints``), composed as
    every run is (the spec's planner still serves a navigator that replans).

    Raises:
        ConfigError: a bad component or parameter, or waypoints that leave the arena (naming ``source``).
    """
    from swarmnav.sim.given_path import given_path
    parts = compose(spec)
    problem, path = given_path(parts.spec.scenario, waypoints, source)
    return parts.episode(problem, path)


def point_to_point(drive, scenario: Scenario) -> PointToPointController:
    """The run's PTP controller: the model's drive geometry, the scenario's top speed, the robot's published
    turn-rate limit and its drift and corner limits (``models.robots``; the controller's defaults when it has
    none: the disc robot's, the paper's)."""
    from swarmnav.models.robots import robot_model
    robot = robot_model(scenario.robot_model)
    extra = {} if robot.max_angular_rad_s is None else {"max_angular_rad_s": robot.max_angular_rad_s}
    if robot.ptp_limits is not None:
        extra["max_drift_m"], extra["max_deceleration_m_s2"] = robot.ptp_limits
    return PointToPointController(drive, max_speed_m_s=scenario.max_speed_m_s, **extra)


def unknown_map_problem(scenario: Scenario) -> Problem:
    """What the robot knows at t = 0 with the map unknown: the arena, its start and goal, no obstacle."""
    return scenario_problem(replace(scenario, obstacles=(), boxes=(), map_grid=None))


def build_planner(spec: EpisodeSpec) -> tuple[Any, bool]:
    """The run's one configured planner (a resolved spec's), under its budget, and whether it honours
    the budget: the first plan and every replan of the navigator use it."""
    planner = make_planner(spec.planner, spec.planner_params, spec.scenario.source_path)
    return apply_budget(planner, spec.budget)


def resolved_params(planner: Any) -> dict[str, Any]:
    """Every parameter of a planner as it runs (its dataclass fields, defaults included; JSON values)."""
    if not dataclasses.is_dataclass(planner):
        return {}
    return json_safe({f.name: getattr(planner, f.name) for f in dataclasses.fields(planner) if f.init})


def run_episode(episode: Episode | EpisodeSpec, recorders: Sequence[Recorder] = (), *,
                time_limit_s: float | None = None, stop_on_collision: bool | None = None) -> Episode:
    """Run a planned episode's closed loop with the given recorders (a spec is planned first).

    Returns the episode with its ``result`` (the planned episode passed in is left as it was,
    so a benchmark may run it again: the navigator is reset at the start of every run).

    Args:
        time_limit_s, stop_on_collision: override the scenario's.
    """
    planned = episode if isinstance(episode, Episode) else plan_episode(episode)
    spec, simulation = planned.spec, planned.simulation
    scenario = spec.scenario
    navigator = planned.navigator
    if navigator is None:
        raise ValueError("this episode was planned without a navigator (plan_episode(drive=False)): nothing to run")
    unknown = scenario.map_knowledge == "unknown"
    known_problem = static_problem(scenario) if not unknown else planned.problem
    world_map = SensedMap(planned.problem, scenario.bounds, scenario.map_cell_m,
                          unknown_cost=scenario.unknown_cost) if unknown else None
    setup = NavigationSetup(
        path=planned.path, problem=planned.problem,
        # With the map unknown every navigator that plans replans its (guidance) path on the sensed map.
        planner=planned.planner if navigator.uses_planner or unknown else None,
        rng=np.random.default_rng(np.random.SeedSequence(spec.seed, spawn_key=(NAVIGATOR_STREAM,))),
        controller=point_to_point(simulation.scene.drive, scenario),
        goal=simulation.goal_checker(), control_dt_s=simulation.control_dt_s,
        max_speed_m_s=scenario.max_speed_m_s, known_problem=known_problem,
        scenario=scenario, world_map=world_map)
    recorder = RecorderGroup(list(recorders)) if recorders else None
    # The log records every resolved parameter (replaying them builds the same planner).
    context = simulation.context(spec.planner, planned.planner_params or spec.planner_params, spec.seed,
                                 spec.navigator, spec.navigator_params) if recorder is not None else None
    result = simulation.run(navigator, setup, recorder=recorder, context=context,
                            time_limit_s=time_limit_s, stop_on_collision=stop_on_collision,
                            safety=planned.safety)
    return replace(planned, result=result)


__all__ = ["Composition", "Episode", "EpisodeSpec", "NAVIGATOR_STREAM", "build_planner", "compose", "given_episode",
           "json_safe", "plan_episode", "reference_length_m", "resolved_params", "run_episode", "static_problem"]
