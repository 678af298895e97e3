"""A scenario as a dm_control task: the ``dm_env`` API over the runner's own episode stepper.

The physics is a :class:`dm_control.mujoco.Physics` built from the MJCF text
that runs and logs use (``compile_scene(scenario).xml``); :func:`same_model`
checks that it compiled to the same model, byte for byte.  The task drives a
:class:`sim.stepper.EpisodeStepper` on that physics' ``MjData``, as
``swarmnav run``'s navigator does, and calls none of the loop's steps itself:

* ``initialize_episode``: a new stepper and its ``reset()`` (start pose, obstacles
  at t = 0, the recorder started, the initial contact check, the first observation);
* ``before_step``: the action becomes a wheel command (:func:`action_command`);
* ``physics.step``: ``EpisodeStepper.step(command)``, one control period;
* ``after_step``: the reward and cost of the stepper's new observation.

So the environment and ``swarmnav run`` share every step of the loop, the metrics
(SPL included) and what a recording holds.  ``discount`` is 0 when the goal is
reached (termination) or, when the scenario stops on collision, at the first
collision; it is 1 at the time limit (truncation), as dm_env defines them.
The step's collision count (the Safety-Gymnasium ``cost``) and the run's
metrics are in :meth:`NavigationTask.info`: dm_env's ``TimeStep`` has no slot
for them.  Collisions present at the start (the robot placed in contact) are
counted in the first step's cost, so the costs always sum to the run's collisions.

An episode already over at its start (the start within the goal's tolerance;
the robot in contact when the scenario stops on collision) ends where ``swarmnav run``
ends it, with no physics step.
dm_env has no first time step that is also the last, so ``reset()`` returns the
usual FIRST time step and the first ``step(action)`` returns the LAST one
(discount 0 for the goal or a collision, 1 for the time limit) without applying
the action or advancing the physics: its reward is 0 (no progress, no time, no
goal bonus: the goal was not reached by a step) and its cost the collisions
present at the start.  The same holds through Gymnasium, whose ``reset`` cannot
end an episode either: ``reset`` returns ``info["outcome"]`` already set (and
``info["metrics"]``), and the first ``step`` returns ``terminated`` or
``truncated``.  The run's metrics have 0 steps, as ``swarmnav run`` reports it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path as FilePath
from typing import Any

import mujoco
import numpy as np
from dm_control import mujoco as dm_mujoco
from dm_control.rl import control

from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.policy_interface import (ACTION_MODES, PolicyObserver, action_command, checked_action,
                                                   ObservationLayout, normalised_action, observation_layout)
from swarmnav.models.errors import ConfigError
from swarmnav.sim.defaults import LOG_FORMATS
from swarmnav.models.scenario import Scenario, load_scenario
from swarmnav.models.seeds import Seeds
from swarmnav.sim.episode import EpisodeSpec, plan_episode
from swarmnav.sim.plugins import load_plugins
from swarmnav.sim.control_period import control_periods
from swarmnav.env.observations import action_spec, observation_specs
from swarmnav.env.reward import RewardWeights
from swarmnav.sim.simulation import Simulation
from swarmnav.sim.scene import compile_scene, index_scene
from swarmnav.sim.stepper import EpisodeStepper

NAVIGATOR_NAME = "env"  # what a recorded episode names as its navigator


@dataclass(frozen=True)
class EnvOptions:
    """How the environment is set up.

    Attributes:
        action: ``"twist"`` (normalised v, omega in [-1, 1]^2) or ``"wheels"`` (rad/s).
        path_planner: a planner name; its path (planned at reset on the obstacles at
            t = 0) gives the ``path`` observation.  None: no ``path``.
        path_waypoints: P, the waypoints in ``path``.
        obstacle_slots: N, the rows of ``obstacles`` (None: the scenario's moving obstacles, at least 1).
        tracked_obstacles: with the ``rangefinder`` sensing model, also observe the tracker's estimates
            as ``obstacles`` (the ``detector`` model always gives ``obstacles``).
        reward: the reward's weights.
        time_limit_s, stop_on_collision: override the scenario's.
        terminate_on_collision: the name RL users look for: end the episode (termination, discount 0)
            at the first collision; sets ``stop_on_collision`` (giving both, they must agree).
        action_repeat: control periods per action (the action is held; the step's reward sums the
            progress, time and effort of all of them and its cost their collisions; an episode that
            ends within them ends there).  ``control_timestep()`` is the repeat's length.
        seed: the planner's seed (None: the scenario's, ``Scenario.seeds``).
        world_seed: the obstacles' random walks (None: the scenario's).
        record_to: an ``.mcap`` path to record each episode to with the recorder of
            ``swarmnav run``; ``{episode}`` in it is replaced by the episode number.
        record_format: the recording's log format, ``swarmnav`` or ``ros2`` (``--log-format`` of ``run``).
    """

    action: str = "twist"
    path_planner: str | None = None
    path_waypoints: int = 5
    obstacle_slots: int | None = None
    tracked_obstacles: bool = False
    reward: RewardWeights = field(default_factory=RewardWeights)
    time_limit_s: float | None = None
    stop_on_collision: bool | None = None
    terminate_on_collision: bool | None = None
    action_repeat: int = 1
    seed: int | None = None
    world_seed: int | None = None
    record_to: str | None = None
    record_format: str = "swarmnav"

    def __post_init__(self) -> None:
        if self.record_format not in LOG_FORMATS:
            raise ConfigError("env.record_format", f"expected one of {list(LOG_FORMATS)}, got {self.record_format!r}")
        if self.action not in ACTION_MODES:
            raise ConfigError("env.action", f"expected one of {list(ACTION_MODES)}, got {self.action!r}")
        if self.path_waypoints < 1:
            raise ConfigError("env.path_waypoints", f"must be >= 1, got {self.path_waypoints}")
        if self.obstacle_slots is not None and self.obstacle_slots < 1:
            raise ConfigError("env.obstacle_slots", f"must be >= 1, got {self.obstacle_slots}")
        if self.time_limit_s is not None and not self.time_limit_s > 0:
            raise ConfigError("env.time_limit_s", f"must be > 0, got {self.time_limit_s}")
        if isinstance(self.action_repeat, bool) or not isinstance(self.action_repeat, int) or self.action_repeat < 1:
            raise ConfigError("env.action_repeat", f"must be an integer >= 1, got {self.action_repeat!r}")
        if not isinstance(self.reward, RewardWeights):
            raise ConfigError("env.reward", f"expected a RewardWeights, got {type(self.reward).__name__}")
        if self.terminate_on_collision is not None:
            if self.stop_on_collision is not None and self.stop_on_collision != self.terminate_on_collision:
                raise ConfigError("env.terminate_on_collision",
                                  f"is {self.terminate_on_collision} but stop_on_collision is {self.stop_on_collision}")
            object.__setattr__(self, "stop_on_collision", bool(self.terminate_on_collision))


def check_time_limit(time_limit_s: float | None, control_dt_s: float) -> None:
    """The episode runs whole control periods: a limit that is not a whole number of them is refused
    (:mod:`sim.control_period`; 0.051 s at 50 Hz would end after 0.04 s)."""
    if time_limit_s is not None:
        control_periods(time_limit_s, control_dt_s, "env.time_limit_s")


def model_bytes(model: mujoco.MjModel) -> bytes:
    """The model in MuJoCo's binary format (MJB)."""
    buffer = np.empty(mujoco.mj_sizeModel(model), dtype=np.uint8)
    mujoco.mj_saveModel(model, None, buffer)
    return buffer.tobytes()


def same_model(a: mujoco.MjModel, b: mujoco.MjModel) -> bool:
    return model_bytes(a) == model_bytes(b)


class SwarmnavPhysics(dm_mujoco.Physics):
    """dm_control physics whose control step is one :meth:`EpisodeStepper.step` with the task's command."""

    stepper: EpisodeStepper | None = None
    command: ControlCommand | None = None  # set by the task's before_step
    frozen: bool = False  # the episode ended at its start: its one step advances nothing
    repeat: int = 1  # control periods per action
    periods: int = 0  # control periods the last step ran (fewer than ``repeat`` when the episode ended)

    def step(self, nstep: int = 1) -> None:
        if self.stepper is None or nstep != self.stepper.k * self.repeat:
            raise RuntimeError(f"step {nstep} physics steps: the environment steps "
                               f"{getattr(self.stepper, 'k', '?')} x {self.repeat} at a time, through its task")
        self.periods = 0
        if self.frozen:
            return
        command, self.command = self.command, None
        if command is None:
            raise RuntimeError("no command for this step: the task's before_step sets it")
        with self.check_invalid_state():
            for _ in range(self.repeat):
                self.stepper.step(command)
                self.periods += 1
                if self.stepper.outcome:
                    break


class NavigationTask(control.Task):
    """Drive from the scenario's start to its goal; see the module docstring."""

    def __init__(self, scenario: Scenario, physics: SwarmnavPhysics, xml: str, options: EnvOptions,
                 layout: ObservationLayout | None = None):
        self.options = options
        self.scene = index_scene(physics.model.ptr, xml)  # the indices, on the physics' own model
        self.simulation = Simulation(scenario, self.scene)
        check_time_limit(options.time_limit_s, self.simulation.control_dt_s)
        self.set_seeds(EpisodeSpec(scenario, seed=options.seed, world_seed=options.world_seed).seeds)
        self.layout = layout or task_layout(scenario, options, self.scene.drive)
        self.episode = -1
        self.stepper: EpisodeStepper | None = None
        self.over_at_start = False
        self._planned: tuple[Seeds, Any] | None = None  # (seeds, episode) of the path

    # --- set-up between episodes -------------------------------------------------------------
    @property
    def scenario(self) -> Scenario:
        return self.simulation.scenario

    def set_seeds(self, seeds: Seeds) -> None:
        """The planner's seed (for the ``path`` observation) and the obstacles' random walks, from the next
        episode on (the model is unchanged)."""
        self.seeds = seeds
        if seeds.world != self.scenario.world_seed:
            self.simulation = Simulation(self.scenario.with_world_seed(seeds.world), self.scene)

    def planned_path(self):
        """The path planner's episode for the current seeds, planned once and kept (None without a planner)."""
        if self.options.path_planner is None:
            return None
        if self._planned is None or self._planned[0] != self.seeds:
            spec = EpisodeSpec(self.scenario, planner=self.options.path_planner, seed=self.seeds.planner,
                               world_seed=self.seeds.world)
            self._planned = (self.seeds, plan_episode(spec, drive=False))  # a path: no navigator to build
        return self._planned[1]

    # --- dm_control.rl.control.Task ---------------------------------------------------------------
    def initialize_episode(self, physics: SwarmnavPhysics) -> None:
        self.close_recording("interrupted")
        self.episode += 1
        scenario, options = self.scenario, self.options
        planned = self.planned_path()
        waypoints = planned.path.waypoints if planned is not None else None
        goal = scenario.goal
        self.observer = PolicyObserver(self.layout, (goal.x_m, goal.y_m), waypoints)
        recorder = self._open_recorder()
        context = None if recorder is None else self.simulation.context(
            options.path_planner or "none", {}, self.seeds.planner, NAVIGATOR_NAME, {"action": options.action})
        self.stepper = physics.stepper = self.simulation.stepper(
            time_limit_s=options.time_limit_s, stop_on_collision=options.stop_on_collision, recorder=recorder,
            context=context, path_m=waypoints, sense_obstacles=bool(self.layout.obstacle_slots),  # only when observed
            data=physics.data.ptr)
        physics.command = None
        physics.repeat = options.action_repeat
        self.action = self.previous_action = None  # normalised; None before the first step (zeros for smoothness)
        self._action_in_reward = bool(options.reward.effort_per_s or options.reward.smoothness)
        self.return_, self.cost, self.reward_value = 0.0, 0.0, 0.0
        self._collisions = 0  # collisions at the start go into the first step's cost
        self._observed(self.stepper.reset())
        physics.frozen = self.over_at_start = bool(self.outcome)

    def before_step(self, action: np.ndarray, physics: SwarmnavPhysics) -> None:
        action = checked_action(action)  # ActionError: NaN, wrong shape or dtype, before any physics
        if self._action_in_reward:  # only the effort and smoothness terms read the normalised action
            self.previous_action, self.action = self.action, normalised_action(action, self.options.action,
                                                                               self.scene.drive)
        if not self.over_at_start:
            physics.command = action_command(action, self.options.action, self.scene.drive,
                                             self.scenario.max_speed_m_s)

    def after_step(self, physics: SwarmnavPhysics) -> None:
        stepper = self.stepper
        collisions = stepper.collisions
        self.cost = float(collisions - self._collisions)
        self._collisions = collisions
        if self.over_at_start:
            self.reward_value = 0.0
        else:
            distance_before_m = self.distance_m
            self._observed(stepper.observation)
            self.reward_value = self.options.reward.reward(
                distance_before_m, self.distance_m, self.outcome == "goal_reached", stepper.dt_s * physics.periods,
                self.cost, self.action, self.previous_action)
        self.return_ += self.reward_value

    def get_observation(self, physics: SwarmnavPhysics) -> dict[str, np.ndarray]:
        return dict(self.obs)  # the observer builds fresh arrays at every observation: nothing to copy

    def get_reward(self, physics: SwarmnavPhysics) -> float:
        return self.reward_value

    def get_termination(self, physics: SwarmnavPhysics) -> float | None:
        if self.outcome in ("goal_reached", "collision", "left_arena"):
            return 0.0
        if self.outcome == "timeout":
            return 1.0
        return None

    def action_spec(self, physics: SwarmnavPhysics):
        return action_spec(self.options.action, self.scene.drive)

    def observation_spec(self, physics: SwarmnavPhysics):
        return observation_specs(self.layout)

    # --- the step's side information -------------------------------------------------------------
    @property
    def outcome(self) -> str:
        return self.stepper.outcome

    @property
    def observation(self):
        """The stepper's last :class:`~controllers.navigator.Observation`."""
        return self.stepper.observation

    def info(self) -> dict[str, Any]:
        """The step's ``cost``, the collisions so far, the clearance now and, at the end, the run's metrics
        (``RunResult.summary()``, as ``swarmnav run --json`` reports them)."""
        stepper = self.stepper
        out: dict[str, Any] = {"cost": self.cost, "collisions": stepper.collisions,
                               "clearance_m": stepper.clearance_m, "time_s": stepper.observation.time_s,
                               "outcome": stepper.outcome}
        if stepper.result is not None:
            out["metrics"] = stepper.result.summary()
        return out

    def close_recording(self, outcome: str) -> None:
        """Finish a recording still open (an episode reset or closed before its end)."""
        if self.stepper is not None:
            self.stepper.close(outcome)

    def _observed(self, observation) -> None:
        """The policy's view of a new observation, and the goal distance the reward needs."""
        self.obs = self.observer(observation)
        self.distance_m = self.observer.goal_distance_m(observation.pose.x_m, observation.pose.y_m)

    def _open_recorder(self):
        if self.options.record_to is None:
            return None
        from swarmnav.log.writer import McapRecorder
        return McapRecorder(FilePath(self.options.record_to.replace("{episode}", str(self.episode))), overwrite=True,
                            log_format=self.options.record_format)


def task_layout(scenario: Scenario, options: EnvOptions, drive) -> ObservationLayout:
    """The observation layout of ``scenario`` under ``options`` (the entries and bounds of the specs)."""
    return observation_layout(scenario, drive, options.path_waypoints if options.path_planner else 0,
                              options.obstacle_slots, options.tracked_obstacles)


def make_environment(scenario: Scenario | str, options: EnvOptions | None = None,
                     layout: ObservationLayout | None = None, **kwargs: Any) -> control.Environment:
    """The dm_env environment of a scenario (a name, a path or a :class:`Scenario`).

    ``kwargs`` are :class:`EnvOptions` fields when ``options`` is not given; ``layout`` fixes the
    observation's entries and bounds (:mod:`swarmnav.env.worlds`: the same spaces across scenarios), else the
    scenario's own.  Installed plugins' scenarios and planners are known here (:mod:`swarmnav.sim.plugins`).
    """
    load_plugins()
    if isinstance(scenario, (str, FilePath)):
        scenario = load_scenario(str(scenario))
    options = options or EnvOptions(**kwargs)
    scene = compile_scene(scenario)
    physics = SwarmnavPhysics.from_xml_string(scene.xml)
    if not same_model(physics.model.ptr, scene.model):
        raise RuntimeError("dm_control compiled the scene's MJCF to a different model")
    task = NavigationTask(scenario, physics, scene.xml, options, layout)
    return control.Environment(physics, task, n_sub_steps=task.simulation.steps_per_control * options.action_repeat)

