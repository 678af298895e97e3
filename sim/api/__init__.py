"""swarmnav's Python API: plan and run scenarios, run studies, bring your own planner and navigator.

For example:

    import swarmnav
    result = swarmnav.run("gwo-scenario-1", planner="astar", seed=0)
    print(result.outcome, result.to_dict()["spl"])   # to_dict() is what `swarmnav run --json` prints
    result.plot()                                     # a Matplotlib figure

Importing ``swarmnav`` is light: MuJoCo, SciPy and the planners load on first use.  The names below are
the public surface; everything else is reachable through ``swarmnav.models``, ``swarmnav.planners``,
``swarmnav.controllers`` and ``swarmnav.sim``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from swarmnav.calls import load_scenario, plan, register_navigator, register_planner, run, run_study
from swarmnav.models.world_scenario import ImportSettings, import_world
from swarmnav.results import PlanResult, RunOutcome

if TYPE_CHECKING:
    from swarmnav.controllers.navigator import NavigationSetup, NavigationStep, Navigator, Observation
    from swarmnav.models.errors import ConfigError
    from swarmnav.models.scenario import Scenario
    from swarmnav.planners.errors import NoPathFound, PlanningError
    from swarmnav.planners.problem import Path, Planner, PlanStats, Problem

_SEAMS = ("Scenario", "ConfigError", "Problem", "Path", "Planner", "PlanStats", "PlanningError", "NoPathFound",
          "Navigator", "Observation", "NavigationSetup", "NavigationStep")

__all__ = ["load_scenario", "plan", "run", "run_study", "register_planner", "register_navigator", "import_world",
           "ImportSettings",
           "PlanResult", "RunOutcome", *_SEAMS]


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
