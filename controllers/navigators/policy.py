"""``policy``: a Python callable ``obs -> action`` drives the robot (a learned or hand-written policy).

``--navigator policy --navigator-set policy=mypkg.agent:act`` calls ``act`` with
the observation dict the environment gives (:mod:`controllers.policy_interface`)
every control step and turns its (2,) action into wheel speeds the same way, so
a policy trained in ``swarmnav.env`` runs here unchanged.

Loading the callable: ``pkgutil.resolve_name`` (the standard library's
``module:attribute`` resolver) imports the user's module.  This is the one place
outside ``sim/`` that loads code by name, and it only ever loads the user's
policy, never project code (the registry of navigators stays explicit);
``tests/test_layering.py`` allows exactly this module and this call.  ``policy``
is declared a code parameter (:func:`models.parameters.code_parameter`): a
scenario file, a study file or a log may name it only when the user passes
``--trust-code`` (the check reads the declaration and imports nothing).
"""

from __future__ import annotations

import pkgutil
from dataclasses import dataclass, field
from typing import Any, Callable, ClassVar

import numpy as np

from swarmnav.controllers.navigator import NavigationSetup, NavigationStep, Observation
from swarmnav.controllers.policy_interface import (ACTION_MODES, ActionError, PolicyObserver, action_command,
                                                   checked_action, flatten_observation, observation_layout)
from swarmnav.controllers.observation_normaliser import ObservationNormaliser
from swarmnav.models.errors import ConfigError
from swarmnav.models.parameters import code_parameter, param, within

FIELD = "navigator.params.policy"


def load_policy(name: str) -> Callable[[dict[str, np.ndarray]], Any]:
    """``"module:function"`` -> the callable (ConfigError naming ``navigator.params.policy``)."""
    module, sep, attribute = name.partition(":")
    if not sep or not module or not attribute:
        raise ConfigError(FIELD, f"expected 'module:function', got {name!r}")
    try:
        policy = pkgutil.resolve_name(name)
    except Exception as exc:  # any failure of the user's module is a bad value of this field
        raise ConfigError(FIELD, f"cannot load {name!r}: {type(exc).__name__}: {exc}") from None
    if not callable(policy):
        raise ConfigError(FIELD, f"{name!r} is not callable")
    return policy


@dataclass
class PolicyNavigator:
    """Calls ``policy`` on the environment's observation dict; its action becomes the wheel command.

    Args:
        policy: ``module:function``, a callable ``obs -> action``.
        action: ``"twist"`` (normalised v, omega) or ``"wheels"`` (rad/s), as in the environment.
        path_waypoints: P > 0 adds the next P waypoints of the path planned at t = 0 as ``path``.
        obstacle_slots: N, the rows of ``obstacles`` (None: the scenario's moving obstacles, at least 1).
        tracked_obstacles: with the ``rangefinder`` sensing model, also give the tracker's estimates as
            ``obstacles`` (the ``detector`` model always does).
        flatten: hand the policy one vector in the documented flat order
            (:data:`controllers.policy_interface.FLAT_ORDER`), as the environment's ``flatten=True``.
        normalise: an ``.npz`` of a saved observation normalisation
            (:mod:`controllers.observation_normaliser`, e.g. a ``VecNormalize``'s statistics) applied to
            the observation (after flattening) before the policy sees it.

    These three mean what the environment's options of the same names mean; a policy
    trained with some values must be run with the same ones.
    """

    name: ClassVar[str] = "policy"
    uses_detections: bool = field(default=True, init=False, repr=False)  # per run: set by reset
    uses_planner: ClassVar[bool] = False
    replan_wall_s: ClassVar[float] = 0.0  # plans nothing in step()
    policy: str = code_parameter()  # names code: never taken from a data file without --trust-code
    action: str = param("twist", choices=ACTION_MODES)
    path_waypoints: int = param(0, within(0, 1000))
    obstacle_slots: int | None = param(None, within(1, 1000))
    tracked_obstacles: bool = False
    flatten: bool = False
    normalise: str = ""

    def __post_init__(self) -> None:
        self._normaliser = (ObservationNormaliser.load(self.normalise, "navigator.params.normalise")
                            if self.normalise else None)
        self._policy = load_policy(self.policy)

    def reset(self, setup: NavigationSetup) -> None:
        geometry = getattr(setup.controller, "geometry", None)
        if geometry is None:
            raise TypeError("the policy navigator needs a controller with a drive geometry")
        self._geometry = geometry
        self._max_speed_m_s = setup.max_speed_m_s
        if setup.scenario is None:
            raise TypeError("the policy navigator needs the scenario in its NavigationSetup")
        layout = observation_layout(setup.scenario, geometry, self.path_waypoints, self.obstacle_slots,
                                    self.tracked_obstacles)
        goal = setup.goal
        self._observer = PolicyObserver(layout, (goal.x_m, goal.y_m), setup.path.waypoints)
        self.uses_detections = bool(layout.obstacle_slots)  # read by the runner after reset

    def policy_observation(self, observation: Observation):
        """What the policy is given: the observation dict, flattened and normalised as asked."""
        obs = self._observer(observation)
        if self.flatten:
            obs = flatten_observation(obs)
        if self._normaliser is not None:
            try:
                obs = self._normaliser(obs)
            except ValueError as exc:
                raise ConfigError("navigator.params.normalise", str(exc)) from None
        return obs

    def step(self, observation: Observation) -> NavigationStep:
        try:
            raw = self._policy(self.policy_observation(observation))
        except Exception as exc:  # the user's code failed: their input, reported against the parameter
            raise ConfigError(FIELD, f"{self.policy!r} raised {type(exc).__name__}: {exc}") from None
        try:
            action = checked_action(raw)  # the environment's own check
        except ActionError as exc:
            raise ConfigError(FIELD, f"{self.policy!r} returned a bad action: {exc}") from None
        return NavigationStep(action_command(action, self.action, self._geometry, self._max_speed_m_s))
