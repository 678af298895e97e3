"""swarmnav's Python API: plan and run scenarios, run studies, bring your own planner and navigator.

For example:

    import swarmnav
    result = swarmnav.run("gwo-scenario-1", planner="astar", seed=0)
    print(result.outcome, result.to_dict()["spl"])   # to_dict() is what `swarmnav run --json` prints
    result.plot()                                     # a Matplotlib figure

Importing ``swarmnav`` is light: MuJoCo, SciPy and the planners load on first use.  The names below are
the public surface; everything else is reachable through ``swarmnav.models``, ``swarmnav.planners``,
``swarmnav.controllers``, ``swarmnav.sim`` (the physics runtime) and what stands on it: ``swarmnav.video``,
``swarmnav.log``, ``swarmnav.study``, ``swarmnav.env``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from swarmnav.calls import load_scenario as load_scenario
from swarmnav.calls import plan as plan
from swarmnav.calls import register_navigator as register_navigator
from swarmnav.calls import register_planner as register_planner
from swarmnav.calls import run as run
from swarmnav.calls import run_study as run_study
from swarmnav.models.world_scenario import ImportSettings as ImportSettings
from swarmnav.models.world_scenario import import_world as import_world
from swarmnav.results import PlanResult as PlanResult
from swarmnav.results import RunOutcome as RunOutcome

if TYPE_CHECKING:  # for type checkers the seams are plain re-exports; at run time they load on first use
    from swarmnav.controllers.navigator import NavigationSetup as NavigationSetup
    from swarmnav.controllers.navigator import NavigationStep as NavigationStep
    from swarmnav.controllers.navigator import Navigator as Navigator
    from swarmnav.controllers.navigator import Observation as Observation
    from swarmnav.models.errors import ConfigError as ConfigError
    from swarmnav.models.scenario import Scenario as Scenario
    from swarmnav.planners.errors import NoPathFound as NoPathFound
    from swarmnav.planners.errors import PlanningError as PlanningError
    from swarmnav.planners.problem import Path as Path
    from swarmnav.planners.problem import Planner as Planner
    from swarmnav.planners.problem import PlanStats as PlanStats
    from swarmnav.planners.problem import Problem as Problem

_SEAMS = ("Scenario", "ConfigError", "Problem", "Path", "Planner", "PlanStats", "PlanningError", "NoPathFound",
          "Navigator", "Observation", "NavigationSetup", "NavigationStep")

# A literal list (type checkers read it as it is written): the calls, their results, then _SEAMS.
__all__ = ["load_scenario", "plan", "run", "run_study", "register_planner", "register_navigator",
           "import_world", "ImportSettings", "PlanResult", "RunOutcome",
           "Scenario", "ConfigError", "Problem", "Path", "Planner", "PlanStats", "PlanningError", "NoPathFound",
           "Navigator", "Observation", "NavigationSetup", "NavigationStep"]


def __getattr__(name: str) -> Any:
    """The seams and errors, each loaded from its module on first use (PEP 562)."""
    if name not in _SEAMS:
        raise AttributeError(f"module 'swarmnav' has no attribute {name!r}")
    from swarmnav.controllers import navigator
    from swarmnav.models import errors, scenario
    from swarmnav.planners import errors as planning_errors, problem
    for module in (scenario, errors, problem, planning_errors, navigator):
        if hasattr(module, name):
            return getattr(module, name)
    raise AttributeError(name)


def __dir__() -> list[str]:
    return sorted(__all__)
