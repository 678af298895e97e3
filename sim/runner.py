"""The one runner loop: controller -> data.ctrl -> mj_step x k -> sensors ->
collision check -> recorder, at the control rate.

Only ``sim/`` touches MuJoCo.  Each control step:

1. move the mocap obstacles to their positions at time t;
2. read the pose (free joint); with a recorder, also the rangefinders (MuJoCo
   computes them every step; ``inf`` = nothing in range) and the wheel speeds;
3. track the clearance to the nearest obstacle with ``mj_geomDistance``;
4. stop on goal, timeout or (optionally) first collision;
5. ask the controller for wheel speeds, write ``data.ctrl``, and ``mj_step`` k
   times, checking after every physics step for a collision: a MuJoCo contact
   between a robot geom and an obstacle geom.

The clearance is sampled at the control rate; collisions at the physics rate.
"""

from __future__ import annotations

import math
import platform
import time
from dataclasses import dataclass, field
from importlib import metadata
from typing import Any

import mujoco
import numpy as np

from swarmnav.controllers import GoalChecker, PointToPointController
from swarmnav.models.scenario import Scenario
from swarmnav.planners import make_planner
from swarmnav.planners.problem import Path
from swarmnav.models.world import Pose2D
from swarmnav.sim.recording import ObstacleInfo, Recorder, RunContext, StepFrame
from swarmnav.sim.scene import CompiledScene, compile_scene
from swarmnav.planners.problem import scenario_problem

CLEARANCE_HORIZON_M = 2.0  # mj_geomDistance search radius: clearances are reported up to this value


def yaw_from_quaternion(w: float, x: float, y: float, z: float) -> float:
    """Heading (rotation about world z) of a wxyz quaternion."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def ranges_from_sensors(raw: np.ndarray, cutoff_m: float) -> np.ndarray:
    """MuJoCo rangefinder values -> metres, with ``inf`` for "nothing in range".

    MuJoCo reports -1 for no hit; with a cutoff the value is clipped to
    [-cutoff, cutoff], so both a miss (-cutoff) and a hit at or beyond the cutoff
    (+cutoff) mean nothing within range.
    """
    out = np.array(raw, dtype=float)
    out[(out < 0.0) | (out >= cutoff_m if cutoff_m > 0 else False)] = np.inf
    return out


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

    def summary(self) -> dict[str, Any]:
        return {"reached": self.reached, "outcome": self.outcome, "collisions": self.collisions,
                "first_collision_s": self.first_collision_s, "sim_time_s": round(self.sim_time_s, 6),
                "wall_time_s": round(self.wall_time_s, 4), "path_length_m": self.path_length_m,
                # None when the scene has no obstacle (JSON has no infinity).
                "min_clearance_m": self.min_clearance_m if math.isfinite(self.min_clearance_m) else None}


def versions() -> dict[str, str]:
    """swarmnav, MuJoCo and Python versions (for logs and summaries)."""
    try:
        swarmnav_version = metadata.version("swarmnav")
    except metadata.PackageNotFoundError:
        swarmnav_version = "unknown"
    return {"swarmnav": swarmnav_version, "mujoco": mujoco.__version__, "python": platform.python_version()}


class ContactMonitor:
    """Counts collisions: MuJoCo contacts between a robot geom and an obstacle geom.

    One event is a robot-obstacle contact after none for at least
    ``release_s``: soft contacts flicker from one physics step to the next
    while the robot is pushed along an obstacle, and that is one collision, not
    hundreds.  ``update`` reads ``data.contact`` (the contacts of the last
    ``mj_step``, found on the state before it integrated).
    """

    def __init__(self, model: mujoco.MjModel, is_robot: np.ndarray, is_obstacle: np.ndarray,
                 recorder: Recorder | None, release_s: float):
        self.model = model
        self.is_robot = is_robot
        self.is_obstacle = is_obstacle
        self.recorder = recorder
        self.release_s = release_s
        self.collisions = 0
        self.first_collision_s: float | None = None
        self.in_contact = False
        self.last_contact_s = -math.inf
        self.pair = ("", "")
        self.points: list[tuple[float, float]] = []

    def _hits(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        """The contact geom pairs and which of them are robot-obstacle contacts."""
        pairs = data.contact.geom[:data.ncon]
        hit = (self.is_robot[pairs[:, 0]] & self.is_obstacle[pairs[:, 1]]) | \
              (self.is_robot[pairs[:, 1]] & self.is_obstacle[pairs[:, 0]])
        return pairs, hit

    def robot_obstacle_contacts(self, data: mujoco.MjData) -> int:
        return int(self._hits(data)[1].sum())

    def update(self, data: mujoco.MjData, time_s: float, x_m: float, y_m: float) -> None:
        pairs, hit = self._hits(data)
        if hit.any():
            if not self.in_contact:
                g1, g2 = pairs[int(np.argmax(hit))]
                self.in_contact = True
                self.collisions += 1
                self.points.append((x_m, y_m))
                if self.first_collision_s is None:
                    self.first_collision_s = time_s
                self.pair = (self.model.geom(int(g1)).name, self.model.geom(int(g2)).name)
                if self.recorder is not None:
                    self.recorder.event(time_s, "collision_begin", {"geom_a": self.pair[0], "geom_b": self.pair[1]})
            self.last_contact_s = time_s
        elif self.in_contact and time_s - self.last_contact_s >= self.release_s:
            self.in_contact = False
            if self.recorder is not None:
                self.recorder.event(time_s, "collision_end", {"geom_a": self.pair[0], "geom_b": self.pair[1]})


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

    def reset(self) -> mujoco.MjData:
        """New MjData with the robot at the start pose and obstacles at t = 0."""
        data = mujoco.MjData(self.model)
        start = self.scenario.start
        adr = self.scene.free_qpos_adr
        data.qpos[adr:adr + 3] = [start.x_m, start.y_m, 0.0]
        data.qpos[adr + 3:adr + 7] = [math.cos(start.heading_rad / 2), 0.0, 0.0, math.sin(start.heading_rad / 2)]
        if self._moving:
            data.mocap_pos[self._mocap_index, :2] = self.obstacle_positions(np.zeros(1))[0]
        mujoco.mj_forward(self.model, data)
        return data

    def context(self, planner_name: str, planner_params: dict[str, Any], seed: int) -> RunContext:
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
            control_dt_s=self.control_dt_s, physics_dt_s=float(model.opt.timestep),
            sensor_angles_rad=self.scene.range_angles_rad.copy(), sensor_range_m=self.scene.range_cutoff_m,
            sensor_offset_m=self.scene.range_offset_m, sensor_height_m=self.scene.range_height_m,
            obstacles=tuple(infos), versions=versions(),
            arena_size_m=(self.scenario.arena_width_m, self.scenario.arena_height_m))

    def run(self, path: Path, recorder: Recorder | None = None, context: RunContext | None = None,
            time_limit_s: float | None = None, stop_on_collision: bool | None = None) -> RunResult:
        """Drive the robot along ``path`` until goal, timeout or (optionally) first collision.

        The recorder, when given, is finished even if the loop raises, so what it
        wrote stays readable.
        """
        scenario, scene, model = self.scenario, self.scene, self.model
        time_limit_s = scenario.time_limit_s if time_limit_s is None else time_limit_s
        stop_on_collision = scenario.sim.stop_on_collision if stop_on_collision is None else stop_on_collision
        k = self.steps_per_control
        dt = self.control_dt_s
        n_max = int(math.floor(time_limit_s / dt + 1e-9))

        data = self.reset()
        controller = PointToPointController(scene.drive, max_speed_m_s=scenario.max_speed_m_s,
                                            goal_tolerance_m=scenario.goal_tolerance_m)
        controller.reset(path.waypoints)
        goal = GoalChecker(scenario.goal.x_m, scenario.goal.y_m, scenario.goal_tolerance_m)

        times = np.arange(n_max + 1) * dt
        obstacle_track = self.obstacle_positions(times)          # (T, M, 2)
        mocap_index = self._mocap_index
        has_moving = len(mocap_index) > 0

        qadr = scene.free_qpos_adr
        chassis = scene.chassis_geom_id
        # Analytic 2-D prefilter to pick the nearest obstacle for mj_geomDistance.
        obstacle_ids = np.array([ob.geom_id for ob in scene.obstacles], dtype=np.int64)
        obstacle_is_box = model.geom_type[obstacle_ids] == mujoco.mjtGeom.mjGEOM_BOX if len(obstacle_ids) else np.zeros(0, bool)
        obstacle_half = model.geom_size[obstacle_ids, :2] if len(obstacle_ids) else np.zeros((0, 2))
        fromto = np.zeros(6)

        poses = np.zeros((n_max + 1, 3))
        wheel_cmd = np.zeros((n_max + 1, 2))
        monitor = ContactMonitor(model, scene.is_robot_geom, scene.is_obstacle_geom, recorder, release_s=dt)
        # Contacts that are not collisions (wheels and casters on the floor), counted at the
        # start: a substep with no more contacts than these and no ongoing collision is skipped.
        resting_contacts = data.ncon - monitor.robot_obstacle_contacts(data)
        physics_dt = float(model.opt.timestep)
        min_clearance = math.inf
        length = 0.0
        outcome = "timeout"
        step = 0
        ctrl = data.ctrl
        qpos = data.qpos
        geom_xpos = data.geom_xpos

        wall0 = time.perf_counter()
        try:
            if recorder is not None:
                recorder.start(context)
                recorder.path(0.0, path.waypoints)
            if data.ncon > resting_contacts:
                monitor.update(data, 0.0, float(qpos[qadr]), float(qpos[qadr + 1]))
            while True:
                t = step * dt
                if has_moving:
                    data.mocap_pos[mocap_index, :2] = obstacle_track[step]
                x, y = float(qpos[qadr]), float(qpos[qadr + 1])
                heading = yaw_from_quaternion(qpos[qadr + 3], qpos[qadr + 4], qpos[qadr + 5], qpos[qadr + 6])
                if step:
                    px, py = poses[step - 1, 0], poses[step - 1, 1]
                    length += math.hypot(x - px, y - py)
                poses[step] = (x, y, heading)
                pose = Pose2D(x, y, heading)

                # Clearance to the nearest obstacle: analytic pick, then mj_geomDistance on it.
                if len(obstacle_ids):
                    rel = np.abs(geom_xpos[obstacle_ids, :2] - (x, y))
                    box_gap = np.hypot(*np.maximum(rel - obstacle_half, 0.0).T)
                    disc_gap = np.hypot(rel[:, 0], rel[:, 1]) - obstacle_half[:, 0]
                    nearest = int(np.argmin(np.where(obstacle_is_box, box_gap, disc_gap)))
                    gap = mujoco.mj_geomDistance(model, data, chassis, int(obstacle_ids[nearest]),
                                                 CLEARANCE_HORIZON_M, fromto)
                    if gap < min_clearance:
                        min_clearance = gap

                if goal.reached(pose):
                    outcome = "goal_reached"
                elif stop_on_collision and monitor.collisions:
                    outcome = "collision"
                elif step >= n_max:
                    outcome = "timeout"
                else:
                    outcome = ""
                if outcome:
                    ctrl[:] = 0.0
                    if recorder is not None:
                        recorder.step(self._frame(data, t, x, y, heading, 0.0, 0.0, 0.0, 0.0,
                                                  controller.waypoint_index, obstacle_track[step]))
                        recorder.event(t, outcome if outcome != "collision" else "stopped_on_collision",
                                       {"x_m": x, "y_m": y})
                    break

                command = controller.command(pose)
                left, right = command.wheels.left_rad_s, command.wheels.right_rad_s
                ctrl[0] = left
                ctrl[1] = right
                wheel_cmd[step] = (left, right)
                if recorder is not None:
                    recorder.step(self._frame(data, t, x, y, heading, left, right, command.linear_m_s,
                                              command.angular_rad_s, command.waypoint_index,
                                              obstacle_track[step]))
                # Physics-grounded collision check at every physics step.
                for substep in range(k):
                    mujoco.mj_step(model, data)
                    if data.ncon > resting_contacts or monitor.in_contact:
                        monitor.update(data, (step * k + substep) * physics_dt, float(qpos[qadr]), float(qpos[qadr + 1]))
                step += 1
            wall = time.perf_counter() - wall0
            result = RunResult(
                reached=outcome == "goal_reached", outcome=outcome, collisions=monitor.collisions,
                first_collision_s=monitor.first_collision_s, sim_time_s=step * dt, wall_time_s=wall,
                path_length_m=length, min_clearance_m=float(min_clearance), steps=step,
                times_s=times[:step + 1].copy(), poses=poses[:step + 1].copy(),
                wheel_command_rad_s=wheel_cmd[:step + 1].copy(),
                collision_points_m=np.array(monitor.points, dtype=float).reshape(-1, 2))
        except BaseException as exc:
            if recorder is not None:
                stopped = isinstance(exc, (KeyboardInterrupt, SystemExit))
                recorder.finish({"outcome": "interrupted" if stopped else "error", "sim_time_s": step * dt})
            raise
        if recorder is not None:
            recorder.finish(result.summary())
        return result

    def _frame(self, data: mujoco.MjData, t: float, x: float, y: float, heading: float,
               left: float, right: float, v: float, omega: float, waypoint: int,
               obstacles_m: np.ndarray) -> StepFrame:
        scene = self.scene
        adr = scene.free_qpos_adr
        return StepFrame(
            time_s=t, position_m=data.qpos[adr:adr + 3].copy(), quaternion_wxyz=data.qpos[adr + 3:adr + 7].copy(),
            heading_rad=heading,
            range_m=ranges_from_sensors(data.sensordata[scene.range_sensor_adr], scene.range_cutoff_m),
            wheel_command_rad_s=np.array([left, right]),
            wheel_measured_rad_s=np.array([data.qvel[scene.wheel_qvel_adr[0]], data.qvel[scene.wheel_qvel_adr[1]]]),
            linear_m_s=v, angular_rad_s=omega, waypoint_index=waypoint, moving_obstacles_m=np.array(obstacles_m))


@dataclass
class Episode:
    """A planned and simulated scenario."""

    scenario: Scenario
    planner_name: str
    planner_params: dict[str, Any]
    seed: int
    path: Path
    result: RunResult


def plan_scenario(scenario: Scenario, planner_name: str | None = None,
                  planner_params: dict[str, Any] | None = None, seed: int | None = None) -> tuple[Path, str, dict, int]:
    """Plan on the scenario's obstacles at t = 0 with a generator seeded once."""
    name = planner_name or scenario.planner_name
    params = dict(scenario.planner_params if planner_params is None and name == scenario.planner_name
                  else (planner_params or {}))
    seed = scenario.seed if seed is None else seed
    planner = make_planner(name, params, scenario.source_path)
    path = planner.plan(scenario_problem(scenario), np.random.default_rng(seed))
    return path, name, params, seed


def simulate(scenario: Scenario, planner_name: str | None = None, planner_params: dict[str, Any] | None = None,
             seed: int | None = None, recorder: Recorder | None = None, **run_options: Any) -> Episode:
    """Plan, then run the closed loop in physics.  Same scenario and seed give the same trajectory."""
    path, name, params, seed = plan_scenario(scenario, planner_name, planner_params, seed)
    simulation = Simulation(scenario)
    context = simulation.context(name, params, seed) if recorder is not None else None
    result = simulation.run(path, recorder=recorder, context=context, **run_options)
    return Episode(scenario, name, params, seed, path, result)
