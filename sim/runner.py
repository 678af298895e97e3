"""The closed loop at the control rate, in small named steps.

Only ``sim/`` touches MuJoCo.  Each control step of :meth:`Simulation.run`:

1. :meth:`StepLoop.move_obstacles`: the mocap obstacles to their positions at time t;
2. :meth:`StepLoop.observe`: pose, twist and rangefinders as an
   :class:`~controllers.navigator.Observation` (plain arrays, ``inf`` = nothing
   in range), and the clearance to the nearest obstacle (``mj_geomDistance``);
3. stop on goal, timeout or (optionally) first collision;
4. the navigator turns the observation into a wheel command (and may replace the path);
5. :meth:`StepLoop.apply` writes ``data.ctrl``; :meth:`StepLoop.advance` runs
   ``mj_step`` k times, checking after every physics step for a collision (a
   MuJoCo contact between a robot geom and an obstacle geom);
6. the recorders get the step.

The clearance is sampled at the control rate; collisions at the physics rate.
The same steps serve the Gymnasium / dm_env environment, so the two cannot drift.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np

from swarmnav.controllers.controller import ControlCommand, Twist
from swarmnav.controllers.goal import GoalChecker
from swarmnav.controllers.navigator import Belief, NavigationSetup, Navigator, Observation
from swarmnav.models.scenario import Scenario
from swarmnav.models.world import Pose2D
from swarmnav.sim.clearance import CLEARANCE_HORIZON_M, ClearanceProbe
from swarmnav.sim.contact import ContactMonitor
from swarmnav.sim.detector import ObstacleSensing
from swarmnav.sim.recording import ObstacleInfo, Recorder, RunContext, StepFrame
from swarmnav.sim.scene import CompiledScene, compile_scene
from swarmnav.sim.sensing import base_twist, ranges_from_sensors, yaw_from_quaternion
from swarmnav.sim.versions import software_versions


@dataclass
class RunResult:
    """What happened in one closed-loop run (arrays have one row per control step)."""

    reached: bool
    outcome: str  # "goal_reached" | "timeout" | "collision"
    collisions: int
    first_collision_s: float | None
    sim_time_s: float
    wall_time_s: float
    path_length_m: float
    min_clearance_m: float
    steps: int
    times_s: np.ndarray = field(repr=False)
    poses: np.ndarray = field(repr=False)  # (T, 3) x, y, heading
    wheel_command_rad_s: np.ndarray = field(repr=False)  # (T, 2)
    collision_points_m: np.ndarray = field(repr=False)  # (C, 2) base position at each collision start
    # Navigation metrics (seed 004 dynamic runs; see summary()).
    time_in_danger_s: float = 0.0
    stopped_s: float = 0.0
    replans: int = 0
    replan_wall_s: float = 0.0
    safety_triggers: int = 0
    reference_length_m: float | None = None  # L*: the shortest path among the static obstacles
    navigator_wall_s: float = 0.0  # wall time spent in navigator.step (not in summary(): benchmarks read it)

    @property
    def success(self) -> bool:
        """Reached the goal before the time limit with no collision."""
        return self.reached and self.collisions == 0

    @property
    def spl(self) -> float | None:
        """Success weighted by path length (Anderson et al. 2018, Eq. 1 for one episode): S L* / max(L, L*)."""
        if self.reference_length_m is None:
            return None
        if not self.success:
            return 0.0
        return self.reference_length_m / max(self.path_length_m, self.reference_length_m)

    def summary(self) -> dict[str, Any]:
        return {"reached": self.reached, "outcome": self.outcome, "collisions": self.collisions,
                "first_collision_s": self.first_collision_s, "sim_time_s": round(self.sim_time_s, 6),
                "wall_time_s": round(self.wall_time_s, 4), "path_length_m": self.path_length_m,
                # None when the scene has no obstacle (JSON has no infinity).
                "min_clearance_m": self.min_clearance_m if math.isfinite(self.min_clearance_m) else None,
                "success": self.success, "time_to_goal_s": round(self.sim_time_s, 6) if self.reached else None,
                "spl": self.spl, "time_in_danger_s": round(self.time_in_danger_s, 6), "replans": self.replans,
                "replan_wall_s": round(self.replan_wall_s, 4), "stopped_s": round(self.stopped_s, 6),
                "safety_triggers": self.safety_triggers}

    def log_summary(self) -> dict[str, Any]:
        """:meth:`summary` without wall-clock figures other than ``wall_*`` (which the log writer drops)."""
        return {k: v for k, v in self.summary().items() if k != "replan_wall_s"}


class Simulation:
    """A scenario's compiled scene with a fresh ``MjData`` per run."""

    def __init__(self, scenario: Scenario, scene: CompiledScene | None = None):
        self.scenario = scenario
        self.scene = scene or compile_scene(scenario)
        self.model = self.scene.model
        self.steps_per_control = int(round(1.0 / (scenario.sim.control_hz * self.model.opt.timestep)))
        self.control_dt_s = self.steps_per_control * self.model.opt.timestep
        self._moving = [ob for ob in self.scene.obstacles if ob.mocap_index >= 0]
        self._mocap_index = np.array([ob.mocap_index for ob in self._moving], dtype=np.int64)

    def obstacle_positions(self, times_s: np.ndarray) -> np.ndarray:
        """(T, M, 2) positions of the moving obstacles at the given times."""
        if not self._moving:
            return np.zeros((len(times_s), 0, 2))
        return np.stack([self.scenario.obstacles[ob.scenario_index].trajectory().positions_at(times_s)
                         for ob in self._moving], axis=1)

    def reset(self, data: mujoco.MjData | None = None) -> mujoco.MjData:
        """New MjData (or ``data`` reset in place) with the robot at the start pose and obstacles at t = 0."""
        if data is None:
            data = mujoco.MjData(self.model)
        else:
            mujoco.mj_resetData(self.model, data)
        start = self.scenario.start
        adr = self.scene.free_qpos_adr
        data.qpos[adr:adr + 3] = [start.x_m, start.y_m, 0.0]
        data.qpos[adr + 3:adr + 7] = [math.cos(start.heading_rad / 2), 0.0, 0.0, math.sin(start.heading_rad / 2)]
        if self._moving:
            data.mocap_pos[self._mocap_index, :2] = self.obstacle_positions(np.zeros(1))[0]
        mujoco.mj_forward(self.model, data)
        return data

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
            control_dt_s=self.control_dt_s, physics_dt_s=float(model.opt.timestep),
            sensor_angles_rad=self.scene.range_angles_rad.copy(), sensor_range_m=self.scene.range_cutoff_m,
            sensor_offset_m=self.scene.range_offset_m, sensor_height_m=self.scene.range_height_m,
            obstacles=tuple(infos), versions=software_versions(),
            arena_size_m=(self.scenario.arena_width_m, self.scenario.arena_height_m))

    def goal_checker(self) -> GoalChecker:
        goal = self.scenario.goal
        return GoalChecker(goal.x_m, goal.y_m, self.scenario.goal_tolerance_m)

    def run(self, navigator: Navigator, setup: NavigationSetup, recorder: Recorder | None = None,
            context: RunContext | None = None, time_limit_s: float | None = None,
            stop_on_collision: bool | None = None, reference_length_m: float | None = None) -> RunResult:
        """Drive the robot with ``navigator`` until goal, timeout or (optionally) first collision.

        The recorder, when given, is finished even if the loop raises, so what it
        wrote stays readable.  ``reference_length_m`` (L*) gives the result its SPL.
        """
        scenario = self.scenario
        stop_on_collision = scenario.sim.stop_on_collision if stop_on_collision is None else stop_on_collision
        loop = StepLoop(self, recorder, scenario.time_limit_s if time_limit_s is None else time_limit_s)
        goal = setup.goal
        outcome = ""
        navigator_wall_s = 0.0
        wall0 = time.perf_counter()
        try:
            navigator.reset(setup)
            loop.sense_obstacles = getattr(navigator, "uses_detections", True)
            if recorder is not None:
                recorder.start(context)
                recorder.path(0.0, setup.path.waypoints)
            loop.check_initial_contacts()
            while True:
                loop.move_obstacles()
                observation = loop.observe()
                outcome = loop.outcome(observation.pose, goal, stop_on_collision)
                if outcome:
                    loop.stop(observation, outcome)
                    break
                nav0 = time.perf_counter()
                decision = navigator.step(observation)
                navigator_wall_s += time.perf_counter() - nav0
                loop.count_events(decision.events)
                if recorder is not None:
                    if decision.new_path is not None:
                        recorder.path(observation.time_s, decision.new_path.waypoints)
                    for kind, details in decision.events:
                        recorder.event(observation.time_s, kind, details)
                loop.apply(observation, decision.command, decision.belief)
                loop.advance()
            result = loop.result(outcome, time.perf_counter() - wall0)
            result.reference_length_m = reference_length_m
            result.navigator_wall_s = navigator_wall_s
            result.replan_wall_s = float(getattr(navigator, "replan_wall_s", 0.0))
        except BaseException as exc:
            if recorder is not None:
                stopped = isinstance(exc, (KeyboardInterrupt, SystemExit))
                recorder.finish({"outcome": "interrupted" if stopped else "error", "sim_time_s": loop.time_s})
            raise
        if recorder is not None:
            recorder.finish(result.log_summary())
        return result


class StepLoop:
    """One episode's state on a :class:`Simulation`, advanced one control step at a time.

    Arrays hold one row per control step; ``step`` counts control steps.  ``data``:
    an ``MjData`` of the simulation's model to run in (the environment's physics
    owns one); by default a new one.
    """

    def __init__(self, simulation: Simulation, recorder: Recorder | None, time_limit_s: float,
                 data: mujoco.MjData | None = None):
        self.simulation = simulation
        self.scene = scene = simulation.scene
        self.model = simulation.model
        self.recorder = recorder
        self.data = simulation.reset(data)
        self.k = simulation.steps_per_control
        self.dt_s = simulation.control_dt_s
        self.physics_dt_s = float(self.model.opt.timestep)
        self.n_max = int(math.floor(time_limit_s / self.dt_s + 1e-9))
        self.times_s = np.arange(self.n_max + 1) * self.dt_s
        self.obstacle_track_m = simulation.obstacle_positions(self.times_s)  # (T, M, 2)
        self.mocap_index = simulation._mocap_index
        self.monitor = ContactMonitor(self.model, scene.is_robot_geom, scene.is_obstacle_geom, recorder,
                                      release_s=self.dt_s)
        # Contacts that are not collisions (wheels and casters on the floor), counted at the
        # start: a substep with no more contacts than these and no ongoing collision is skipped.
        self.resting_contacts = self.data.ncon - self.monitor.robot_obstacle_contacts(self.data)
        self.clearance = ClearanceProbe(scene, self.data)
        # Farther than this from every obstacle, no contact can begin within one control period:
        # twice the distance the base covers at full wheel speed, plus a centimetre.
        top_speed_m_s = scene.drive.max_wheel_speed_rad_s * scene.drive.wheel_radius_m
        self.contact_free_gap_m = 2.0 * top_speed_m_s * self.dt_s + 0.01
        self.qadr = qadr = scene.free_qpos_adr
        # Views into data, made once: the base's position and quaternion, its velocity, the rangefinders.
        self._base_qpos = self.data.qpos[qadr:qadr + 7]
        self._base_qvel = self.data.qvel[scene.free_qvel_adr:scene.free_qvel_adr + 6]
        self._wheel_qvel_adr = np.array(scene.wheel_qvel_adr)
        adr = np.asarray(scene.range_sensor_adr)
        contiguous = len(adr) > 0 and np.array_equal(adr, np.arange(adr[0], adr[0] + len(adr)))
        self._range_raw = self.data.sensordata[adr[0]:adr[0] + len(adr)] if contiguous else None
        # How far the moving obstacles can have moved: obstacle_shift_m[j] - obstacle_shift_m[i]
        # bounds every obstacle's displacement between control steps i and j (for clearance skips).
        track = self.obstacle_track_m
        hops = np.hypot(*np.moveaxis(np.diff(track, axis=0), 2, 0)).max(axis=1) if track.shape[1] else \
            np.zeros(max(len(track) - 1, 0))
        self.obstacle_shift_m = np.concatenate([[0.0], np.cumsum(hops)]).tolist()
        self._shift_at_measure_m = 0.0
        self._observed_step = -1
        self.poses = np.zeros((self.n_max + 1, 3))
        self.wheel_cmd = np.zeros((self.n_max + 1, 2))
        self.min_clearance_m = math.inf
        self._clearance_m: float | None = math.inf  # at the last observation; None: not measured (see clearance_m)
        self._contact_free = True  # the last observation's clearance rules out a contact (none yet: inf, as ever)
        self.length_m = 0.0
        self.waypoint_index = 0  # of the last command, recorded with the final step
        self.in_danger = False
        self.step = 0
        radii = [simulation.scenario.obstacles[ob.scenario_index].radius_m for ob in simulation._moving]
        # Whether observations carry detections: a navigator that never reads them
        # (``uses_detections = False``) spares the sensing model's work.
        self.sense_obstacles = True
        self.sensing = ObstacleSensing(simulation.scenario, self.obstacle_track_m, np.array(radii), self.dt_s,
                                       scene.range_angles_rad, scene.range_offset_m)
        self.danger_m = simulation.scenario.sim.danger_m
        self.danger_steps = self.stopped_steps = self.replans = self.safety_triggers = 0

    @property
    def time_s(self) -> float:
        return self.step * self.dt_s

    def check_initial_contacts(self) -> None:
        qpos = self.data.qpos
        if self.data.ncon > self.resting_contacts:
            self.monitor.update(self.data, 0.0, float(qpos[self.qadr]), float(qpos[self.qadr + 1]))

    def move_obstacles(self) -> None:
        if len(self.mocap_index):
            self.data.mocap_pos[self.mocap_index, :2] = self.obstacle_track_m[self.step]

    @property
    def clearance_m(self) -> float:
        """The clearance at the last observation (measured on demand if :meth:`observe` could skip it)."""
        if self._clearance_m is None:
            if self._observed_step != self.step:
                raise RuntimeError("the clearance of an observation is only available until the next advance()")
            x, y = self.poses[self.step, :2].tolist()
            self._clearance_m = self.clearance.measure(self.data, x, y)
            self._shift_at_measure_m = self.obstacle_shift_m[max(self.step - 1, 0)]
        return self._clearance_m

    def clearance_bound_m(self) -> float:
        """A value the clearance now certainly exceeds (:meth:`ClearanceProbe.lower_bound_m`)."""
        return self.clearance.lower_bound_m(self.obstacle_shift_m[self.step] - self._shift_at_measure_m)

    def observe(self) -> Observation:
        """Pose, twist and ranges now; also tracks the driven length and the clearance.

        The clearance is measured only when it could matter: when
        :meth:`ClearanceProbe.lower_bound_m` shows it above the minimum so far, the
        danger distance and the contact-free gap, none of the minimum, the time in
        danger or the batching of :meth:`advance` depends on its value (and beyond
        the probe's horizon the value is the horizon).
        """
        data, scene, step = self.data, self.scene, self.step
        x, y, _, w, qx, qy, qz = self._base_qpos.tolist()
        heading = yaw_from_quaternion(w, qx, qy, qz)
        if step:
            last_x, last_y, _ = self.poses[step - 1].tolist()
            self.length_m += math.hypot(x - last_x, y - last_y)
        self.poses[step] = (x, y, heading)
        self._observed_step = step
        bound_m = self.clearance_bound_m()
        if bound_m > CLEARANCE_HORIZON_M:
            gap: float | None = CLEARANCE_HORIZON_M  # what measure() returns beyond its horizon
        elif bound_m > max(self.min_clearance_m, self.danger_m, self.contact_free_gap_m):
            gap = None  # not a new minimum, not in danger, no contact possible: the value is not needed
        else:
            gap = self.clearance.measure(data, x, y)
            # The obstacles the probe saw are where the last mj_step put them (the previous step's).
            self._shift_at_measure_m = self.obstacle_shift_m[max(step - 1, 0)]
        self._clearance_m = gap
        if gap is None:
            self.in_danger = False
            self._contact_free = True
        else:
            if gap < self.min_clearance_m:
                self.min_clearance_m = gap
            self.in_danger = gap < self.danger_m
            self._contact_free = gap > self.contact_free_gap_m
        v, omega = base_twist(self._base_qvel.tolist(), 0, heading)
        pose = Pose2D(x, y, heading)
        raw = self._range_raw if self._range_raw is not None else data.sensordata[scene.range_sensor_adr]
        ranges = ranges_from_sensors(raw, scene.range_cutoff_m)
        time_s = step * self.dt_s
        return Observation(time_s=time_s, pose=pose, twist=Twist(v, omega), ranges_m=ranges,
                           range_angles_rad=scene.range_angles_rad, range_offset_m=scene.range_offset_m,
                           range_cutoff_m=scene.range_cutoff_m,
                           detections=self.sensing.sense(step, time_s, pose, ranges) if self.sense_obstacles else ())

    def count_events(self, events) -> None:
        """Count the navigator's replans and safety-filter triggers."""
        for kind, _ in events:
            if kind == "replan":
                self.replans += 1
            elif kind == "safety_trigger":
                self.safety_triggers += 1

    def outcome(self, pose: Pose2D, goal: GoalChecker, stop_on_collision: bool) -> str:
        """"goal_reached", "collision" (when stopping on one), "timeout", or "" to go on."""
        if goal.reached(pose):
            return "goal_reached"
        if stop_on_collision and self.monitor.collisions:
            return "collision"
        if self.step >= self.n_max:
            return "timeout"
        return ""

    def apply(self, observation: Observation, command: ControlCommand, belief: Belief | None = None) -> None:
        """Write the wheel command into ``data.ctrl`` and hand the step (and the navigator's belief) to the recorder."""
        left, right = command.wheels.left_rad_s, command.wheels.right_rad_s
        self.data.ctrl[0] = left
        self.data.ctrl[1] = right
        self.wheel_cmd[self.step] = (left, right)
        self.waypoint_index = command.waypoint_index
        self.danger_steps += self.in_danger
        self.stopped_steps += left == 0.0 and right == 0.0
        if self.recorder is not None:
            self.recorder.step(self._frame(observation, command, belief))

    def advance(self) -> None:
        """``mj_step`` k times, checking for a collision after every physics step.

        When the clearance measured at the start of the step exceeds what the
        robot can travel in one control period (obstacles move only between
        control steps), no contact can begin, and the k steps run in one call.
        """
        model, data, monitor, qpos, qadr = self.model, self.data, self.monitor, self.data.qpos, self.qadr
        if self._contact_free and not monitor.in_contact:
            mujoco.mj_step(model, data, self.k)
            self.step += 1
            return
        base = self.step * self.k
        for substep in range(self.k):
            mujoco.mj_step(model, data)
            if data.ncon > self.resting_contacts or monitor.in_contact:
                monitor.update(data, (base + substep) * self.physics_dt_s, float(qpos[qadr]), float(qpos[qadr + 1]))
        self.step += 1

    def stop(self, observation: Observation, outcome: str) -> None:
        """End the run: zero the wheels, record the last step and the outcome."""
        self.data.ctrl[:] = 0.0
        if self.recorder is not None:
            self.recorder.step(self._frame(observation, ControlCommand.stop(self.waypoint_index)))
            pose = observation.pose
            self.recorder.event(observation.time_s, outcome if outcome != "collision" else "stopped_on_collision",
                                {"x_m": pose.x_m, "y_m": pose.y_m})

    def result(self, outcome: str, wall_time_s: float) -> RunResult:
        step, monitor = self.step, self.monitor
        return RunResult(
            reached=outcome == "goal_reached", outcome=outcome, collisions=monitor.collisions,
            first_collision_s=monitor.first_collision_s, sim_time_s=step * self.dt_s, wall_time_s=wall_time_s,
            path_length_m=self.length_m, min_clearance_m=float(self.min_clearance_m), steps=step,
            times_s=self.times_s[:step + 1].copy(), poses=self.poses[:step + 1].copy(),
            wheel_command_rad_s=self.wheel_cmd[:step + 1].copy(),
            collision_points_m=np.array(monitor.points, dtype=float).reshape(-1, 2),
            time_in_danger_s=self.danger_steps * self.dt_s, stopped_s=self.stopped_steps * self.dt_s,
            replans=self.replans, safety_triggers=self.safety_triggers)

    def _frame(self, observation: Observation, command: ControlCommand, belief: Belief | None = None) -> StepFrame:
        base_qpos = self._base_qpos
        return StepFrame(
            time_s=observation.time_s, position_m=base_qpos[:3].copy(), quaternion_wxyz=base_qpos[3:].copy(),
            heading_rad=observation.pose.heading_rad, range_m=observation.ranges_m,
            wheel_command_rad_s=np.array([command.wheels.left_rad_s, command.wheels.right_rad_s]),
            wheel_measured_rad_s=self.data.qvel[self._wheel_qvel_adr],
            linear_m_s=command.linear_m_s, angular_rad_s=command.angular_rad_s,
            waypoint_index=command.waypoint_index, moving_obstacles_m=self.obstacle_track_m[self.step].copy(),
            belief=belief)
