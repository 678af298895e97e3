"""The safety layer: what the stepper applies to a navigator's command after ``navigator.step`` (no MuJoCo).

Nav2 keeps its Collision Monitor after the controller, as a node of its own, so that no controller
carries a copy of it; here likewise no navigator carries the safety filter or the evasion.  The run's
composition (:func:`sim.episode.plan_episode`) builds one :class:`SafetyLayer` per run beside the
navigator, and :meth:`sim.simulation.Simulation.run` passes every :class:`~controllers.navigator.NavigationStep`
through :meth:`SafetyLayer.after` before the stepper applies it.  Two stages, in this order:

1. the evasion (``evade``, :mod:`controllers.evasion`): velocity-obstacle avoidance takes over while a
   sensed obstacle's predicted time to collision is below ``evade_trigger_s`` (an ``evade`` event at each
   takeover);
2. the safety filter (``safety_filter``, :mod:`controllers.safety_filter`): Nav2's "approach" filter
   slows or stops a command whose predicted time to collision is below ``time_before_collision_s`` (a
   ``safety_trigger`` event at each rising edge; the run's ``safety_triggers`` counts them).

The layer is configured per run with the navigator's parameters (``navigator.params`` in a scenario,
``--navigator-set``, an ``--arm``): a navigator class offers the switches it takes, with its defaults,
in ``safety_layer: ClassVar[dict[str, bool]]`` (``replan``: ``{"safety_filter": False, "evade": True}``);
each switch brings its threshold (:data:`SWITCHES`).  A navigator that offers none takes none.  A switch's
further options (:data:`OPTIONS`, all off by default) are taken only by a navigator that lists them in
``safety_layer_options: ClassVar[tuple[str, ...]]`` (``dstar_replan``, ``dwa``, ``iaco_local`` and ``immas_stepwise``:
``evade_still_m_s``, ``evade_reverse``, ``evade_turn_cost_m_s_rad``), so the others' parameters stay as they were.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

from swarmnav.controllers.evasion import Evasion, evaded, evasion_for
from swarmnav.controllers.navigator import NavigationSetup, NavigationStep, Observation
from swarmnav.controllers.safety_filter import SafetyFilter
from swarmnav.models.parameters import above, param, within

SWITCHES = {"safety_filter": "time_before_collision_s", "evade": "evade_trigger_s"}  # switch -> its threshold
# switch -> its further options (a navigator takes those it lists in safety_layer_options)
OPTIONS = {"evade": ("evade_still_m_s", "evade_reverse", "evade_turn_cost_m_s_rad")}


def offered(navigator_class: type) -> tuple[str, ...]:
    """The layer parameters a navigator class takes: each switch it offers, then that switch's threshold."""
    switches = getattr(navigator_class, "safety_layer", {})
    options = getattr(navigator_class, "safety_layer_options", ())
    return tuple(key for switch in switches
                 for key in (switch, SWITCHES[switch], *(o for o in OPTIONS.get(switch, ()) if o in options)))


@dataclass
class SafetyLayer:
    """The evasion and the safety filter after a navigator; see the module docstring.

    Args:
        safety_filter: Nav2's "approach" filter on every command.
        time_before_collision_s: the filter's smallest allowed predicted time to collision.
        evade: the velocity-obstacle evasion on every command.
        evade_trigger_s: the predicted time to collision below which the evasion takes over.
        evade_still_m_s: sensed obstacles no faster than this do not trigger the evasion (0: off).
        evade_reverse: the evasion backs toward a candidate behind the robot instead of turning round first.
        evade_turn_cost_m_s_rad: the evasion's cost of a candidate grows by this per radian of turn it needs.
    """

    name: ClassVar[str] = "safety"
    safety_filter: bool = False
    time_before_collision_s: float = param(1.0, above(0, 600))
    evade: bool = False
    evade_trigger_s: float = param(2.0, within(0, 600))
    evade_still_m_s: float = param(0.0, within(0, 5))
    evade_reverse: bool = False
    evade_turn_cost_m_s_rad: float = param(0.0, within(0, 10))

    def __post_init__(self) -> None:
        self.filter: SafetyFilter | None = None
        self.evasion: Evasion | None = None

    @property
    def on(self) -> bool:
        """Whether any stage is switched on (the stepper then senses obstacles for it)."""
        return self.safety_filter or self.evade

    def reset(self, setup: NavigationSetup) -> None:
        """Fresh stages for a run (their trigger state cleared)."""
        known = setup.map_problem
        self.filter = SafetyFilter(setup.controller.geometry, known.robot_radius_m,
                                   self.time_before_collision_s) if self.safety_filter else None
        self.evasion = evasion_for(setup, self.evade_trigger_s, self.evade_still_m_s, self.evade_reverse,
                                   self.evade_turn_cost_m_s_rad) if self.evade else None

    def after(self, observation: Observation, answer: NavigationStep) -> NavigationStep:
        """The navigator's answer with the evasion, then the filter, applied to its command (the answer
        itself when neither changes it)."""
        answer = evaded(self.evasion, observation, answer)
        if self.filter is None:
            return answer
        command, triggered = self.filter.apply(observation.pose, answer.command, observation.detections)
        if command is answer.command:
            return answer
        events = answer.events + ((("safety_trigger", {"linear_m_s": command.linear_m_s}),) if triggered else ())
        return NavigationStep(command, answer.new_path, events, answer.belief)


def layer_settings(navigator_class: type, params: dict[str, Any] | None) -> tuple[dict[str, Any], dict[str, Any]]:
    """``params`` split into the navigator's own and the layer's (the navigator's defaults for the
    switches it offers, overridden by ``params``)."""
    keys = offered(navigator_class)
    params = params or {}
    own = {k: v for k, v in params.items() if k not in keys}
    layer = {**getattr(navigator_class, "safety_layer", {}), **{k: v for k, v in params.items() if k in keys}}
    return own, layer


__all__ = ["OPTIONS", "SWITCHES", "SafetyLayer", "layer_settings", "offered"]
