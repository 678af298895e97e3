"""``oracle``: the clairvoyant yardstick, a planner-navigator that knows the obstacles' true future motion.

**Clairvoyant, not a navigator to rank**: at reset it reads the scenario's true
obstacle trajectories (the random walks drawn from the run's world seed) and
searches space-time for the earliest collision-free arrival within the robot's
speed and turning limits (:mod:`controllers.oracle_search`: a time-expanded
lattice, waiting allowed, at a stated resolution).  Then it drives that timed
trajectory in physics, reading only its own pose and the clock: no sensing.

Its verdict (solvable at its resolution or not, T*) tells which scenes an online
navigator could have solved; its physics outcome validates the verdict.

Driving the timed trajectory (ours): the reference pose at the observation's
time, interpolated between the lattice's ticks, tracked with Kanayama, Kimura,
Miyazaki & Noguchi (1990)'s law for a unicycle, Eq. (3):
v = v_r cos(e_theta) + K_x e_x and omega = omega_r + v_r (K_y e_y + K_theta sin(e_theta)),
e the reference pose in the robot's frame; v and omega clipped to the robot's limits (the lattice plans at
``speed_fraction`` of the top speed, so the rest is there to catch up).  After T* the reference holds the
arrival pose.  On a scene it calls unsolvable it stands still (its outcome is then whatever the world
does to a waiting robot).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.models.parameters import above, param, within
from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.kinematics import wheel_speeds
from swarmnav.controllers.navigator import NavigationSetup, NavigationStep, Observation
from swarmnav.controllers.oracle_search import OraclePlan, OracleSettings, search
from swarmnav.models.errors import ConfigError
from swarmnav.models.world import wrap_angle_rad


@dataclass
class ClairvoyantOracleNavigator:
    """Clairvoyant yardstick: knows the true future, searches space-time for the earliest arrival, tracks it.

    Args:
        cell_m, speed_fraction, turn_rate_rad_s, margin_m: the lattice (:class:`OracleSettings`).
        gain_x, gain_y, gain_theta: Kanayama et al. (1990)'s K_x (1/s), K_y (1/m^2), K_theta (1/m).
        max_angular_rad_s: the turn-rate limit of the drive.
    """

    name: ClassVar[str] = "oracle"
    uses_detections: ClassVar[bool] = False  # it knows the future instead
    uses_planner: ClassVar[bool] = False
    replan_wall_s: ClassVar[float] = 0.0     # its search runs in reset(), not in step()
    clairvoyant: ClassVar[bool] = True       # benchmarks report it as the yardstick, never as a contender
    # the lattice coarsens itself past 10^8 state-ticks, so a fine cell costs time, not memory (models.parameters)

    cell_m: float = param(0.1, within(0.01, 10))
    speed_fraction: float = param(0.9, above(0, 1))
    turn_rate_rad_s: float = param(1.0, above(0, 100))
    margin_m: float = param(0.04, within(0, 10))
    gain_x: float = param(2.0, above(0, 1e4))
    gain_y: float = param(40.0, above(0, 1e6))
    gain_theta: float = param(8.0, above(0, 1e4))
    max_angular_rad_s: float = param(1.5, above(0, 100))

    def __post_init__(self) -> None:
        self.settings = OracleSettings(self.cell_m, self.speed_fraction, self.turn_rate_rad_s, self.margin_m)
        self.settings.check("navigator.params")
        self.plan: OraclePlan | None = None

    def reset(self, setup: NavigationSetup) -> None:
        if setup.scenario is None:
            raise ConfigError("navigator", "oracle needs the scenario (its true obstacle motion)")
        self.geometry = setup.controller.geometry
        self.max_speed = setup.max_speed_m_s
        self.plan = search(setup.scenario, self.settings)
        self._announced = False

    def reference(self, time_s: float) -> tuple[float, float, float, float, float]:
        """(x, y, heading, v, omega) of the timed trajectory at ``time_s`` (held at the end)."""
        poses, tick = self.plan.poses, self.plan.tick_s
        last = len(poses) - 1
        u = time_s / tick
        if u >= last:
            x, y, th = poses[last]
            return float(x), float(y), float(th), 0.0, 0.0
        k = int(math.floor(u))
        frac = u - k
        a, b = poses[k], poses[k + 1]
        dth = wrap_angle_rad(b[2] - a[2])
        x, y = a[:2] + frac * (b[:2] - a[:2])
        v = math.hypot(b[0] - a[0], b[1] - a[1]) / tick
        return float(x), float(y), float(a[2] + frac * dth), v, dth / tick

    def step(self, observation: Observation) -> NavigationStep:
        events = []
        if not self._announced:
            self._announced = True
            events.append(("oracle", self.plan.verdict()))
        if not self.plan.solvable:
            return NavigationStep(ControlCommand.stop(), None, tuple(events))
        pose = observation.pose
        xr, yr, thr, vr, wr = self.reference(observation.time_s)
        c, s = math.cos(pose.heading_rad), math.sin(pose.heading_rad)
        ex = c * (xr - pose.x_m) + s * (yr - pose.y_m)
        ey = -s * (xr - pose.x_m) + c * (yr - pose.y_m)
        eth = wrap_angle_rad(thr - pose.heading_rad)
        v = vr * math.cos(eth) + self.gain_x * ex
        omega = wr + vr * (self.gain_y * ey + self.gain_theta * math.sin(eth))
        v = min(max(v, -self.max_speed), self.max_speed)
        omega = min(max(omega, -self.max_angular_rad_s), self.max_angular_rad_s)
        return NavigationStep(ControlCommand(wheel_speeds(v, omega, self.geometry), v, omega, 0), None, tuple(events))
