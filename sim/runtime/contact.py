"""Collisions from physics: MuJoCo contacts between a robot geom and an obstacle geom."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from swarmnav.sim.recording import Recorder


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
        # Where the first collision began: time, base position, and which obstacle geom the robot touched
        # (``obstacle_NN`` is the scenario's ``[[obstacles]]`` entry NN, ``wall_*`` an arena wall,
        # ``map_box_NNN`` a box of the map).
        self.first_contact: dict[str, object] | None = None

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
                if self.first_contact is None:
                    robot, obstacle = self.pair if self.is_robot[int(g1)] else self.pair[::-1]
                    self.first_contact = {"time_s": time_s, "x_m": x_m, "y_m": y_m, "obstacle": obstacle,
                                          "robot_geom": robot}
                if self.recorder is not None:
                    self.recorder.event(time_s, "collision_begin", {"geom_a": self.pair[0], "geom_b": self.pair[1]})
            self.last_contact_s = time_s
        elif self.in_contact and time_s - self.last_contact_s >= self.release_s:
            self.in_contact = False
            if self.recorder is not None:
                self.recorder.event(time_s, "collision_end", {"geom_a": self.pair[0], "geom_b": self.pair[1]})
