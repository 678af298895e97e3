"""One study cell: plan (and simulate) through the one episode function, and turn the result into rows.

This is the function every engine runs, in a worker process or a Ray task.  A
failure never escapes: a planner that finds no path is an outcome ``no_path``
row, one that raises anything else an ``error`` row with the message, and a run
past the study's wall limit a ``timeout`` row.

A cell naming a planner, navigator or scenario this process does not know (a plugin installed where the
driver runs but not where the worker does) is no row: :class:`ComponentMissing` ends the whole study, as
the driver's own validation would have.

Outcome (``outcome``) is the harness's: ``ok``, ``no_path``, ``error`` or
``timeout``.  The simulation's own end (``goal_reached``, ``timeout`` in simulated
time, ``collision``) is ``run_outcome``.  ``success`` is: plan-only, a
collision-free plan; physics, the goal reached with no collision.
"""

from __future__ import annotations

import functools
import json
import math
import signal
import threading
import time
from pathlib import Path as FilePath
from typing import Any

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import load_scenario, resolve_scenario_path
from swarmnav.planners.errors import PlanningError
from swarmnav.planners.swarm import Budget
from swarmnav.sim.plugins import load_plugins
from swarmnav.sim.episode import EpisodeSpec, compose, json_safe, plan_episode, resolved_params, run_episode
from swarmnav.study.grid import Cell
from swarmnav.sim.trajectory_metrics import bends, count_turns
from swarmnav.sim.versions import software_versions

# Quantities some planners report in ``stats.extra`` that a paper's table prints: given their own columns.
EXTRA_COLUMNS = {"raw_length_m": "plan_raw_length_m",  # the tour before shortcutting (grid and ant planners)
                 "gates_raised": "plan_gates_raised",  # IMMAS (Hasan et al. 2023), GateRaiseState
                 "tunnels_closed": "plan_tunnels_closed",  # IMMAS, Algorithm 2 (tight tunnels)
                 "total_arc_cost": "plan_arc_cost",  # IMMAS, the arc cost of its tour
                 "map_arc_cost": "plan_map_arc_cost",  # IMMAS and MMAS: the tour's arc cost on the map as given
                 "moves": "plan_moves",  # grid planners: cell moves of the raw tour (IMMAS's Table 1 iterations)
                 "mean_cell_clearance_m": "plan_cell_clearance_m",  # grid planners: mean obstacle distance of the cells
                 "nodes_visited": "plan_nodes_visited"}  # M-ACO (Habib et al. 2021): random nodes on the route


class EventTally:
    """A recorder that counts the navigator's events by kind (``collision_type`` also by its ``action``) and
    keeps each kind's last details: the row's ``run_events`` (JSON), e.g. IMMAS's moves and arc cost from its
    last ``immas_move``, the escapes of IACO's collision-type strategies."""

    def __init__(self) -> None:
        self.counts: dict[str, int] = {}
        self.last: dict[str, Any] = {}

    def start(self, context) -> None: ...
    def path(self, time_s, waypoints_m) -> None: ...
    def step(self, frame) -> None: ...
    def finish(self, summary) -> None: ...

    def event(self, time_s: float, kind: str, details: dict[str, Any]) -> None:
        keys = [kind] + ([f"{kind}.{details['action']}"] if "action" in details else [])
        for key in keys:
            self.counts[key] = self.counts.get(key, 0) + 1
        self.last[kind] = details

    def as_json(self) -> str:
        return json.dumps(json_safe({"counts": self.counts, "last": self.last}), sort_keys=True)


class WallLimitExceeded(BaseException):
    """Raised in the cell by SIGALRM at the wall limit (a BaseException, so planners' ``except Exception``
    cannot swallow it)."""


# The navigation metrics of ``run --json`` kept as columns of their own.
NAVIGATION_METRICS = ("time_to_goal_s", "spl", "time_in_danger_s", "replans", "replan_wall_s", "stopped_s",
                      "safety_triggers", "discomfort_frequency", "min_separation_m", "path_irregularity_rad_m")


class _WallLimit:
    """SIGALRM after ``limit_s`` when running on a main thread; elsewhere the limit is checked afterwards.

    Both engines run cells on their worker's main thread (a spawned process's, and a Ray
    task's: Ray executes a normal task on its worker process's main thread), so the
    timer interrupts a long run there.  Only a caller running :func:`run_cell` on
    another thread gets the after-the-run check (the run finishes, then becomes a
    ``timeout`` row saying so)."""

    def __init__(self, limit_s: float):
        self.limit_s = limit_s
        self.armed = threading.current_thread() is threading.main_thread()

    def __enter__(self):
        if self.armed:
            self.previous = signal.signal(signal.SIGALRM, self._fire)
            signal.setitimer(signal.ITIMER_REAL, self.limit_s)
        return self

    def _fire(self, signum, frame):
        raise WallLimitExceeded()

    def __exit__(self, *exc):
        if self.armed:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, self.previous)
        return False


@functools.cache
def _versions_json() -> str:
    return json.dumps(software_versions("numpy", "scipy"), sort_keys=True)


def base_row(cell: Cell) -> dict[str, Any]:
    return {"study": cell.study, "config_hash": cell.config_hash, "scenario": cell.scenario_name,
            "scenario_ref": cell.scenario, "planner": cell.planner, "label": cell.label,
            "planner_params": json.dumps(cell.planner_params, sort_keys=True), "navigator": cell.navigator,
            "navigator_label": cell.navigator_label,
            "navigator_params": json.dumps(cell.navigator_params, sort_keys=True), "seed": cell.seed,
            "world_seed": cell.world_seed, "mode": cell.mode,
            "budget": None if cell.budget is None else json.dumps(cell.budget, sort_keys=True),
            "budget_evaluations": (cell.budget or {}).get("evaluations"),
            "budget_time_s": (cell.budget or {}).get("time_s")}


class ComponentMissing(ConfigError):
    """A cell names a component the worker's process does not know (its plugin is not installed there)."""

    def __reduce__(self):  # crosses the worker's pipe and Ray as itself
        return (ComponentMissing, (self.field, self.problem, self.source))


def check_components(cell: Cell) -> None:
    """Raise :class:`ComponentMissing` unless this process knows the cell's planner, navigator and scenario
    (plugins loaded first)."""
    from swarmnav.controllers.navigators import NAVIGATORS
    from swarmnav.planners.registry import PLANNERS
    load_plugins()
    missing = []
    if cell.planner not in PLANNERS:
        missing.append(f"planner {cell.planner!r}")
    if cell.navigator not in NAVIGATORS:
        missing.append(f"navigator {cell.navigator!r}")
    try:
        resolve_scenario_path(cell.scenario)
    except ConfigError:
        missing.append(f"scenario {cell.scenario!r}")
    if missing:
        raise ComponentMissing("study", f"a worker does not know the {' and the '.join(missing)} that the study "
                               "names (install the plugin that provides it where the workers run)")


def run_cell(cell: Cell, logs_dir: str | None = None,
             log_format: str = "swarmnav") -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """Run one cell; return its run row and its best-cost history rows (``progress``); its log (in
    ``logs_dir``) of format ``log_format``.

    Raises:
        ComponentMissing: the cell names a component unknown in this process (no row: the study ends).
    """
    check_components(cell)
    row = base_row(cell)
    row["versions"] = _versions_json()
    progress: list[dict[str, Any]] = []
    started = time.perf_counter()
    try:
        with _WallLimit(cell.wall_limit_s):
            scenario = load_scenario(cell.scenario, trust_code=cell.trust_code)
            scenario = scenario.with_knowledge(cell.map_knowledge, cell.pose_source)  # the maps / poses axes
            row.update(map_knowledge=scenario.map_knowledge, pose_source=scenario.pose_source)
            row["straight_line_m"] = math.hypot(scenario.goal.x_m - scenario.start.x_m,
                                                scenario.goal.y_m - scenario.start.y_m)
            spec = EpisodeSpec(scenario, cell.planner, cell.planner_params, cell.navigator, cell.navigator_params,
                               seed=cell.seed, world_seed=cell.world_seed, clearance_m=cell.clearance_m,
                               budget=None if cell.budget is None else Budget(**cell.budget))
            row["clearance_m"] = scenario.clearance_m if cell.clearance_m is None else cell.clearance_m
            parts = compose(spec)   # its planner recorded for every row, failed ones too; built once
            row.update(planner_resolved=json.dumps(resolved_params(parts.planner), sort_keys=True),
                       budgeted=parts.budgeted, plan_mode=getattr(parts.planner, "mode", None))
            episode = plan_episode(parts)
            if cell.physics:
                tally = EventTally()
                recorders = [tally]
                if logs_dir is not None:
                    from swarmnav.log.writer import McapRecorder
                    log_path = FilePath(logs_dir) / f"{cell.config_hash}.mcap"
                    recorders.append(McapRecorder(log_path, overwrite=True, log_format=log_format))
                    row["log"] = str(log_path)
                cpu0 = time.thread_time()
                episode = run_episode(episode, recorders, time_limit_s=cell.time_limit_s)
                row["run_cpu_s"] = time.thread_time() - cpu0  # this thread's CPU: the load of others left out
                row["run_events"] = tally.as_json()
        row["outcome"] = "ok"
    except WallLimitExceeded:
        row.update(outcome="timeout", error=f"exceeded the wall limit of {cell.wall_limit_s:g} s")
        episode = None
    except PlanningError as exc:
        # What the failed search spent, when the planner says (the swarm loop does).
        row.update(outcome="no_path", error=f"{type(exc).__name__}: {exc}",
                   plan_evaluations=getattr(exc, "evaluations", None), plan_time_s=getattr(exc, "plan_time_s", None))
        episode = None
    except Exception as exc:  # noqa: BLE001 - a failing run is a row, never the end of the study
        row.update(outcome="error", error=f"{type(exc).__name__}: {exc}")
        episode = None
    row["cell_wall_s"] = time.perf_counter() - started
    if episode is not None and row["cell_wall_s"] > cell.wall_limit_s:  # the limit could not be armed here
        row.update(outcome="timeout", error=f"exceeded the wall limit of {cell.wall_limit_s:g} s "
                                            "(checked after the run: no timer off the main thread)")
    if episode is not None:
        _add_metrics(row, episode)
        progress = _progress_rows(cell, episode)
    row["success"] = _success(row)
    return row, progress


def _add_metrics(row: dict[str, Any], episode) -> None:
    plan = episode.plan_summary()
    stats = episode.path.stats
    row.update(plan_length_m=plan["length_m"], plan_time_s=plan["plan_time_s"],
               plan_iterations=plan["iterations"], plan_evaluations=plan["evaluations"],
               plan_collision_free=plan["collision_free"], plan_waypoints=json.dumps(plan["waypoints"]),
               plan_bends=bends(episode.path.waypoints),
               plan_convergence_iteration=stats.extra.get("convergence_iteration"),
               plan_extra=json.dumps(json_safe(stats.extra), sort_keys=True))
    for key, column in EXTRA_COLUMNS.items():
        value = stats.extra.get(key)
        row[column] = None if value is None or not math.isfinite(float(value)) else value
    if episode.result is not None:
        run = episode.result.summary()
        row.update(reached=run["reached"], run_outcome=run["outcome"], collisions=run["collisions"],
                   first_collision_s=run["first_collision_s"], sim_time_s=run["sim_time_s"],
                   wall_time_s=run["wall_time_s"], path_length_m=run["path_length_m"],
                   min_clearance_m=run["min_clearance_m"], control_steps=episode.result.steps,
                   navigator_wall_s=episode.result.navigator_wall_s,
                   driven_turns=count_turns(episode.result.poses, episode.spec.scenario.cell_m))
        row.update({key: run.get(key) for key in NAVIGATION_METRICS})


def _progress_rows(cell: Cell, episode) -> list[dict[str, Any]]:
    """Best cost per iteration with the evaluations spent by then, as the planner recorded them
    (``stats.evaluation_history``).  A planner that records a best-cost history but no evaluation
    history gets its total spread evenly over its iterations, and ``evaluations_estimated`` says so.
    ``wall_s`` is the planner's own ``stats.time_history`` (seconds since the plan started), null where it
    records none."""
    stats = episode.path.stats
    history = stats.cost_history
    if not history:
        return []
    recorded = len(stats.evaluation_history) == len(history)
    if recorded:
        evaluations = [int(e) for e in stats.evaluation_history]
    else:
        steps = max(len(history) - 1, 1)
        evaluations = [int(round(stats.evaluations * i / steps)) for i in range(len(history))]
    times = ([float(t) for t in stats.time_history] if len(stats.time_history) == len(history)
             else [None] * len(history))
    return [{"config_hash": cell.config_hash, "iteration": i, "best_cost": float(cost),
             "evaluations": spent, "evaluations_estimated": not recorded, "wall_s": wall_s}
            for i, (cost, spent, wall_s) in enumerate(zip(history, evaluations, times))]


def _success(row: dict[str, Any]) -> bool:
    if row.get("outcome") != "ok":
        return False
    if row["mode"] == "physics":
        return bool(row.get("reached")) and row.get("collisions") == 0
    return bool(row.get("plan_collision_free"))
