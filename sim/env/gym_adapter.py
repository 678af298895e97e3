"""A Gymnasium adapter over the dm_control task: ``swarmnav/Navigate-v0``.

Importing :mod:`swarmnav.env` registers the id, so in a fresh interpreter::

    env = gymnasium.make("swarmnav.env:swarmnav/Navigate-v0", scenario="gwo-scenario-2")

(Gymnasium 1.x imports the module before the colon; it does not load plugin
entry points.)  ``reset(seed=..., options={"scenario": ..., "planner_seed": ..., "world_seed": ...})``:
``seed`` seeds ``np_random`` and derives the episode's two seeds
(:meth:`models.scenario.Seeds.derived`: ``SeedSequence(seed).spawn(2)``, the path
planner's from the first child, the obstacles' random walks from the second), so
another ``seed`` gives another world; with ``scenarios=`` (:mod:`swarmnav.env.worlds`) the
seed (or, without one, a draw from ``np_random``) also draws the episode's scenario,
so every reset is a new world; ``planner_seed`` and ``world_seed`` in
``options`` override the derived ones.  ``reset()`` with no seed after a seeded
one derives the next episode's seeds from ``np_random`` (so an RL loop that seeds
once meets a new world every episode, the same sequence for the same first seed);
before any seeded reset it keeps the seeds of the environment's options (the
scenario's by default).  ``scenario`` switches to another scenario (a new model).  ``step`` returns ``(obs, reward, terminated, truncated, info)`` with
``terminated`` on the goal (or a collision when the scenario stops on one),
``truncated`` at the time limit, and ``info`` from :meth:`NavigationTask.info`
(``cost``, ``collisions``, ``clearance_m``, ``time_s``, ``outcome``, and
``metrics`` at the end).  ``render()`` (``render_mode="rgb_array"``) draws the
scene with the offscreen renderer of ``swarmnav run --video``.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from dm_env import specs
from gymnasium import spaces

from swarmnav.controllers.policy_interface import FLAT_ORDER, flatten_observation
from swarmnav.models.errors import ConfigError
from swarmnav.models.seeds import Seeds
from swarmnav.env.worlds import draw_rng, merged_layout, scenario_source
from swarmnav.env.task import EnvOptions, NavigationTask, make_environment

ENV_ID = "swarmnav/Navigate-v0"
RESET_OPTIONS = ("scenario", "planner_seed", "world_seed")


def _box(spec: specs.Array) -> spaces.Box:
    if isinstance(spec, specs.BoundedArray):
        low, high = np.broadcast_to(spec.minimum, spec.shape), np.broadcast_to(spec.maximum, spec.shape)
    else:
        low, high = np.full(spec.shape, -np.inf), np.full(spec.shape, np.inf)
    return spaces.Box(low=low.astype(spec.dtype), high=high.astype(spec.dtype), shape=spec.shape, dtype=spec.dtype)


class NavigateEnv(gymnasium.Env):
    """One scenario's navigation task as a Gymnasium environment (see the module docstring).

    Args:
        scenario: a bundled scenario name, a path, or a Scenario.
        flatten: observations as one float32 vector in the documented flat order
            (:func:`controllers.policy_interface.flatten_observation`), the ``policy`` navigator's ``flatten``.
        scenarios: a new world per episode (:mod:`swarmnav.env.worlds`): a list of scenarios or a generator
            specification; ``scenario`` is then not used.
        render_mode: None or ``"rgb_array"``.
        width, height, camera: the rendered frames.
        **options: :class:`EnvOptions` fields (action, path_planner, reward, record_to, ...).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 50}

    def __init__(self, scenario: Any = "gwo-scenario-2", render_mode: str | None = None, width: int = 640,
                 height: int = 480, camera: str = "top", scenarios: Any = None, flatten: bool = False,
                 **options: Any):
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode: expected None or 'rgb_array', got {render_mode!r}")
        self.render_mode = render_mode
        self._size = (width, height, camera)
        self._options = EnvOptions(**options)
        self._renderer = None
        self._flatten = bool(flatten)
        self._seeded = False  # whether a reset had a seed: then reset() derives new seeds from np_random
        self._source, self._layout = None, None
        if scenarios is not None:
            self._source = scenario_source(scenarios)
            envelope = [make_environment(s, self._options) for s in self._source.envelope()]
            self._layout = self._source.widen(merged_layout([env.task.layout for env in envelope]))
            actions = {(env.action_spec().minimum.tobytes(), env.action_spec().maximum.tobytes()) for env in envelope}
            if len(actions) > 1:
                raise ConfigError("env.scenarios", "the scenarios' robots differ: the action space must not change")
            scenario = envelope[0].task.scenario
        self._build(scenario)

    def _build(self, scenario: Any) -> None:
        episode = self.task.episode if getattr(self, "dm_env", None) is not None else -1
        self.close()
        self.dm_env = make_environment(scenario, self._options, self._layout)
        self.task.episode = episode  # record_to's {episode} keeps counting across drawn worlds
        self.observation_space = spaces.Dict({key: _box(spec) for key, spec in self.dm_env.observation_spec().items()})
        layout = self.task.layout
        if self._flatten:
            low, high = layout.flat_bounds()
            self.observation_space = spaces.Box(low=low, high=high, dtype=low.dtype)
        self.metadata = {**self.metadata, "range_angles_rad": self.task.scene.range_angles_rad.tolist(),
                         "flat_order": [key for key in FLAT_ORDER if key in layout.bounds()]}
        self.action_space = _box(self.dm_env.action_spec())
        self.metadata = {**self.metadata, "render_fps": 1.0 / self.dm_env.control_timestep()}

    @property
    def task(self) -> NavigationTask:
        return self.dm_env.task

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        super().reset(seed=seed)
        options = dict(options or {})
        unknown = set(options) - set(RESET_OPTIONS)
        if unknown:
            raise ValueError(f"reset options: unknown {sorted(unknown)} (known: {', '.join(RESET_OPTIONS)})")
        if "scenario" in options:
            if self._source is not None:
                raise ConfigError("reset options.scenario", "the environment draws its scenarios (scenarios=)")
            self._build(options["scenario"])
        seeds = self.task.seeds
        if self._source is not None:  # a new world every episode, from the seed or np_random
            episode_seed = seed if seed is not None else int(self.np_random.integers(2**63))
            self._build(self._source.draw(draw_rng(episode_seed)))
            seeds = Seeds.derived(episode_seed)
        elif seed is not None:
            seeds = Seeds.derived(seed)
            self._seeded = True
        elif self._seeded:
            seeds = Seeds.derived(int(self.np_random.integers(2**63)))
        planner = options.get("planner_seed")
        world = options.get("world_seed")
        self.task.set_seeds(Seeds(seeds.planner if planner is None else int(planner),
                                  seeds.world if world is None else int(world)))
        timestep = self.dm_env.reset()
        return self._observation(timestep.observation), self.task.info()

    def _observation(self, observation: dict[str, np.ndarray]):
        return flatten_observation(observation) if self._flatten else observation

    def step(self, action):
        timestep = self.dm_env.step(action)  # the task checks it (ActionError) and reads it in float64
        last = timestep.last()
        terminated = bool(last and timestep.discount == 0.0)
        truncated = bool(last and timestep.discount == 1.0)
        return self._observation(timestep.observation), float(timestep.reward), terminated, truncated, self.task.info()

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        from swarmnav.video.render import SceneRenderer
        stepper = self.task.stepper
        if self._renderer is None:
            width, height, camera = self._size
            self._renderer = SceneRenderer(self.dm_env.physics.model.ptr, width, height, camera)
        planned = self.task.planned_path()
        return self._renderer.render(stepper.data, path_m=None if planned is None else planned.path.waypoints,
                                     trail_m=stepper.poses[:stepper.step_index + 1, :2])

    def close(self) -> None:
        if getattr(self, "dm_env", None) is not None:
            self.task.close_recording("interrupted")
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point=NavigateEnv)
