"""``velocity_obstacle``: velocity obstacles (Fiorini & Shiller 1998), the robot taking the whole
avoidance, guided by the global path, converted to (v, omega) for the differential drive.

Fiorini & Shiller (1998): the collision cone CC_i of obstacle B_i is the set
of relative velocities whose ray from the robot meets B_i grown by the
robot's radius (Eq. 2); the velocity obstacle VO_i = CC_i ⊕ v_i is that cone
translated by the obstacle's velocity (Eq. 3): a robot velocity in VO_i
collides with B_i at some time if both keep their velocities.  A velocity
outside the union of the VO_i (Eq. 4) avoids every obstacle; the paper
restricts the VO to collisions within a time horizon T_h (§ 4) and picks,
among the reachable avoidance velocities, one by a heuristic (e.g. toward the
goal, fastest).  Here:

* The cylinders do not react: the robot takes the whole avoidance (no
  reciprocity).  Sensed obstacles move with their estimated velocities; the
  known map's discs are VOs of still obstacles; a map box is in the way of a
  velocity when the straight segment the robot would drive within T_h passes
  within the inflation of it.
* Candidate velocities are a polar grid in the world frame (``speed_samples``
  speeds up to the robot's limit x ``heading_samples`` directions around the
  current heading, within ``max_turn_rad``); membership in the truncated VO is
  decided by the time to collision (:func:`~controllers.prediction.time_to_collision_s`)
  being below ``time_horizon_s``.
* Choice (ours; the paper leaves the heuristic open): the admissible velocity
  nearest the *preferred* one, full speed toward a carrot ``lookahead_m`` along
  the global path (slowed near the goal).  With none admissible, the one with
  the latest time to collision.
* Conversion to (v, omega) (ours; the paper's robot is holonomic in the
  plane): omega = ``heading_gain`` x the heading error to the chosen velocity,
  v = its speed x cos(error), zero when the error exceeds ``turn_in_place_rad``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.models.parameters import above, param, within
from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.guidance import local_setup
from swarmnav.controllers.guided import box_guidance
from swarmnav.controllers.kinematics import wheel_speeds
from swarmnav.controllers.navigator import Belief, NavigationSetup, NavigationStep, Observation
from swarmnav.controllers.velocity_candidates import (candidate_times_s, chosen_candidate,
                                                      footprint_candidate_times_s, unicycle_command)


@dataclass
class VelocityObstacleNavigator:
    """Fiorini & Shiller (1998) velocity obstacles, non-reciprocal, for a differential drive.

    Args:
        time_horizon_s: T_h, collisions later than this do not exclude a velocity.
        speed_samples, heading_samples: the candidate grid.
        max_turn_rad: candidate directions lie within this of the current heading.
        margin_m: extra distance kept beyond the robot radius.  0.15 m (ours): the rangefinder
            tracker's centres are off by several centimetres, and a random walker that turns toward
            the robot at 0.1 m/s closes 0.15 m in 1.5 s, time to turn and leave; at 0.05 m the robot
            skirted obstacles it could not escape (bench navigation: 0.87 -> 0.97 success on the suite).
        lookahead_m: the carrot's distance along the global path.
        heading_gain, max_angular_rad_s, turn_in_place_rad: the (v, omega) conversion.
        carrot_in_sight: the carrot is the farthest point of the lookahead the robot can reach straight past
            the known map (:meth:`controllers.guidance.PathCarrot.keep_in_sight`; ours, on by default: on
            dyn300's door scenes the carrot behind a wall held the robot still against it; false: the plain
            lookahead point).  The bundled dyn-* scenes have no static obstacle: there it changes nothing.
        footprint: "circle" (default: the robot radius about the base) or "box" (named option, ours; BARN's
            Jackal): each candidate is checked for the chassis box's covering discs
            (:func:`controllers.footprint.covering_discs`) facing the candidate's direction
            (:func:`controllers.velocity_candidates.footprint_candidate_times_s`), and with the map unknown the
            guidance path is planned for the chassis' inscribed circle and kept to the middle of passages
            (:class:`controllers.centred_path.CentredPlanner`) instead of the run's planner's.
        cost_weight, cost_reach_m: with ``footprint = "box"``, the guidance path's penalty near obstacles.
        speed_cap_m_s: the fastest candidate, at most the robot's top speed (named option, ours; 0: the robot's).
    """

    name: ClassVar[str] = "velocity_obstacle"
    safety_layer: ClassVar[dict[str, bool]] = {"safety_filter": False, "evade": False}  # controllers.safety_layer
    uses_detections: ClassVar[bool] = True
    uses_planner: ClassVar[bool] = False
    replan_wall_s: ClassVar[float] = 0.0  # plans nothing in step()

    time_horizon_s: float = param(4.0, above(0, 60))
    speed_samples: int = param(5, within(1, 100))
    heading_samples: int = param(25, within(1, 360))
    max_turn_rad: float = param(math.pi, above(0, math.pi))
    margin_m: float = param(0.15, within(0, 100))
    lookahead_m: float = param(1.0, above(0, 1000))
    heading_gain: float = param(2.5, above(0, 1000))
    max_angular_rad_s: float = param(1.2, above(0, 100))
    turn_in_place_rad: float = param(math.radians(60.0), above(0, math.pi))
    carrot_in_sight: bool = True
    footprint: str = param("circle", choices=("circle", "box"))
    cost_weight: float = param(0.0, within(0, 1000))
    cost_reach_m: float = param(0.3, above(0, 100))
    speed_cap_m_s: float = param(0.0, within(0, 100))

    def reset(self, setup: NavigationSetup) -> None:
        self.centred, self.discs, radius = box_guidance(setup, self.footprint, self.cost_weight, self.cost_reach_m)
        (self.geometry, self.max_speed, self.inflation, self.local, self.carrot, self.goal) = local_setup(
            setup, self.margin_m, self.lookahead_m, self.carrot_in_sight, self.centred, radius, self.speed_cap_m_s)
        speeds = np.linspace(self.max_speed / self.speed_samples, self.max_speed, self.speed_samples)
        offsets = np.linspace(-self.max_turn_rad, self.max_turn_rad, self.heading_samples)
        speed, offset = (a.ravel() for a in np.meshgrid(speeds, offsets, indexing="ij"))
        # The candidates in the robot's frame (+x ahead), standing still last: fixed, so the
        # obstacles are moved into this frame at each step rather than the candidates out of it.
        self.speeds = np.append(speed, 0.0)                                              # (K,)
        self.offsets = np.append(offset, 0.0)
        self.candidates = np.column_stack([self.speeds * np.cos(self.offsets), self.speeds * np.sin(self.offsets)])
        self.reach = self.max_speed * self.time_horizon_s + 1.0

    def step(self, observation: Observation) -> NavigationStep:
        pose = observation.pose
        target = self.carrot.update(pose)
        c, s = math.cos(pose.heading_rad), math.sin(pose.heading_rad)
        rx, ry = float(target[0]) - pose.x_m, float(target[1]) - pose.y_m
        preferred_speed = min(self.max_speed, math.hypot(self.goal[0] - pose.x_m, self.goal[1] - pose.y_m))
        scale = preferred_speed / max(math.hypot(rx, ry), 1e-9)
        preferred = (scale * (c * rx + s * ry), scale * (-s * rx + c * ry))                # robot frame
        candidates = self.candidates
        cost = np.hypot(candidates[:, 0] - preferred[0], candidates[:, 1] - preferred[1])
        centres, velocities, radii, boxes = self.local.near(pose.x_m, pose.y_m, self.reach, observation.detections)
        if (len(centres) or len(boxes)) and self.centred is not None:
            ttc = footprint_candidate_times_s(pose, np.array([[c, -s], [s, c]]), candidates, self.offsets, self.discs,
                                              centres, velocities, radii + self.inflation, boxes, self.inflation,
                                              self.time_horizon_s)
            k = chosen_candidate(ttc, cost, self.time_horizon_s)
        elif len(centres) or len(boxes):
            ttc = candidate_times_s(pose, np.array([[c, -s], [s, c]]), candidates, centres, velocities,
                                    radii + self.inflation, boxes, self.inflation, self.time_horizon_s)
            k = chosen_candidate(ttc, cost, self.time_horizon_s)
        else:
            k = int(np.argmin(cost))
        v, omega = unicycle_command(float(self.speeds[k]), float(self.offsets[k]), self.heading_gain,
                                    self.max_angular_rad_s, self.turn_in_place_rad)
        command = ControlCommand(wheel_speeds(v, omega, self.geometry), v, omega, 0)
        return NavigationStep(command, None, (), Belief(observation.detections, self.time_horizon_s))
