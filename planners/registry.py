"""The planner registry: ``PLANNERS`` is built explicitly here; registering a duplicate name is an error.

Importing this module imports every planner (and SciPy with the ant colonies);
``swarmnav.planners`` itself stays light and hands these names out on first use.
"""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

from swarmnav.planners.ant_system import AntSystemPlanner
from swarmnav.planners.bee_colony import AdaptiveLimitBeeColonyPlanner, BeeColonyPlanner
from swarmnav.planners.dstar_lite import DStarLitePlanner
from swarmnav.planners.grid_search import AStarPlanner, DijkstraPlanner
from swarmnav.planners.improved_ant_colony import ImprovedAntColonyPlanner
from swarmnav.planners.improved_max_min_ant_system import ImprovedMaxMinAntSystemPlanner
from swarmnav.planners.max_min_ant_system import MaxMinColonyPlanner
from swarmnav.planners.waiter_ant_colony import WaiterAntColonyPlanner
from swarmnav.planners.grey_wolf import GreyWolfPlanner
from swarmnav.planners.optimal import OptimalPlanner
from swarmnav.planners.particle_swarm import ParticleSwarmPlanner
from swarmnav.planners.ompl_geometric import OMPL_GEOMETRIC_PLANNERS
from swarmnav.planners.sampling_ompl import OMPL_PLANNERS
from swarmnav.planners.errors import BudgetExceeded, GoalBlocked, NoPathFound, PlanningError, StartBlocked
from swarmnav.models.errors import ConfigError
from swarmnav.models.world import Box, Disc, Pose2D, Rect
from swarmnav.planners.problem import Path, Planner, PlanStats, Problem
from swarmnav.planners.straight import StraightPlanner
from swarmnav.planners.theta_star import ThetaStarPlanner
from swarmnav.models.parameters import build_component, register_component

PLANNERS: dict[str, type[Planner]] = {}
PlannerClass = TypeVar("PlannerClass", bound=type)


def register(cls: PlannerClass) -> PlannerClass:
    """Add a planner class to :data:`PLANNERS`: it needs a free name, a ``plan`` method and the obstacles it
    supports (:class:`planners.problem.Planner`)."""
    supports = getattr(cls, "supports", None)
    if not isinstance(supports, frozenset) or not supports or not supports <= {"discs", "boxes"}:
        raise TypeError(f"{cls.__name__} must declare the obstacles it supports, a non-empty subset "
                        "of {'discs', 'boxes'}")
    if not callable(getattr(cls, "plan", None)):
        raise TypeError(f"{cls.__name__} has no plan(problem, rng) method (planners.problem.Planner)")
    if not dataclasses.is_dataclass(cls):  # its fields are its parameters (models.parameters.build_component)
        raise TypeError(f"{cls.__name__} must be a dataclass: its fields are its parameters")
    register_component(PLANNERS, "planner", cls)
    return cls


for _cls in (StraightPlanner, AStarPlanner, DijkstraPlanner, ThetaStarPlanner, DStarLitePlanner,
             ImprovedMaxMinAntSystemPlanner, ImprovedAntColonyPlanner, WaiterAntColonyPlanner, AntSystemPlanner,
             OptimalPlanner, BeeColonyPlanner, AdaptiveLimitBeeColonyPlanner, GreyWolfPlanner,
             ParticleSwarmPlanner, MaxMinColonyPlanner, *OMPL_PLANNERS, *OMPL_GEOMETRIC_PLANNERS):
    register(_cls)


def make_planner(name: str, params: dict[str, Any] | None = None, source: str | None = None,
                 trust_code: bool = True) -> Planner:
    """Build a registered planner from its name and a parameter table (``trust_code``: see build_component).

    Raises:
        ConfigError: unknown planner, unknown parameter, or a value of the wrong type.
    """
    return build_component(PLANNERS, "planner", name, params, source, trust_code)


__all__ = [
    "PLANNERS", "register", "make_planner",
    "Problem", "Path", "PlanStats", "Planner", "Pose2D", "Disc", "Box", "Rect",
    "PlanningError", "StartBlocked", "GoalBlocked", "NoPathFound", "BudgetExceeded", "ConfigError",
]
