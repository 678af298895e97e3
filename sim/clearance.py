"""The robot's clearance to the nearest obstacle, from MuJoCo's geometry.

An analytic 2-D pick (disc and box footprints against the base centre) chooses
the nearest obstacle; ``mj_geomDistance`` then measures the exact gap between
it and every collision geom of the robot (chassis, wheels, casters), so a wheel
that sticks out of a small chassis is not forgotten.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from swarmnav.sim.scene import CompiledScene

CLEARANCE_HORIZON_M = 2.0  # mj_geomDistance search radius: clearances are reported up to this value


class ClearanceProbe:
    """Measures the gap between the robot and its nearest obstacle (``inf`` with no obstacle)."""

    def __init__(self, scene: CompiledScene):
        model = scene.model
        self.model = model
        self.robot_geom_ids = [int(g) for g in scene.robot_geom_ids]
        self.obstacle_ids = np.array([ob.geom_id for ob in scene.obstacles], dtype=np.int64)
        if len(self.obstacle_ids):
            self.is_box = model.geom_type[self.obstacle_ids] == mujoco.mjtGeom.mjGEOM_BOX
            self.half_m = model.geom_size[self.obstacle_ids, :2].copy()
        self._fromto = np.zeros(6)

    def measure(self, data: mujoco.MjData, x_m: float, y_m: float) -> float:
        if not len(self.obstacle_ids):
            return math.inf
        rel = np.abs(data.geom_xpos[self.obstacle_ids, :2] - (x_m, y_m))
        box_gap = np.hypot(*np.maximum(rel - self.half_m, 0.0).T)
        disc_gap = np.hypot(rel[:, 0], rel[:, 1]) - self.half_m[:, 0]
        nearest = int(self.obstacle_ids[int(np.argmin(np.where(self.is_box, box_gap, disc_gap)))])
        return min(mujoco.mj_geomDistance(self.model, data, g, nearest, CLEARANCE_HORIZON_M, self._fromto)
                   for g in self.robot_geom_ids)
