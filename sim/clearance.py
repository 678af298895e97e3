"""The robot's clearance to the nearest obstacle, from MuJoCo's geometry.

An analytic 2-D pick (disc and box footprints against the base centre) chooses
the nearest obstacle; ``mj_geomDistance`` then measures the exact gap between
it and the robot: the chassis, and every other robot collision geom (wheel,
caster) that reaches beyond the chassis footprint, so a wheel that sticks out
of a small chassis is not forgotten, while the usual robot costs one call.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from swarmnav.sim.scene import CompiledScene

CLEARANCE_HORIZON_M = 2.0  # mj_geomDistance search radius: clearances are reported up to this value


def outer_robot_geoms(scene: CompiledScene) -> list[int]:
    """The chassis and the robot collision geoms whose bounding sphere reaches beyond its radius."""
    model = scene.model
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    chassis = scene.chassis_geom_id
    base_xy = data.geom_xpos[chassis, :2]
    chassis_radius = float(model.geom_size[chassis, 0])
    out = [chassis]
    for g in scene.robot_geom_ids:
        g = int(g)
        reach = float(np.hypot(*(data.geom_xpos[g, :2] - base_xy))) + float(model.geom_rbound[g])
        if g != chassis and reach > chassis_radius + 1e-9:
            out.append(g)
    return out


class ClearanceProbe:
    """Measures the gap between the robot and its nearest obstacle (``inf`` with no obstacle)."""

    def __init__(self, scene: CompiledScene):
        model = scene.model
        self.model = model
        self.robot_geom_ids = outer_robot_geoms(scene)
        self.obstacle_ids = np.array([ob.geom_id for ob in scene.obstacles], dtype=np.int64)
        is_box = model.geom_type[self.obstacle_ids] == mujoco.mjtGeom.mjGEOM_BOX
        size = model.geom_size[self.obstacle_ids, :2]
        # One formula for both shapes: |max(|rel| - half, 0)| - radius, with half = 0 for
        # discs and radius = 0 for boxes.
        self.half_m = np.where(is_box[:, None], size, 0.0)
        self.radius_m = np.where(is_box, 0.0, size[:, 0])
        self._fromto = np.zeros(6)

    def measure(self, data: mujoco.MjData, x_m: float, y_m: float) -> float:
        if not len(self.obstacle_ids):
            return math.inf
        d = np.maximum(np.abs(data.geom_xpos[self.obstacle_ids, :2] - (x_m, y_m)) - self.half_m, 0.0)
        nearest = int(self.obstacle_ids[np.argmin(np.sqrt(np.einsum("ij,ij->i", d, d)) - self.radius_m)])
        model, fromto = self.model, self._fromto
        gap = math.inf
        for g in self.robot_geom_ids:
            gap = min(gap, mujoco.mj_geomDistance(model, data, g, nearest, CLEARANCE_HORIZON_M, fromto))
        return gap
