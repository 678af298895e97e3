"""Navigators behind one seam (:mod:`controllers.navigator`), in an explicit registry.

No module in this package imports MuJoCo.
"""

from __future__ import annotations

from typing import Any, TypeVar

from swarmnav.controllers.navigator import Navigator, check_declarations
from swarmnav.controllers.navigators.follow import FollowNavigator
from swarmnav.controllers.navigators.iaco_local import IacoLocalNavigator
from swarmnav.controllers.navigators.immas_stepwise import ImmasStepwiseNavigator
from swarmnav.controllers.navigators.policy import PolicyNavigator
from swarmnav.controllers.navigators.dstar_replan import DStarReplanNavigator
from swarmnav.controllers.navigators.dwa import DynamicWindowNavigator
from swarmnav.controllers.navigators.mppi import MppiNavigator
from swarmnav.controllers.navigators.oracle import ClairvoyantOracleNavigator
from swarmnav.controllers.navigators.replan import ReplanNavigator
from swarmnav.controllers.navigators.velocity_obstacle import VelocityObstacleNavigator
from swarmnav.models.parameters import build_component, register_component

NAVIGATORS: dict[str, type[Navigator]] = {}
NavigatorClass = TypeVar("NavigatorClass", bound=type)


def register(cls: NavigatorClass) -> NavigatorClass:
    """Add a navigator class to :data:`NAVIGATORS`; a missing or taken name, a missing ``reset`` or ``step``, or a
    missing declaration of what it uses (:func:`controllers.navigator.check_declarations`), is an error."""
    check_declarations(cls)
    missing = [method for method in ("reset", "step") if not callable(getattr(cls, method, None))]
    if missing:
        raise TypeError(f"navigator {cls.__name__} has no {' or '.join(missing)} method "
                        "(controllers.navigator.Navigator)")
    register_component(NAVIGATORS, "navigator", cls)
    return cls


for _cls in (FollowNavigator, ReplanNavigator, DStarReplanNavigator, DynamicWindowNavigator, VelocityObstacleNavigator,
             IacoLocalNavigator, ImmasStepwiseNavigator, PolicyNavigator):
    register(_cls)
register(MppiNavigator)  # Williams et al. (2017) as Nav2 adapts it (controllers/navigators/mppi.py)
register(ClairvoyantOracleNavigator)  # the clairvoyant yardstick (controllers/navigators/oracle.py)


def make_navigator(name: str, params: dict[str, Any] | None = None, source: str | None = None,
                   trust_code: bool = True) -> Navigator:
    """Build a registered navigator from its name and a parameter table (ConfigError naming the field;
    ``trust_code``: see :func:`models.parameters.build_component`)."""
    return build_component(NAVIGATORS, "navigator", name, params, source, trust_code)


__all__ = ["NAVIGATORS", "register", "make_navigator"]
