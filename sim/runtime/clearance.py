"""The robot's clearance to the nearest obstacle, from MuJoCo's geometry.

An analytic 2-D pick (disc and box footprints against the base centre) chooses
the nearest obstacle; ``mj_geomDistance`` then measures the exact gap between
it and the robot: the chassis, and every other robot collision geom (wheel,
caster) that reaches beyond the chassis footprint, so a wheel that sticks out
of a small chassis is not forgotten, while the usual robot costs one call.

:meth:`ClearanceProbe.lower_bound_m` bounds the clearance from below without MuJoCo, from the last :meth:`~ClearanceProbe.measure`: footprint
distances are 1-Lipschitz in the point they are measured from, a geom's plan
view lies within its bounding sphere, and a 3-D distance is at least the
distance between plan views, so the nearest footprint distance then, less how
far the robot's geoms and the obstacles have moved since, less the geoms'
bounding radii, is a lower bound on what ``measure`` would return now.  The
runner asks it first and measures only when the answer could matter.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import mujoco
import numpy as np

from swarmnav.sim.scene import CompiledScene

CLEARANCE_HORIZON_M = 2.0  # mj_geomDistance search radius: clearances are reported up to this value
# lower_bound_m keeps this much to spare, far above mj_geomDistance's numerical error.
BOUND_MARGIN_M = 1e-4
PICK_SLACK_M = 1e-9  # taken off the nearest obstacle's lead over the next: far above the rounding of either


def outer_robot_geoms(scene: CompiledScene, data: mujoco.MjData | None = None) -> list[int]:
    """The chassis and the robot collision geoms whose bounding sphere reaches beyond its radius.

    ``data``: the scene's model after ``mj_forward`` at its default state (None: made here).
    """
    model = scene.model
    if data is None:
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


@dataclass(frozen=True, eq=False)
class _SceneGeometry:
    """What a probe needs of a scene that no run changes: worked out once per scene, from one ``MjData``."""

    robot_geom_ids: list[int]
    obstacle_ids: np.ndarray
    is_box: np.ndarray
    centres_m: np.ndarray  # at the default state (the mocap obstacles' are replaced at every measure)
    upright: bool


_GEOMETRY: "weakref.WeakKeyDictionary[CompiledScene, _SceneGeometry]" = weakref.WeakKeyDictionary()


def _scene_geometry(scene: CompiledScene) -> _SceneGeometry:
    geometry = _GEOMETRY.get(scene)
    if geometry is None:
        model = scene.model
        data = mujoco.MjData(model)  # a few hundred microseconds each: one for all, once per scene
        mujoco.mj_forward(model, data)
        obstacle_ids = np.array([ob.geom_id for ob in scene.obstacles], dtype=np.int64)
        is_box = model.geom_type[obstacle_ids] == mujoco.mjtGeom.mjGEOM_BOX
        geometry = _GEOMETRY[scene] = _SceneGeometry(
            outer_robot_geoms(scene, data), obstacle_ids, is_box, data.geom_xpos[obstacle_ids, :2].copy(),
            _upright_footprints(model, obstacle_ids, is_box, data))
    return geometry


class ClearanceProbe:
    """Measures the gap between the robot and its nearest obstacle (``inf`` with no obstacle).

    ``data``, when given, is the ``MjData`` that :meth:`lower_bound_m` reads (the
    runner's); :meth:`measure` takes its ``data`` per call.
    """

    def __init__(self, scene: CompiledScene, data: mujoco.MjData | None = None):
        model = scene.model
        self.model = model
        geometry = _scene_geometry(scene)
        self.robot_geom_ids = geometry.robot_geom_ids
        self.obstacle_ids = geometry.obstacle_ids
        is_box = geometry.is_box
        size = model.geom_size[self.obstacle_ids, :2]
        # One formula for both shapes: |max(|rel| - half, 0)| - radius, with half = 0 for
        # discs and radius = 0 for boxes.
        self.half_m = np.where(is_box[:, None], size, 0.0)
        self.radius_m = np.where(is_box, 0.0, size[:, 0])
        self._fromto = np.zeros(6)
        # Obstacle centres: those fixed to the world read once (MuJoCo recomputes the same values every
        # step), the others (mocap) at every measure; work arrays for the footprint distances.
        self._moving = np.flatnonzero(model.geom_bodyid[self.obstacle_ids] != 0)
        self._centres_m = geometry.centres_m.copy()
        self._point_m = np.zeros(2)
        self._work = np.zeros_like(self._centres_m)
        # For lower_bound_m: each outer robot geom's centre (a view of x, y into data) and bounding radius.
        self._robot_xy = [] if data is None else [(data.geom_xpos[g, :2], float(model.geom_rbound[g]))
                                                  for g in self.robot_geom_ids]
        self._bound_valid = bool(self._robot_xy) and len(self.obstacle_ids) > 0 and geometry.upright
        self._reference: tuple[float, float, float] | None = None  # (x, y, nearest footprint distance)
        # The last pick over every obstacle, in a scene whose obstacles never move: (index, x, y, how much
        # nearer the nearest footprint was than the next).  Footprint distances are 1-Lipschitz in the
        # point, so within half that margin of (x, y) the same obstacle is the nearest and one
        # footprint, computed with the same operations in the same order (the same bits), suffices.
        self._pick: tuple[int, float, float, float] | None = None
        self._shapes = [(float(cx), float(cy), float(hx), float(hy), float(r)) for (cx, cy), (hx, hy), r
                        in zip(self._centres_m, self.half_m, self.radius_m)]

    def measure(self, data: mujoco.MjData, x_m: float, y_m: float) -> float:
        if not len(self.obstacle_ids):
            return math.inf
        pick = self._pick
        if pick is not None and 2.0 * math.hypot(x_m - pick[1], y_m - pick[2]) < pick[3]:
            i = pick[0]
            cx, cy, hx, hy, radius_m = self._shapes[i]
            dx, dy = max(abs(cx - x_m) - hx, 0.0), max(abs(cy - y_m) - hy, 0.0)
            self._reference = (x_m, y_m, math.sqrt(dx * dx + dy * dy) - radius_m)
            return self._gap(data, int(self.obstacle_ids[i]))
        if self._moving.size:
            self._centres_m[self._moving] = data.geom_xpos[self.obstacle_ids[self._moving], :2]
        point = self._point_m
        point[0], point[1] = x_m, y_m
        d = self._work
        np.subtract(self._centres_m, point, out=d)
        np.abs(d, out=d)
        np.subtract(d, self.half_m, out=d)
        np.maximum(d, 0.0, out=d)
        np.multiply(d, d, out=d)
        footprint_m = np.sqrt(d[:, 0] + d[:, 1]) - self.radius_m
        i = int(footprint_m.argmin())
        self._reference = (x_m, y_m, float(footprint_m[i]))
        if not self._moving.size:
            margin_m = float(np.partition(footprint_m, 1)[1]) - float(footprint_m[i]) if len(footprint_m) > 1 \
                else math.inf
            self._pick = (i, x_m, y_m, margin_m - PICK_SLACK_M)
        return self._gap(data, int(self.obstacle_ids[i]))

    def _gap(self, data: mujoco.MjData, nearest: int) -> float:
        """The least ``mj_geomDistance`` from the outer robot geoms to obstacle geom ``nearest``."""
        model, fromto = self.model, self._fromto
        gap = math.inf
        for g in self.robot_geom_ids:
            gap = min(gap, mujoco.mj_geomDistance(model, data, g, nearest, CLEARANCE_HORIZON_M, fromto))
        return gap

    def lower_bound_m(self, obstacle_shift_m: float) -> float:
        """A value that :meth:`measure` on the bound ``data`` would now certainly exceed.

        From the last :meth:`measure`, with ``obstacle_shift_m`` bounding how far any
        obstacle has moved since; ``BOUND_MARGIN_M`` below the geometric bound.
        ``-inf`` when there is none (before any measure, or an obstacle whose plan view is
        not its footprint).  Above ``CLEARANCE_HORIZON_M``, ``measure`` returns exactly
        the horizon.
        """
        reference = self._reference
        if reference is None or not self._bound_valid:
            return -math.inf
        x0, y0, footprint_m = reference
        reach_m = 0.0
        for xy, rbound_m in self._robot_xy:
            gx, gy = xy.tolist()
            reach_m = max(reach_m, math.hypot(gx - x0, gy - y0) + rbound_m)
        return footprint_m - obstacle_shift_m - reach_m - BOUND_MARGIN_M


def _upright_footprints(model: mujoco.MjModel, geom_ids: np.ndarray, is_box: np.ndarray,
                        data: mujoco.MjData) -> bool:
    """Whether every obstacle's plan view is its footprint: upright cylinders, axis-aligned boxes
    (``data``: after ``mj_forward`` at the default state)."""
    xmat = data.geom_xmat[geom_ids].reshape(-1, 3, 3)
    upright = np.all(np.abs(xmat[:, :, 2] - (0.0, 0.0, 1.0)) < 1e-12, axis=1)
    aligned = np.all(np.abs(xmat - np.eye(3)) < 1e-12, axis=(1, 2))
    cylinder = model.geom_type[geom_ids] == mujoco.mjtGeom.mjGEOM_CYLINDER
    return bool(np.all(np.where(is_box, aligned, cylinder & upright)))
