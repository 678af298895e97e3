"""The API's calls: each composes a run the one way the command line does (``sim.episode``), so
``swarmnav.run(...).to_dict()`` is what ``swarmnav run --json`` prints for the same arguments.

Heavy modules (MuJoCo, SciPy, the planners) are imported inside the calls, on first use.
"""

from __future__ import annotations

import os
import time
from pathlib import Path as FilePath
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

from swarmnav.results import PlanResult, RunOutcome

if TYPE_CHECKING:
    import numpy as np

    from swarmnav.models.scenario import Scenario
    from swarmnav.sim.episode import EpisodeSpec
    from swarmnav.study.spec import Study

ComponentClass = TypeVar("ComponentClass", bound=type)


def load_scenario(name_or_path: str | os.PathLike[str], trust_code: bool = False) -> Scenario:
    """A bundled scenario by name (``swarmnav scenarios``), an installed package's, or a ``.toml`` path
    (``trust_code``: the file may name code to run, e.g. a ``policy``; see ``--trust-code``).

    Raises:
        ConfigError: missing file, malformed TOML or a field that breaks the schema (naming it).
    """
    from swarmnav.models.scenario import load_scenario as load
    from swarmnav.sim.plugins import load_plugins
    load_plugins()
    scenario = load(str(name_or_path), trust_code)
    check_components(scenario, trust_code)
    return scenario


def check_components(scenario: "Scenario", trust_code: bool = False) -> None:
    """The scenario's ``planner`` and ``navigator`` tables built once, so a file naming an unknown component or
    parameter is refused on load (naming the field), whatever ``--planner`` later overrides.

    Raises:
        ConfigError: ``planner.name``, ``planner.params.KEY`` (or the navigator's) and the file.
    """
    from swarmnav.controllers.navigators import NAVIGATORS, make_navigator
    from swarmnav.models.parameters import code_parameters
    from swarmnav.planners.registry import PLANNERS, make_planner

    def names_code(registry: dict[str, type], name: str, params: Any) -> bool:
        # Such a table is left to the run's composition, which refuses it without --trust-code unless the command
        # line replaced the code (``--navigator-set policy=...``): nothing is imported or built here.
        return (not trust_code and bool(params) and name in registry
                and any(k in params for k in code_parameters(registry[name])))
    if not names_code(PLANNERS, scenario.planner_name, scenario.planner_params):
        make_planner(scenario.planner_name, scenario.planner_params, scenario.source_path, trust_code=trust_code)
    if not names_code(NAVIGATORS, scenario.navigator_name, scenario.navigator_params):
        make_navigator(scenario.navigator_name, scenario.navigator_params, scenario.source_path,
                       trust_code=trust_code)


def _scenario(scenario: str | os.PathLike[str] | Scenario) -> Scenario:
    """A scenario as given, or loaded by name or path and its components checked (the caller has loaded the
    plugins)."""
    from swarmnav.models.scenario import Scenario
    from swarmnav.models.scenario import load_scenario as load
    if isinstance(scenario, Scenario):
        return scenario
    loaded = load(str(scenario))
    check_components(loaded)
    return loaded


def episode_spec(scenario: str | os.PathLike[str] | Scenario, planner: str | None = None,
                 params: Mapping[str, Any] | None = None, navigator: str | None = None,
                 navigator_params: Mapping[str, Any] | None = None, seed: int | None = None,
                 world_seed: int | None = None, clearance_m: float | None = None) -> EpisodeSpec:
    """The :class:`swarmnav.sim.episode.EpisodeSpec` of these arguments (``None``: the scenario's); the
    plugins are loaded here, once per call."""
    from swarmnav.sim.episode import EpisodeSpec
    from swarmnav.sim.plugins import load_plugins
    load_plugins()
    return EpisodeSpec(_scenario(scenario), planner=planner, planner_params=dict(params or {}),
                       navigator=navigator, navigator_params=dict(navigator_params or {}),
                       seed=seed, world_seed=world_seed, clearance_m=clearance_m)


def plan(scenario: str | os.PathLike[str] | Scenario, planner: str | None = None,
         params: Mapping[str, Any] | None = None, seed: int | None = None,
         clearance_m: float | None = None) -> PlanResult:
    """Plan the scenario (its obstacles at t = 0) with a registered planner.

    Raises:
        ConfigError: unknown planner or a bad parameter.
        PlanningError: no path (``NoPathFound``, ``StartBlocked``, ...).
    """
    from swarmnav.sim.episode import plan_episode
    return PlanResult(plan_episode(episode_spec(scenario, planner, params, seed=seed, clearance_m=clearance_m)))


def given_episode(spec: EpisodeSpec, waypoints: np.ndarray, source: str) -> Any:
    """An episode whose path is the given waypoints instead of a plan (``run --waypoints``), composed as every
    run is (:func:`swarmnav.sim.episode.given_episode`)."""
    from swarmnav.sim.episode import given_episode as composed
    return composed(spec, waypoints, source)


def run(scenario: str | os.PathLike[str] | Scenario, planner: str | None = None,
        params: Mapping[str, Any] | None = None, navigator: str | None = None,
        navigator_params: Mapping[str, Any] | None = None, seed: int | None = None, world_seed: int | None = None,
        clearance_m: float | None = None, *,
        waypoints: Sequence[Sequence[float]] | np.ndarray | str | os.PathLike[str] | None = None,
        log: str | os.PathLike[str] | bool | None = None, overwrite: bool = False,
        video: str | os.PathLike[str] | None = None, camera: str = "top", width: int = 640, height: int = 480,
        fps: float | None = None, stop_on_collision: bool | None = None, live: bool = False,
        on_live: Callable[[str], None] | None = None, log_format: str = "swarmnav") -> RunOutcome:
    """Plan (or take ``waypoints``) and drive the scenario in MuJoCo (:func:`run_spec` of :func:`episode_spec`).

    Args:
        waypoints: a path to drive instead of planning: ``(N, 2)`` metres, or a CSV/JSON file
            (:mod:`swarmnav.sim.given_path`).
        log: an MCAP path, ``True`` for ``logs/<scenario>_<planner>_seed<N>_<stamp>.mcap``, or ``None``/``False``
            for no log.
        video: an MP4 path rendered offscreen while running.
        log_format: ``swarmnav`` (Foxglove's schemas) or ``ros2`` (CDR messages of the standard ROS 2 types).

    Raises:
        ConfigError: bad input (naming the field); the log or video file exists without ``overwrite``.
        PlanningError: no path.
    """
    spec = episode_spec(scenario, planner, params, navigator, navigator_params, seed, world_seed, clearance_m)
    return run_spec(spec, waypoints=waypoints, log=log, overwrite=overwrite, video=video, camera=camera, width=width,
                    height=height, fps=fps, stop_on_collision=stop_on_collision, live=live, on_live=on_live,
                    log_format=log_format)


def run_spec(spec: Any, *, waypoints: "Sequence[Sequence[float]] | np.ndarray | str | os.PathLike | None" = None,
             log: "str | os.PathLike | bool | None" = None, overwrite: bool = False,
             video: "str | os.PathLike | None" = None, camera: str = "top", width: int = 640, height: int = 480,
             fps: float | None = None, stop_on_collision: bool | None = None, live: bool = False,
             on_live: Callable[[str], None] | None = None, log_format: str = "swarmnav") -> RunOutcome:
    """Plan (or take ``waypoints``) and drive an :class:`~swarmnav.sim.episode.EpisodeSpec` (the command line's
    ``run`` builds its spec as ``plan`` does, then comes here); the outputs as :func:`run` takes them."""
    from swarmnav.models.errors import ConfigError
    from swarmnav.sim.episode import given_episode, plan_episode, run_episode
    if waypoints is not None:
        from swarmnav.sim.given_path import as_waypoints, read_waypoints
        if isinstance(waypoints, (str, os.PathLike)):
            planned = given_episode(spec, read_waypoints(waypoints), str(waypoints))
        else:
            planned = given_episode(spec, as_waypoints(waypoints, "waypoints"), "waypoints")
    else:
        planned = plan_episode(spec)  # bad input or no path fails before any file is made
    recorders: list[Any] = []
    log_path = None
    if log:
        from swarmnav.log.writer import McapRecorder, default_log_path
        log_path = FilePath(log) if log is not True else default_log_path(
            planned.spec.scenario.name, planned.spec.planner, planned.spec.seed, time.strftime("%Y%m%d-%H%M%S"))
        if log_path.is_dir():
            raise ConfigError("--out", "Is a directory (give a file path)", str(log_path))
        if log_path.exists() and not overwrite:
            raise ConfigError("--out", "file exists (use --overwrite)", str(log_path))
        recorders.append(McapRecorder(log_path, live=live, overwrite=True, on_live=on_live, log_format=log_format))
    elif live:
        raise ConfigError("--live", "needs the log (drop --no-log)")
    if video:
        from swarmnav.sim.defaults import DEFAULT_FPS
        from swarmnav.video.render import VideoRecorder
        recorders.append(VideoRecorder(str(video), camera=camera, width=width, height=height,
                                       fps=DEFAULT_FPS if fps is None else fps))
    episode = run_episode(planned, recorders, stop_on_collision=stop_on_collision)
    return RunOutcome(episode, str(log_path) if log_path else None, str(video) if video else None)


def run_study(file_or_spec: str | os.PathLike[str] | Mapping[str, Any] | Study,
              out: str | os.PathLike[str] | None = None, *, workers: int | None = None,
              engine: str = "local", address: str | None = None, logs: bool = False,
              quick: bool = False) -> dict[str, Any]:
    """Run a study (a bundled name, a ``.toml`` path, or the tables of a study file as a dict) into ``out``
    (default ``studies/<name>``); a folder that holds some of its rows resumes.  Returns the summary that
    ``swarmnav study --json`` prints."""
    from swarmnav.sim.plugins import load_plugins
    from swarmnav.study.execute import run_study as execute
    from swarmnav.study.spec import Study, load_study, study_from_tables
    load_plugins()
    if isinstance(file_or_spec, Study):
        study = file_or_spec
    elif isinstance(file_or_spec, Mapping):
        study = study_from_tables(dict(file_or_spec), "<tables>", str(file_or_spec.get("name", "study")))
    else:
        study = load_study(str(file_or_spec))
    if quick:
        study = study.quick()
    target = FilePath(out) if out is not None else FilePath("studies") / study.name
    return execute(study, target, engine=engine, workers=workers, address=address, logs=logs)


def register_planner(cls: ComponentClass) -> ComponentClass:
    """Register a planner class in this process (a decorator, too); every command run from this process, and
    this API, then knows it by ``cls.name``.  To make it known to the ``swarmnav`` command and to study
    workers, declare it as an entry point (``swarmnav.planners``) of an installed package instead."""
    from swarmnav.planners.registry import register
    return register(cls)


def register_navigator(cls: ComponentClass) -> ComponentClass:
    """Register a navigator class in this process (see :func:`register_planner`; group ``swarmnav.navigators``)."""
    from swarmnav.controllers.navigators import register
    return register(cls)
