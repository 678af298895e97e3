"""Path planners behind one seam: ``plan(problem, rng) -> Path``.

``PLANNERS`` is built explicitly here; registering a duplicate name is an error.
No module in this package imports MuJoCo.
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from typing import Any

from swarmnav.planners.bee_colony import AdaptiveLimitBeeColonyPlanner, BeeColonyPlanner
from swarmnav.planners.grid_search import AStarPlanner, DijkstraPlanner, DStarLitePlanner, ThetaStarPlanner
from swarmnav.planners.improved_ant_colony import ImprovedAntColonyPlanner
from swarmnav.planners.max_min_ant_system import MaxMinAntSystemPlanner
from swarmnav.planners.waiter_ant_colony import WaiterAntColonyPlanner
from swarmnav.planners.grey_wolf import GreyWolfPlanner
from swarmnav.planners.optimal import OptimalPlanner
from swarmnav.planners.particle_swarm import ParticleSwarmPlanner
from swarmnav.planners.errors import BudgetExceeded, GoalBlocked, NoPathFound, PlanningError, StartBlocked
from swarmnav.models.errors import ConfigError
from swarmnav.models.world import Box, Disc, Pose2D, Rect
from swarmnav.planners.problem import Path, Planner, PlanStats, Problem
from swarmnav.planners.straight import StraightPlanner

PLANNERS: dict[str, type] = {}


def register(cls: type) -> type:
    """Add a planner class to :data:`PLANNERS`; a name already taken is an error."""
    name = getattr(cls, "name", None)
    if not isinstance(name, str) or not name:
        raise TypeError(f"{cls.__name__} has no planner name")
    if name in PLANNERS:
        raise ValueError(f"planner name {name!r} is registered twice "
                         f"({PLANNERS[name].__name__} and {cls.__name__})")
    PLANNERS[name] = cls
    return cls


for _cls in (StraightPlanner, AStarPlanner, DijkstraPlanner, ThetaStarPlanner, DStarLitePlanner,
             MaxMinAntSystemPlanner, ImprovedAntColonyPlanner, WaiterAntColonyPlanner,
             OptimalPlanner, BeeColonyPlanner, AdaptiveLimitBeeColonyPlanner, GreyWolfPlanner,
             ParticleSwarmPlanner):
    register(_cls)


def planner_params(cls: type) -> dict[str, Any]:
    """The parameters a planner accepts, with their defaults."""
    return {f.name: (f.default if f.default is not dataclasses.MISSING else None)
            for f in dataclasses.fields(cls) if f.init}


def _coerce(value: Any, annotation: Any, field: str) -> Any:
    """Check a user-given parameter against a dataclass field's annotation."""
    origin = typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType):
        args = typing.get_args(annotation)
        if value is None and type(None) in args:
            return None
        errors = []
        for arg in args:
            if arg is type(None):
                continue
            try:
                return _coerce(value, arg, field)
            except ConfigError as exc:
                errors.append(exc.problem)
        raise ConfigError(field, "; ".join(errors))
    if annotation is bool:
        if isinstance(value, bool):
            return value
        raise ConfigError(field, f"expected true or false, got {value!r}")
    if annotation is int:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or float(value) != int(value):
            raise ConfigError(field, f"expected an integer, got {value!r}")
        return int(value)
    if annotation is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(field, f"expected a number, got {value!r}")
        if not math.isfinite(float(value)):
            raise ConfigError(field, f"must be finite, got {value!r}")
        return float(value)
    if annotation is str:
        if not isinstance(value, str):
            raise ConfigError(field, f"expected a string, got {value!r}")
        return value
    return value


def make_planner(name: str, params: dict[str, Any] | None = None, source: str | None = None) -> Any:
    """Build a registered planner from its name and a parameter table.

    Raises:
        ConfigError: unknown planner, unknown parameter, or a value of the wrong type.
    """
    if name not in PLANNERS:
        raise ConfigError("planner.name", f"unknown planner {name!r} (known: {', '.join(sorted(PLANNERS))})",
                          source)
    cls = PLANNERS[name]
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    hints = typing.get_type_hints(cls)
    kwargs = {}
    for key, value in (params or {}).items():
        if key not in fields:
            raise ConfigError(f"planner.params.{key}",
                              f"unknown parameter for {name!r} (known: {', '.join(sorted(fields)) or 'none'})",
                              source)
        try:
            kwargs[key] = _coerce(value, hints.get(key, typing.Any), f"planner.params.{key}")
        except ConfigError as exc:
            raise ConfigError(exc.field, exc.problem, source) from None
    try:
        return cls(**kwargs)
    except ConfigError as exc:
        raise ConfigError(exc.field, exc.problem, source) from None
    except (ValueError, TypeError) as exc:
        raise ConfigError(f"planner.params", str(exc), source) from None


__all__ = [
    "PLANNERS", "register", "make_planner", "planner_params",
    "Problem", "Path", "PlanStats", "Planner", "Pose2D", "Disc", "Box", "Rect",
    "PlanningError", "StartBlocked", "GoalBlocked", "NoPathFound", "BudgetExceeded", "ConfigError",
]
