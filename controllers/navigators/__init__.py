"""Navigators behind one seam (:mod:`controllers.navigator`), in an explicit registry.

No module in this package imports MuJoCo.
"""

from __future__ import annotations

from typing import Any

from swarmnav.controllers.navigator import check_declarations
from swarmnav.controllers.navigators.follow import FollowNavigator
from swarmnav.controllers.navigators.iaco_local import IacoLocalNavigator
from swarmnav.controllers.navigators.immas_stepwise import ImmasStepwiseNavigator
from swarmnav.controllers.navigators.policy import PolicyNavigator
from swarmnav.controllers.navigators.dstar_replan import DStarReplanNavigator
from swarmnav.controllers.navigators.dwa import DynamicWindowNavigator
from swarmnav.controllers.navigators.replan import ReplanNavigator
from swarmnav.controllers.navigators.velocity_obstacle import VelocityObstacleNavigator
from swarmnav.models.parameters import build_component, register_component

NAVIGATORS: dict[str, type] = {}


def register(cls: type) -> type:
    """Add a navigator class to :data:`NAVIGATORS`; a missing or taken name, or a missing declaration of what
    it uses (:func:`controllers.navigator.check_declarations`), is an error."""
    return register_component(NAVIGATORS, "navigator", check_declarations(cls))


for _cls in (FollowNavigator, ReplanNavigator, DStarReplanNavigator, DynamicWindowNavigator, VelocityObstacleNavigator,
             IacoLocalNavigator, ImmasStepwiseNavigator, PolicyNavigator):
    register(_cls)


def make_navigator(name: str, params: dict[str, Any] | None = None, source: str | None = None) -> Any:
    """Build a registered navigator from its name and a parameter table (ConfigError naming the field)."""
    return build_component(NAVIGATORS, "navigator", name, params, source)


__all__ = ["NAVIGATORS", "register", "make_navigator"]
