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
from swarmnav.controllers.safety_layer import SafetyLayer, layer_settings, offered
from swarmnav.models.parameters import build_component, parameter_table, register_component

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


def make_driver(name: str, params: dict[str, Any] | None = None, source: str | None = None,
                trust_code: bool = True) -> tuple[Navigator, SafetyLayer]:
    """Build a registered navigator and the run's safety layer after it (:mod:`controllers.safety_layer`)
    from the navigator's name and one parameter table: the layer takes the switches the navigator offers
    (``safety_layer``) and their thresholds, the navigator the rest (ConfigError naming the field;
    ``trust_code``: see :func:`models.parameters.build_component`)."""
    cls = NAVIGATORS.get(name)
    own, layer = layer_settings(cls, params) if cls is not None else (params, {})
    navigator = build_component(NAVIGATORS, "navigator", name, own, source, trust_code, offered(cls))
    return navigator, build_component({name: SafetyLayer}, "navigator", name, layer, source)


def make_navigator(name: str, params: dict[str, Any] | None = None, source: str | None = None,
                   trust_code: bool = True) -> Navigator:
    """The navigator of :func:`make_driver` alone (its layer parameters checked and set aside)."""
    return make_driver(name, params, source, trust_code)[0]


def navigator_table(name: str) -> list[dict[str, Any]]:
    """The parameters a registered navigator takes (:func:`models.parameters.parameter_table`): its own, then
    the safety layer's switches it offers, with its defaults."""
    cls = NAVIGATORS[name]
    return parameter_table(cls, (SafetyLayer, offered(cls), layer_settings(cls, {})[1]))


def navigator_parameters(name: str) -> tuple[str, ...]:
    """The names of every parameter a registered navigator takes (:func:`navigator_table`)."""
    return tuple(row["name"] for row in navigator_table(name))


__all__ = ["NAVIGATORS", "make_driver", "make_navigator", "navigator_parameters", "navigator_table", "register"]
