"""A navigator drives the episode stepper: ``swarmnav run``'s closed loop.

:class:`Simulation` is a scenario's compiled scene; :meth:`Simulation.run` hands
the navigator each observation of an :class:`~sim.stepper.EpisodeStepper` and the
stepper each of the navigator's commands (with its new paths, events and belief),
passed first through the run's safety layer (:mod:`controllers.safety_layer`: the
evasion and the safety filter, after the navigator as Nav2's Collision Monitor is after
its controller), until the stepper reports an outcome.  The steps of a control period, and their
order, are the stepper's (:mod:`sim.stepper`); the Gymnasium / dm_env environment
drives the same stepper with a policy's actions, so the two cannot drift.
"""

from __future__ import annotations

import time
from typing import Any

import mujoco
import numpy as np

from swarmnav.controllers.goal import GoalChecker
from swarmnav.controllers.navigator import NavigationSetup, Navigator
from swarmnav.controllers.safety_layer import SafetyLayer
from swarmnav.models.scenario import Scenario
from swarmnav.sim.recording import ObstacleInfo, Recorder, RunContext
from swarmnav.sim.scene import CompiledScene, compile_scene
from swarmnav.sim.run_result import RunResult
from swarmnav.sim.stepper import (EpisodeStepper, goal_checker, obstacle_positions, reset_data,
                                  steps_per_control)
from swarmnav.sim.versions import software_versions


MAP_LOG_PERIOD_S = 1.0  # the sensed map on /map: once a simulated second (Nav2 publishes its global costmap at 1 Hz)


class Simulation:
    """A scenario's compiled scene with a fresh ``MjData`` per run."""

    def __init__(self, scenario: Scenario, scene: CompiledScene | None = None):
        self.scenario = scenario
        self.scene = scene or compile_scene(scenario)
        self.model = self.scene.model
        self.steps_per_control = steps_per_control(scenario, self.model)
        self.control_dt_s = self.steps_per_control * self.model.opt.timestep

    def obstacle_positions(self, times_s: np.ndarray) -> np.ndarray:
        """(T, M, 2) positions of the moving obstacles at the given times."""
        return obstacle_positions(self.scenario, self.scene, times_s)

    def reset(self, data: mujoco.MjData | None = None) -> mujoco.MjData:
        """New MjData (or ``data`` reset in place) with the robot at the start pose and obstacles at t = 0."""
        return reset_data(self.scenario, self.scene, data)

    def context(self, planner_name: str, planner_params: dict[str, Any], seed: int,
                navigator_name: str = "follow", navigator_params: dict[str, Any] | None = None) -> RunContext:
        model = self.model
        infos = []
        for ob in self.scene.obstacles:
            g = ob.geom_id
            size = model.geom_size[g]
            shape = "cylinder" if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CYLINDER else "box"
            data_pos = model.geom_pos[g] if ob.mocap_index < 0 else model.body_pos[model.geom_bodyid[g]]
            infos.append(ObstacleInfo(entity_id=ob.name, shape=shape,
                                      size_m=tuple(float(s) for s in (size[:2] if shape == "cylinder" else size)),
                                      position_m=tuple(float(p) for p in data_pos), moving=ob.mocap_index >= 0))
        return RunContext(
            scenario_name=self.scenario.name, scenario_toml=self.scenario.source_text,
            planner_name=planner_name, planner_params=dict(planner_params), seed=seed, mjcf_xml=self.scene.xml,
            navigator_name=navigator_name, navigator_params=dict(navigator_params or {}),
            world_seed=self.scenario.world_seed, clearance_m=self.scenario.clearance_m,
            map_knowledge=self.scenario.map_knowledge if self.scenario.knowledge_overridden else None,
            pose_source=self.scenario.pose_source if self.scenario.knowledge_overridden else None,
            control_dt_s=self.control_dt_s, physics_dt_s=float(model.opt.timestep),
            sensor_angles_rad=self.scene.range_angles_rad.copy(), sensor_range_m=self.scene.range_cutoff_m,
            sensor_offset_m=self.scene.range_offset_m, sensor_height_m=self.scene.range_height_m,
            obstacles=tuple(infos), versions=software_versions(),
            arena_size_m=(self.scenario.arena_width_m, self.scenario.arena_height_m))

    def goal_checker(self) -> GoalChecker:
        return goal_checker(self.scenario)

    def stepper(self, **options: Any) -> EpisodeStepper:
        """An :class:`~sim.stepper.EpisodeStepper` on this scene (``options``: its keyword arguments)."""
        return EpisodeStepper(self.scenario, self.scene, **options)

    def run(self, navigator: Navigator, setup: NavigationSetup, recorder: Recorder | None = None,
            context: RunContext | None = None, time_limit_s: float | None = None,
            stop_on_collision: bool | None = None, safety: SafetyLayer | None = None) -> RunResult:
        """Drive the robot with ``navigator`` until goal, timeout or (optionally) first collision.

        ``safety``: the run's safety layer, applied to every answer of the navigator (None: none).
        The navigator's wall time (``navigator_wall_s``) includes the layer's.

        The recorder, when given, is finished even if the loop raises, so what it
        wrote stays readable.  The result's SPL uses the stepper's L*.
        """
        stepper = None
        navigator_wall_s = 0.0
        try:
            navigator.reset(setup)
            layer = safety if safety is not None and safety.on else None
            if layer is not None:
                layer.reset(setup)
            stepper = self.stepper(time_limit_s=time_limit_s, stop_on_collision=stop_on_collision,
                                   recorder=recorder, context=context, path_m=setup.path.waypoints,
                                   sense_obstacles=navigator.uses_detections or layer is not None)
            observation = stepper.reset()
            clock = time.perf_counter
            world_map = setup.world_map  # with the map unknown: fed every scan, before the navigator reads it
            next_map_log_s = 0.0
            while not stepper.outcome:
                if world_map is not None:
                    world_map.observe(observation)
                    if recorder is not None and observation.time_s >= next_map_log_s - 1e-9:
                        next_map_log_s = observation.time_s + MAP_LOG_PERIOD_S
                        recorder.occupancy(observation.time_s, world_map.grid)
                nav0 = clock()
                decision = navigator.step(observation)
                if layer is not None:
                    decision = layer.after(observation, decision)
                navigator_wall_s += clock() - nav0
                observation = stepper.step(decision.command, decision.belief, decision.new_path, decision.events)
        except BaseException as exc:
            stopped = isinstance(exc, (KeyboardInterrupt, SystemExit))
            if stepper is not None:
                stepper.close("interrupted" if stopped else "error")
            elif recorder is not None:
                recorder.finish({"outcome": "interrupted" if stopped else "error", "sim_time_s": 0.0})
            raise
        result = stepper.result
        result.navigator_wall_s = navigator_wall_s
        result.replan_wall_s = float(navigator.replan_wall_s)
        return result
