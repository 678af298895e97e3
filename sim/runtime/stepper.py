"""One episode, one control period at a time: the only place that orders the steps of the closed loop.

:class:`EpisodeStepper` owns an episode on a compiled scene: the ``MjData``, the
obstacle motion, sensing, the contact check, the recorders' ``start`` and
``finish``, the reference length L* and the metrics.  Whoever chooses the wheel
commands drives it: a navigator (:meth:`sim.simulation.Simulation.run`) or a policy
(the dm_control task of :mod:`swarmnav.env.task`)::

    observation = stepper.reset()
    while not stepper.outcome:
        observation = stepper.step(command_for(observation))
    result = stepper.result

:meth:`~EpisodeStepper.reset` puts the robot at the start and the obstacles at
t = 0, starts the recorder, counts contacts present at the start and senses.
Each :meth:`~EpisodeStepper.step` then

1. records the driver's new path and events, and the step (pose, ranges, command, belief);
2. writes ``data.ctrl`` and runs ``mj_step`` k times, checking for a collision (a MuJoCo
   contact between a robot geom and an obstacle geom) after every physics step, or all
   k in one call when the clearance rules out any contact within the period;
3. moves the mocap obstacles to their positions at the new time;
4. observes: pose, twist and rangefinders as an :class:`~controllers.navigator.Observation`
   (plain arrays, ``inf`` = nothing in range; detections only when asked for), the driven
   length and the clearance (``mj_geomDistance``, skipped when a bound shows it cannot matter);
5. stops on goal, timeout or (optionally) the first collision: the wheels are zeroed, the last
   step and the outcome recorded, the :class:`RunResult` built and the recorder finished.

The clearance is sampled at the control rate; collisions at the physics rate.
"""

from __future__ import annotations

import math
import time
from typing import Any

import mujoco
import numpy as np

from swarmnav.controllers.controller import ControlCommand, Twist
from swarmnav.controllers.goal import GoalChecker
from swarmnav.controllers.navigator import Belief, Observation
from swarmnav.models.scenario import Scenario
from swarmnav.models.world import Pose2D
from swarmnav.planners.problem import Path
from swarmnav.sim.clearance import CLEARANCE_HORIZON_M, ClearanceProbe
from swarmnav.sim.contact import ContactMonitor
from swarmnav.sim.control_period import control_periods, steps_per_control
from swarmnav.sim.crowd_stepping import ReactiveCrowd, RolledCrowd, crowd_metrics, human_columns
from swarmnav.sim.detector import ObstacleSensing
from swarmnav.sim.laser import LaserCaster
from swarmnav.controllers.odometry import WheelOdometry
from swarmnav.sim.recording import Recorder, RunContext, StepFrame
from swarmnav.sim.reference import reference_length_m as shortest_static_length_m
from swarmnav.sim.run_result import RunResult
from swarmnav.sim.scene import CompiledScene
from swarmnav.sim.sensing import base_twist, ranges_from_sensors, yaw_from_quaternion


def moving_obstacles(scene: CompiledScene) -> list:
    """The scene's mocap obstacles (:class:`~sim.scene.ObstacleGeom`), in scene order."""
    return [ob for ob in scene.obstacles if ob.mocap_index >= 0]


def obstacle_positions(scenario: Scenario, scene: CompiledScene, times_s: np.ndarray,
                       held: np.ndarray | None = None) -> np.ndarray:
    """(T, M, 2) positions of the moving obstacles at the given times; the columns ``held`` (indices into
    the moving obstacles) only at the first time, repeated (the stepper writes them as the episode goes)."""
    moving = moving_obstacles(scene)
    if not moving:
        return np.zeros((len(times_s), 0, 2))
    held_set = set() if held is None else set(np.asarray(held).tolist())
    first = np.asarray(times_s, dtype=float).reshape(-1)[:1]
    return np.stack([scenario.obstacles[ob.scenario_index].trajectory().positions_at(times_s) if col not in held_set
                     else np.repeat(scenario.obstacles[ob.scenario_index].trajectory().positions_at(first),
                                    len(times_s), axis=0)
                     for col, ob in enumerate(moving)], axis=1)


def reset_data(scenario: Scenario, scene: CompiledScene, data: mujoco.MjData | None = None) -> mujoco.MjData:
    """New MjData (or ``data`` reset in place) with the robot at the start pose and obstacles at t = 0."""
    model = scene.model
    if data is None:
        data = mujoco.MjData(model)
    else:
        mujoco.mj_resetData(model, data)
    start = scenario.start
    adr = scene.free_qpos_adr
    data.qpos[adr:adr + 3] = [start.x_m, start.y_m, 0.0]
    data.qpos[adr + 3:adr + 7] = [math.cos(start.heading_rad / 2), 0.0, 0.0, math.sin(start.heading_rad / 2)]
    moving = moving_obstacles(scene)
    if moving:
        index = np.array([ob.mocap_index for ob in moving], dtype=np.int64)
        data.mocap_pos[index, :2] = obstacle_positions(scenario, scene, np.zeros(1))[0]
    mujoco.mj_forward(model, data)
    return data


def goal_checker(scenario: Scenario) -> GoalChecker:
    goal = scenario.goal
    return GoalChecker(goal.x_m, goal.y_m, scenario.goal_tolerance_m)


class EpisodeStepper:
    """One episode on a compiled scene of ``scenario``; see the module docstring.

    Args:
        time_limit_s, stop_on_collision: None = the scenario's; a limit of whole control periods only
            (:func:`sim.control_period.control_periods`: ``ConfigError`` otherwise).
        recorder: gets ``start(context)`` at :meth:`reset`, every step, and ``finish`` once
            (:meth:`close` finishes it early, e.g. after an exception).
        path_m: the path planned at t = 0, recorded at time 0 (None: no path).
        sense_obstacles: whether observations carry detections (the sensing model's work is
            spared for a driver that never reads them).
        data: an ``MjData`` of ``scene.model`` to run in (the environment's physics owns one);
            by default one made with the stepper (every :meth:`reset` resets it in place).

    After :meth:`reset`: ``observation`` (the last one), ``outcome`` ("" while running),
    ``result`` (once over), ``step_index``, ``poses``, ``wheel_cmd``, ``obstacle_track_m``
    and ``clearance_m``.
    """

    def __init__(self, scenario: Scenario, scene: CompiledScene, *, time_limit_s: float | None = None,
                 stop_on_collision: bool | None = None, recorder: Recorder | None = None,
                 context: RunContext | None = None, path_m: np.ndarray | None = None, sense_obstacles: bool = True,
                 data: mujoco.MjData | None = None):
        self.scenario = scenario
        self.scene = scene
        self.model = model = scene.model
        self.recorder = recorder
        self.context = context
        self.path_m = path_m
        # With the map unknown and the rays as the sensing (Nav2's obstacle layer), every hit goes to the
        # sensed map (controllers.world_map), moving obstacles' too: the ray tracker, which tells unknown
        # hits from the known map's, has no map to tell them from, and makes no detections.
        self.sense_obstacles = bool(sense_obstacles) and not (scenario.map_knowledge == "unknown"
                                                              and scenario.sensor_model == "rangefinder")
        # L* of the SPL: the shortest path among the static obstacles (sim.reference).
        self.reference_length_m = shortest_static_length_m(scenario)
        self.stop_on_collision = scenario.sim.stop_on_collision if stop_on_collision is None else stop_on_collision
        self.k = steps_per_control(scenario, model)
        self.physics_dt_s = float(model.opt.timestep)
        self.dt_s = self.k * self.physics_dt_s
        # Whole control periods only (sim.control_period): the file's limit, or the override's.
        self.n_max = control_periods(scenario.time_limit_s, self.dt_s, "time_limit_s", scenario.source_path) \
            if time_limit_s is None else control_periods(time_limit_s, self.dt_s, "time limit (override)")
        self.times_s = np.arange(self.n_max + 1) * self.dt_s
        self.goal = goal_checker(scenario)
        # The robot has left the arena when its centre is beyond an edge by more than its radius (its body
        # wholly past that edge): the run ends there, outcome "left_arena" (never a success).
        arena, margin_m = scenario.bounds, scenario.robot_radius_m
        self.arena_limits_m = (arena.x_min_m - margin_m, arena.y_min_m - margin_m,
                               arena.x_max_m + margin_m, arena.y_max_m + margin_m)
        # A path (a given one: planners keep inside the arena) with a waypoint outside the arena: reaching the
        # goal along it is "left_arena" too.
        self.path_leaves_arena = path_m is not None and not bool(np.all(
            (path_m[:, 0] >= arena.x_min_m - 1e-6) & (path_m[:, 0] <= arena.x_max_m + 1e-6)
            & (path_m[:, 1] >= arena.y_min_m - 1e-6) & (path_m[:, 1] <= arena.y_max_m + 1e-6)))
        moving = moving_obstacles(scene)
        self.mocap_index = np.array([ob.mocap_index for ob in moving], dtype=np.int64)
        self._moves = bool(moving)
        self._crowd = ReactiveCrowd.of(scenario, moving, self.dt_s) if moving else None  # agents that see the robot
        # Agents blind to it, rolled out as the episode goes (RolledCrowd), when they can be.
        self._rolled = RolledCrowd.of(scenario, moving, self.dt_s, self.n_max) \
            if moving and self._crowd is None else None
        # (T, M, 2). Agents that see the robot are written step by step (ReactiveCrowd.advance): their rollout
        # without a robot is not made when nothing reads it (ReactiveCrowd.lazy; it then holds their start);
        # nor, beyond the steps run, the rollout of blind ones (RolledCrowd.extend writes it).
        held = self._crowd.columns if self._crowd is not None and self._crowd.lazy else \
            self._rolled.columns if self._rolled is not None else None
        self.obstacle_track_m = obstacle_positions(scenario, scene, self.times_s, held)
        self._radii_m = np.array([scenario.obstacles[ob.scenario_index].radius_m for ob in moving])
        self._humans = human_columns(scenario, moving)  # agents: the crowd metrics of the result
        # How far the moving obstacles can have moved: obstacle_shift_m[j] - obstacle_shift_m[i]
        # bounds every obstacle's displacement between control steps i and j (for clearance skips).
        track = self.obstacle_track_m
        hops = np.hypot(*np.moveaxis(np.diff(track, axis=0), 2, 0)).max(axis=1) if track.shape[1] else \
            np.zeros(max(len(track) - 1, 0))
        hops = hops if self._crowd is None else np.maximum(hops, self._crowd.max_hop_m())  # bounded by top speed
        self._other_hops_m = hops  # with a RolledCrowd: the other obstacles' (it extends obstacle_shift_m)
        self.obstacle_shift_m = np.concatenate([[0.0], np.cumsum(hops)]).tolist() if self._rolled is None else [0.0]
        # Farther than this from every obstacle, no contact can begin within one control period:
        # twice the distance the base covers at full wheel speed, plus a centimetre.
        top_speed_m_s = scene.drive.max_wheel_speed_rad_s * scene.drive.wheel_radius_m
        self.contact_free_gap_m = 2.0 * top_speed_m_s * self.dt_s + 0.01
        self.danger_m = scenario.sim.danger_m
        self._unneeded_above_m = max(self.danger_m, self.contact_free_gap_m)  # see _observe
        self.qadr = scene.free_qpos_adr
        self._wheel_qvel_adr = np.array(scene.wheel_qvel_adr)
        # The caller's MjData, or one made once and reset in place (a new one costs ~100 steps' bookkeeping).
        self._data = data if data is not None else mujoco.MjData(model)
        self._unfinished = recorder is not None  # the recorder is owed its finish()
        self.outcome = ""
        self.result: RunResult | None = None
        self.observation: Observation | None = None
        self.step_index = 0

    # --- the episode ------------------------------------------------------------------------------
    def reset(self) -> Observation:
        """Start pose, obstacles at t = 0, recorder started, contacts at the start counted; the first observation.

        With a recorder, once per stepper (a recording is one episode); without, as often as wanted.
        """
        if self.recorder is not None and self.observation is not None:
            raise RuntimeError("a recorded episode is reset once: make another stepper for the next episode")
        self._wall0 = time.perf_counter()
        self._start_state()
        if self.recorder is not None:
            self.recorder.start(self.context)
            if self.path_m is not None:
                self.recorder.path(0.0, self.path_m)
        qpos = self.data.qpos
        if self.data.ncon > self.resting_contacts:
            self.monitor.update(self.data, 0.0, float(qpos[self.qadr]), float(qpos[self.qadr + 1]))
        return self._sense()

    def step(self, command: ControlCommand, belief: Belief | None = None, new_path: Path | None = None,
             events: tuple[tuple[str, dict[str, Any]], ...] = ()) -> Observation:
        """One control period with ``command`` (and what the driver decided with it: a new path, events,
        its belief, all recorded); the next observation."""
        if self.outcome or self.observation is None:
            raise RuntimeError(f"the episode is over ({self.outcome}): reset() starts another" if self.outcome
                               else "reset() first")
        recorder = self.recorder
        time_s = self.observation.time_s
        if recorder is not None:
            if new_path is not None:
                recorder.path(time_s, new_path.waypoints)
            for kind, details in events:
                recorder.event(time_s, kind, details)
        if events:
            for kind, _ in events:
                if kind == "replan":
                    self.replans += 1
                elif kind == "safety_trigger":
                    self.safety_triggers += 1
        wheels = command.wheels
        left, right = wheels.left_rad_s, wheels.right_rad_s
        ctrl = self._ctrl
        ctrl[0] = left
        ctrl[1] = right
        step = self.step_index
        self.wheel_cmd[step] = (left, right)
        self.waypoint_index = command.waypoint_index
        self.danger_steps += self.in_danger
        self.stopped_steps += left == 0.0 and right == 0.0
        if recorder is not None:
            recorder.step(self._frame(self.observation, command, belief))
        if self._contact_free and not self.monitor.in_contact:
            # No contact can begin within the period (see _advance): the k physics steps in one call.
            mujoco.mj_step(self.model, self.data, self.k)
            self.step_index = step + 1
        else:
            self._advance()
        return self._sense()

    def close(self, outcome: str) -> None:
        """Finish a recording still open (the episode interrupted, failed or abandoned before its end)."""
        if self._unfinished:
            self._unfinished = False
            self.recorder.finish({"outcome": outcome, "sim_time_s": self.time_s})

    @property
    def time_s(self) -> float:
        return self.step_index * self.dt_s

    @property
    def collisions(self) -> int:
        return self.monitor.collisions

    @property
    def clearance_m(self) -> float:
        """The clearance at the last observation (measured on demand if the observation could skip it)."""
        if self._clearance_m is None:
            if self._observed_step != self.step_index:
                raise RuntimeError("the clearance of an observation is only available until the next step()")
            x, y = self.poses[self.step_index, :2].tolist()
            self._clearance_m = self.clearance.measure(self.data, x, y)
            self._shift_at_measure_m = self.obstacle_shift_m[max(self.step_index - 1, 0)]
        return self._clearance_m

    def clearance_bound_m(self) -> float:
        """A value the clearance now certainly exceeds (:meth:`ClearanceProbe.lower_bound_m`)."""
        return self.clearance.lower_bound_m(self.obstacle_shift_m[self.step_index] - self._shift_at_measure_m)

    # --- the steps of a control period --------------------------------------------------------------
    def _start_state(self) -> None:
        scene = self.scene
        self.data = data = reset_data(self.scenario, scene, self._data)
        self.monitor = ContactMonitor(self.model, scene.is_robot_geom, scene.is_obstacle_geom, self.recorder,
                                      release_s=self.dt_s)
        # Contacts that are not collisions (wheels and casters on the floor), counted at the
        # start: a substep with no more contacts than these and no ongoing collision is skipped.
        self.resting_contacts = data.ncon - self.monitor.robot_obstacle_contacts(data)
        self.clearance = ClearanceProbe(scene, data)
        qadr = self.qadr
        # Views into data, made once: the base's position and quaternion, its velocity, the rangefinders.
        self._base_qpos = data.qpos[qadr:qadr + 7]
        self._base_qvel = data.qvel[scene.free_qvel_adr:scene.free_qvel_adr + 6]
        self._qpos, self._qvel, self._ctrl, self._mocap_pos = data.qpos, data.qvel, data.ctrl, data.mocap_pos
        adr = np.asarray(scene.range_sensor_adr)
        contiguous = len(adr) > 0 and np.array_equal(adr, np.arange(adr[0], adr[0] + len(adr)))
        self._range_raw = data.sensordata[adr[0]:adr[0] + len(adr)] if contiguous else None
        self._laser = LaserCaster(scene, data) if scene.laser_site_id >= 0 else None
        self._odometry = None
        if self.scenario.pose_source == "odometry":
            model = self.model
            self._wheel_qpos_adr = np.array([model.joint(f"{side}_wheel_hinge").qposadr[0] for side in ("left", "right")])
            self._odometry = WheelOdometry(self.scenario.start, scene.drive.wheel_radius_m, scene.drive.track_m,
                                           self.scenario.encoder_noise, self.scenario.world_seed)
            self.pose_error_m = self.max_pose_error_m = 0.0
        self.sensing = ObstacleSensing(self.scenario, self.obstacle_track_m, self._radii_m, self.dt_s,
                                       scene.range_angles_rad, scene.range_offset_m)
        if self._crowd is not None:
            self._crowd.reset(self.obstacle_track_m, self.sensing.velocity_m_s, self.times_s)
        if self._rolled is not None:
            self._rolled.attach(self.obstacle_track_m, self.sensing.velocity_m_s, self._other_hops_m,
                                self.obstacle_shift_m)
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
        self.step_index = 0
        self.danger_steps = self.stopped_steps = self.replans = self.safety_triggers = 0
        self.outcome = ""
        self._reached = False
        self.result = None

    def _advance(self) -> None:
        """``mj_step`` k times, checking for a collision after every physics step.

        When the clearance measured at the start of the step exceeds what the
        robot can travel in one control period (obstacles move only between
        control steps), no contact can begin, and :meth:`step` runs the k steps in one call.
        """
        model, data, monitor, qpos, qadr = self.model, self.data, self.monitor, self._qpos, self.qadr
        base = self.step_index * self.k
        for substep in range(self.k):
            mujoco.mj_step(model, data)
            if data.ncon > self.resting_contacts or monitor.in_contact:
                monitor.update(data, (base + substep) * self.physics_dt_s, float(qpos[qadr]), float(qpos[qadr + 1]))
        self.step_index += 1

    def _sense(self) -> Observation:
        """Obstacles to the new time, the observation, the outcome; the end of the episode when there is one."""
        step = self.step_index
        if self._moves:
            if self._crowd is not None:  # agents that see the robot: their step s -> s + 1 from its state now
                self._crowd.advance(step, self._base_qpos, self._base_qvel)
            elif self._rolled is not None:  # blind ones: their rollout to s + 1 (the velocity at s needs it)
                self._rolled.extend(step + 1)
            self._mocap_pos[self.mocap_index, :2] = self.obstacle_track_m[step]
        self.observation = observation = self._observe()
        pose = self._truth  # the goal, the arena and the result judge the true pose (odometry is the robot's)
        if self.goal.reached(pose):
            outcome = "left_arena" if self.path_leaves_arena else "goal_reached"
            self._reached = True
        elif self.stop_on_collision and self.monitor.collisions:
            outcome = "collision"
        elif not (self.arena_limits_m[0] <= pose.x_m <= self.arena_limits_m[2]
                  and self.arena_limits_m[1] <= pose.y_m <= self.arena_limits_m[3]):
            outcome = "left_arena"
        elif step >= self.n_max:
            outcome = "timeout"
        else:
            return observation
        self._stop(observation, outcome)
        return observation

    def _observe(self) -> Observation:
        """Pose, twist and ranges now; also tracks the driven length and the clearance.

        The clearance is measured only when it could matter: when
        :meth:`ClearanceProbe.lower_bound_m` shows it above the minimum so far, the
        danger distance and the contact-free gap, none of the minimum, the time in
        danger or the batching of :meth:`_advance` depends on its value (and beyond
        the probe's horizon the value is the horizon).
        """
        step = self.step_index
        x, y, _, w, qx, qy, qz = self._base_qpos.tolist()
        heading = yaw_from_quaternion(w, qx, qy, qz)
        if step:
            last_x, last_y = self._last_xy
            self.length_m += math.hypot(x - last_x, y - last_y)
        self._last_xy = (x, y)
        self.poses[step] = (x, y, heading)
        self._observed_step = step
        bound_m = self.clearance.lower_bound_m(self.obstacle_shift_m[step] - self._shift_at_measure_m)
        if bound_m > CLEARANCE_HORIZON_M:
            gap: float | None = CLEARANCE_HORIZON_M  # what measure() returns beyond its horizon
        elif bound_m > self.min_clearance_m and bound_m > self._unneeded_above_m:
            gap = None  # not a new minimum, not in danger, no contact possible: the value is not needed
        else:
            gap = self.clearance.measure(self.data, x, y)
            # The obstacles the probe saw are where the last mj_step put them (the previous step's).
            self._shift_at_measure_m = self.obstacle_shift_m[step - 1 if step else 0]
        self._clearance_m = gap
        if gap is None:
            self.in_danger = False
            self._contact_free = True
        else:
            if gap < self.min_clearance_m:
                self.min_clearance_m = gap
            self.in_danger = gap < self.danger_m
            self._contact_free = gap > self.contact_free_gap_m
        vx, vy, _, _, _, omega = self._base_qvel.tolist()
        pose = self._truth = Pose2D(x, y, heading)
        if self._odometry is not None:  # the robot sees its dead-reckoned pose (controllers.odometry)
            angles = self._qpos[self._wheel_qpos_adr]
            if step:  # each wheel's mean speed over the period: its encoder angle's change / dt
                left, right = ((angles - self._wheel_angles) / self.dt_s).tolist()
                self._odometry.update(left, right, self.dt_s)
            self._wheel_angles = angles.copy()
            pose = self._odometry.pose
            error = math.hypot(pose.x_m - x, pose.y_m - y)
            self.pose_error_m = error
            self.max_pose_error_m = max(self.max_pose_error_m, error)
        scene = self.scene
        if self._laser is not None:
            ranges = self._laser.scan(heading)
        else:
            raw = self._range_raw if self._range_raw is not None else self.data.sensordata[scene.range_sensor_adr]
            ranges = ranges_from_sensors(raw, scene.range_cutoff_m)
        time_s = step * self.dt_s
        linear_m_s, angular_rad_s = base_twist(vx, vy, omega, heading)
        return Observation(time_s, pose, Twist(linear_m_s, angular_rad_s), ranges, scene.range_angles_rad,
                           scene.range_offset_m,
                           self.sensing.sense(step, time_s, pose, ranges) if self.sense_obstacles else (),
                           scene.range_cutoff_m)

    def _stop(self, observation: Observation, outcome: str) -> None:
        """End the episode: zero the wheels, record the last step and the outcome, build the result."""
        self.outcome = outcome
        self.data.ctrl[:] = 0.0
        recorder = self.recorder
        if recorder is not None:
            recorder.step(self._frame(observation, ControlCommand.stop(self.waypoint_index)))
            pose = self._truth
            recorder.event(observation.time_s, outcome if outcome != "collision" else "stopped_on_collision",
                           {"x_m": pose.x_m, "y_m": pose.y_m})
        step, monitor = self.step_index, self.monitor
        self.result = RunResult(
            reached=self._reached, outcome=outcome, collisions=monitor.collisions,
            first_collision_s=monitor.first_collision_s, first_contact=monitor.first_contact,
            sim_time_s=step * self.dt_s,
            wall_time_s=time.perf_counter() - self._wall0,
            path_length_m=self.length_m, min_clearance_m=float(self.min_clearance_m), steps=step,
            times_s=self.times_s[:step + 1].copy(), poses=self.poses[:step + 1].copy(),
            wheel_command_rad_s=self.wheel_cmd[:step + 1].copy(),
            collision_points_m=np.array(monitor.points, dtype=float).reshape(-1, 2),
            time_in_danger_s=self.danger_steps * self.dt_s, stopped_s=self.stopped_steps * self.dt_s,
            replans=self.replans, safety_triggers=self.safety_triggers, reference_length_m=self.reference_length_m,
            crowd=crowd_metrics(self.poses[:step + 1], self.obstacle_track_m[:step + 1, self._humans],
                                self._radii_m[self._humans], self.scenario.robot_radius_m, self.length_m)
            if len(self._humans) else None,
            odometry={"pose_error_m": round(self.pose_error_m, 6), "max_pose_error_m": round(self.max_pose_error_m, 6)}
            if self._odometry is not None else None)
        if self._unfinished:
            self._unfinished = False
            recorder.finish(self.result.log_summary())

    def _frame(self, observation: Observation, command: ControlCommand, belief: Belief | None = None) -> StepFrame:
        base_qpos = self._base_qpos.copy()  # one fresh copy; position and quaternion are views of it
        wheels = command.wheels
        return StepFrame(observation.time_s, base_qpos[:3], base_qpos[3:], self._truth.heading_rad,
                         observation.ranges_m, np.array((wheels.left_rad_s, wheels.right_rad_s)),
                         self._qvel[self._wheel_qvel_adr], command.linear_m_s, command.angular_rad_s,
                         command.waypoint_index, self.obstacle_track_m[self.step_index].copy(), belief,
                         observation.pose if self._odometry is not None else None)
