"""An evasion layer for path-following navigators: when a sensed obstacle is about to run into the robot,
take the velocity-obstacle avoidance over from the path (no MuJoCo).

Why (measured on ``bench navigation --suite dyn300``): ``replan`` and ``dstar_replan`` plan around the
sensed obstacles' *swept footprints*, and keep those sweeps off the robot's own position so that a plan can
start (``replan.keep_outside``).  An obstacle that comes at the robot (a crosser faster than it, one chasing
it from behind, a walker turning onto it) is therefore missing exactly where it matters, and the robot,
following its path or waiting for a replan, is run into: most of their failures were collisions after which
the robot went on to reach its goal.  A planner over cells cannot express "step aside now"; a velocity
obstacle can.

What it does (ours; the composition of a global planner with a reactive local avoidance is the usual
architecture, e.g. Nav2's planner and controller servers; the avoidance is
:mod:`controllers.navigators.velocity_obstacle`'s, Fiorini & Shiller 1998):

* **Trigger**: each control step, the robot's motion under the navigator's command (its forward speed
  along the current heading; standing still when the command is a stop or a turn on the spot) is tested
  against every sensed obstacle predicted along its estimated velocity
  (:func:`~controllers.prediction.time_to_collision_s`, discs grown by the robot radius + ``margin_m``).
  When the earliest collision is closer than ``trigger_s``, the evasion takes over for this step.
* **Avoidance**: candidate velocities on a polar grid in the robot's frame (``speed_samples`` speeds up to
  the top speed x ``heading_samples`` directions all round, and standing still); the admissible ones (no
  collision with a sensed obstacle or a known map disc or box within ``horizon_s``) compete on their distance
  to the navigator's own velocity, so the evasion departs from the path no more than it must; with none
  admissible, the one with the latest collision.  (v, omega) as ``velocity_obstacle`` converts it.
* The navigator's state is untouched: its path and controller resume when the threat has passed (the
  controller heads for its next waypoint again; ``dstar_replan`` sees that the robot left its path).

An ``evade`` event marks each step at which the evasion starts to override (a rising edge).

Three options, off by default (ours; measured among CrowdNav's ORCA humans for ``dstar_replan``, docs/navigation.md):

* ``still_m_s`` > 0: a sensed obstacle no faster than this does not trigger the evasion (as the map's discs do
  not: a standing obstacle is the planner's, whose cells mark it).  ORCA humans that have reached their goals
  jitter at 0.01 m/s (RVO2's perturbation), so they counted as moving: the trigger extrapolates the robot
  straight along its heading, past the bend of a path that goes round such a human, fired, the evasion pushed
  the robot off the path, the controller turned it back, and the two alternated until the time limit.
* ``reverse``: a chosen candidate behind the robot (more than 90 degrees off its heading) is driven backwards
  (the rear turned toward it, the speed negative) instead of by a turn on the spot first: a differential drive
  can back away from a person walking at its front at once, where turning round to face the escape took
  1-2.6 s at 1.2 rad/s, in which the person walked into it.
* ``turn_cost_m_s_rad`` > 0: each candidate's cost (its distance to the navigator's velocity, m/s) grows by this
  much per radian the robot must turn to drive it (to its front, or with ``reverse`` to the nearer of front and
  rear; DWA's heading term in spirit, Fox et al. 1997).  With the navigator's command a stop or a turn on the spot
  every candidate of one speed costs the same, the tie went to the first in the robot-frame order, and that
  direction turned with the robot: the evasion turned on the spot for 1.5 s (validation case 688) and never left.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.kinematics import DriveGeometry, wheel_speeds
from swarmnav.controllers.navigator import DetectedObstacle, NavigationSetup, NavigationStep, Observation
from swarmnav.controllers.prediction import LocalObstacles, time_to_collision_s
from swarmnav.controllers.velocity_candidates import (candidate_times_s, chosen_candidate, unicycle_command,
                                                     world_to_robot)
from swarmnav.models.world import Pose2D, wrap_angle_rad


ORIGIN = np.zeros(2)  # the robot, in its own frame (read only)


@dataclass
class Evasion:
    """Overrides a command whose predicted time to collision with a sensed obstacle is below ``trigger_s``.

    Args:
        geometry: the drive, to turn (v, omega) into wheel speeds.
        robot_radius_m: the robot's footprint radius.
        max_speed_m_s: the robot's top speed (the candidates' largest).
        local: the known map's discs and boxes (checked by the candidates, not by the trigger).
        trigger_s: the evasion takes over below this predicted time to collision.
        horizon_s: a candidate is admissible when it collides with nothing within this.
        margin_m: extra distance kept beyond the robot radius.
        speed_samples, heading_samples: the candidate grid.
        heading_gain, max_angular_rad_s, turn_in_place_rad: the (v, omega) conversion.
        still_m_s: sensed obstacles no faster than this do not trigger (0: only those exactly still).
        reverse: drive a candidate behind the robot backwards rather than turning round to it first.
        turn_cost_m_s_rad: a candidate's cost grows by this per radian of turn it needs (0: off).
    """

    geometry: DriveGeometry
    robot_radius_m: float
    max_speed_m_s: float
    local: LocalObstacles
    trigger_s: float = 2.0
    horizon_s: float = 3.0
    margin_m: float = 0.1
    speed_samples: int = 4
    heading_samples: int = 24
    heading_gain: float = 2.5
    max_angular_rad_s: float = 1.2
    turn_in_place_rad: float = math.radians(60.0)
    still_m_s: float = 0.0
    reverse: bool = False
    turn_cost_m_s_rad: float = 0.0

    def __post_init__(self) -> None:
        speeds = np.linspace(self.max_speed_m_s / self.speed_samples, self.max_speed_m_s, self.speed_samples)
        offsets = np.linspace(-math.pi, math.pi, self.heading_samples, endpoint=False)
        speed, offset = (a.ravel() for a in np.meshgrid(speeds, offsets, indexing="ij"))
        self.speeds = np.append(speed, 0.0)
        self.offsets = np.append(offset, 0.0)
        self.candidates = np.column_stack([self.speeds * np.cos(self.offsets), self.speeds * np.sin(self.offsets)])
        turn = np.abs(self.offsets)
        self.turn_rad = np.minimum(turn, math.pi - turn) if self.reverse else turn
        self.reach_m = self.max_speed_m_s * self.horizon_s + 1.0
        self.active = False

    def apply(self, pose: Pose2D, command: ControlCommand, detections: tuple[DetectedObstacle, ...]
              ) -> tuple[ControlCommand, bool]:
        """The command to send, and whether the evasion started to override at this step."""
        if not detections:
            self.active = False
            return command, False
        centres, velocities, radii, boxes = self.local.near(pose.x_m, pose.y_m, self.reach_m, detections)
        rotate = world_to_robot(pose)                                          # row @ rotate: world -> robot
        local = (centres - (pose.x_m, pose.y_m)) @ rotate
        local_v = velocities @ rotate
        grown = radii + self.robot_radius_m + self.margin_m
        moving = np.hypot(velocities[:, 0], velocities[:, 1]) > max(1e-9, self.still_m_s)
        own = np.array([[max(command.linear_m_s, 0.0), 0.0]])
        if not moving.any():
            threat_s = math.inf
        elif moving.all():  # the usual case (every sensed obstacle moves): the arrays as they are
            threat_s = time_to_collision_s(ORIGIN, own, local, local_v, grown).min()
        else:
            threat_s = time_to_collision_s(ORIGIN, own, local[moving], local_v[moving], grown[moving]).min()
        if threat_s >= self.trigger_s:
            self.active = False
            return command, False
        ttc = candidate_times_s(pose, rotate, self.candidates, centres, velocities, grown, boxes,
                                self.robot_radius_m + self.margin_m, self.horizon_s)
        cost = np.hypot(self.candidates[:, 0] - own[0, 0], self.candidates[:, 1])
        if self.turn_cost_m_s_rad > 0.0:
            cost = cost + self.turn_cost_m_s_rad * self.turn_rad
        k = chosen_candidate(ttc, cost, self.horizon_s)
        self.chosen_m_s = self.candidates[k]                                  # robot frame, for the record
        offset = float(self.offsets[k])
        if self.reverse and math.cos(offset) < 0.0:  # behind: back toward it, the rear turned onto it
            v, omega = unicycle_command(float(self.speeds[k]), wrap_angle_rad(offset - math.pi), self.heading_gain,
                                        self.max_angular_rad_s, self.turn_in_place_rad)
            v = -v
        else:
            v, omega = unicycle_command(float(self.speeds[k]), offset, self.heading_gain,
                                        self.max_angular_rad_s, self.turn_in_place_rad)
        rising = not self.active
        self.active = True
        return ControlCommand(wheel_speeds(v, omega, self.geometry), v, omega, command.waypoint_index), rising


def evasion_for(setup: NavigationSetup, trigger_s: float, still_m_s: float = 0.0, reverse: bool = False,
                turn_cost_m_s_rad: float = 0.0) -> Evasion:
    """The evasion layer for a run, from its :class:`~controllers.navigator.NavigationSetup`."""
    known = setup.map_problem
    return Evasion(setup.controller.geometry, known.robot_radius_m, setup.max_speed_m_s,
                   LocalObstacles(known.disc_centres_m, known.disc_radii_m, known.box_array_m), trigger_s=trigger_s,
                   still_m_s=still_m_s, reverse=reverse, turn_cost_m_s_rad=turn_cost_m_s_rad)


def evaded(evasion: Evasion | None, observation: Observation, answer: NavigationStep) -> NavigationStep:
    """A navigator's :class:`~controllers.navigator.NavigationStep` with the evasion applied to its command
    (an ``evade`` event when it starts to override); the answer itself when ``evasion`` is None."""
    if evasion is None:
        return answer
    command, started = evasion.apply(observation.pose, answer.command, observation.detections)
    if command is answer.command:
        return answer
    events = answer.events + ((("evade", {"linear_m_s": round(command.linear_m_s, 6),
                                          "angular_rad_s": round(command.angular_rad_s, 6)}),) if started else ())
    return NavigationStep(command, answer.new_path, events, answer.belief)
