"""Path planners behind one seam: ``plan(problem, rng) -> Path``.

The registry (``PLANNERS``, ``register``, ``make_planner``) lives in
:mod:`swarmnav.planners.registry`.  This package's own import is light, so that
``swarmnav.planners.errors`` (which the CLI maps to exit 3) costs no planner
and no SciPy; the registry's names below are still importable from here, loaded
on first use (PEP 562 module ``__getattr__``).  No module in this package
imports MuJoCo.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "PLANNERS", "register", "make_planner",
    "Problem", "Path", "PlanStats", "Planner", "Pose2D", "Disc", "Box", "Rect",
    "PlanningError", "StartBlocked", "GoalBlocked", "NoPathFound", "BudgetExceeded", "ConfigError",
]


def __getattr__(name: str) -> Any:
    if name not in __all__:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from swarmnav.planners import registry
    return getattr(registry, name)
