"""Typed planning failures, after nav2_core's planner exceptions.

Every failure a planner can report is a :class:`PlanningError`; the CLI maps
them to exit code 3.  Bad *input* (a malformed scenario, an unknown parameter)
is a :class:`ConfigError` instead and maps to exit code 2.
"""

from __future__ import annotations

from swarmnav.models.toml_table import fail


class PlanningError(RuntimeError):
    """Base class of every planner failure."""


class StartBlocked(PlanningError):
    """The start lies inside an (inflated) obstacle or outside the bounds."""


class GoalBlocked(PlanningError):
    """The goal lies inside an (inflated) obstacle or outside the bounds."""


class NoPathFound(PlanningError):
    """The planner finished without a collision-free path."""


class BudgetExceeded(PlanningError):
    """The planner ran out of its time or evaluation budget."""


def check_parameters(planner: object, checks: tuple[tuple[str, bool, str], ...]) -> None:
    """Raise a :class:`ConfigError` naming the first planner parameter that fails its check.

    Args:
        planner: the planner instance (its attribute gives the offending value).
        checks: ``(parameter name, passes, what it must be)`` triples, e.g.
            ``("ants", self.ants >= 1, "must be at least 1")``.
    """
    for name, ok, requirement in checks:
        if not ok:
            fail(f"planner.params.{name}", f"{requirement}, got {getattr(planner, name)!r}")
