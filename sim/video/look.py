"""How a rendered frame looks, beyond what the model says: cameras, colours, lights, ground.

Everything here changes only what is drawn (a free camera, geom colours, light
intensities, decor geoms computed for the scene), never what a simulation reads,
so logs and physics do not depend on it and an older log's MJCF renders alike.
Used by :class:`swarmnav.video.render.SceneRenderer`.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from swarmnav.sim import palette

# The follow camera looks straight down on the robot from this high: the frame's height
# spans about FOLLOW_VIEW_M metres of its surroundings whatever the arena's size.
FOLLOW_VIEW_M = 3.0
# A visual-only ground beyond the scene's floor (decor boxes around it), so no camera ever
# sees the black background past the floor's edge; drawn, never part of the model.
GROUND_HALF_M = 200.0


def follow_camera(model: mujoco.MjModel, view_m: float = FOLLOW_VIEW_M) -> mujoco.MjvCamera:
    """A free camera looking straight down (x to the right, y up), high enough that the
    frame's height spans ``view_m`` metres; its ``lookat`` is set to the robot each frame."""
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    camera.elevation = -90.0
    camera.azimuth = 90.0
    camera.distance = 0.5 * view_m / math.tan(math.radians(0.5 * float(model.vis.global_.fovy)))
    return camera


def paint_obstacles(model: mujoco.MjModel) -> None:
    """Give obstacles the shared palette's colours (:mod:`sim.palette`), as ``plot`` draws them.

    Colours only: nothing a simulation reads changes, so a log's MJCF renders the same
    whichever colours it was written with.
    """
    static, moving, wall = (np.array(palette.rgba(c)) for c in (palette.OBSTACLE, palette.MOVING_OBSTACLE,
                                                                   palette.ARENA))
    for g in range(model.ngeom):
        name = model.geom(g).name
        if name.startswith(("obstacle_", "map_box_")):
            moving_body = model.body_mocapid[model.geom_bodyid[g]] >= 0
            model.geom_rgba[g] = moving if moving_body else static
        elif name.startswith("wall_"):
            model.geom_rgba[g] = wall


def soften_lights(model: mujoco.MjModel) -> None:
    """Lights that add up to about 1 on a surface facing up (the scene's add up to 1.6, which
    washed the palette's light greys out to white): ambient and headlight 0.3 each, the
    scene's lights 0.4."""
    model.vis.headlight.ambient[:] = 0.3
    model.vis.headlight.diffuse[:] = 0.3
    model.light_diffuse[:] = 0.4
    model.light_specular[:] = 0.1


def ground_boxes(model: mujoco.MjModel, reach_m: float = GROUND_HALF_M) -> np.ndarray:
    """(B, 2, 3) centres and half-sizes of thin boxes that tile the ground around the floor.

    Four strips around the ``floor`` geom (one box under the whole view when the scene has no
    finite floor), so every pixel is drawn once: a box under the floor would cost a second fill
    of most of the frame in a software renderer.
    """
    floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "floor")
    z, half_z = -0.011, 0.01
    if floor < 0 or model.geom_size[floor, 0] <= 0 or model.geom_size[floor, 1] <= 0:
        return np.array([[[0.0, 0.0, z], [reach_m, reach_m, half_z]]])
    cx, cy = model.geom_pos[floor, :2]
    hx, hy = model.geom_size[floor, :2]
    x0, x1, y0, y1 = cx - hx, cx + hx, cy - hy, cy + hy
    side = (reach_m - hx) / 2
    strips = [((x0 - side, cy), (side, reach_m)), ((x1 + side, cy), (side, reach_m)),
              ((cx, y0 - (reach_m - hy) / 2), (hx, (reach_m - hy) / 2)),
              ((cx, y1 + (reach_m - hy) / 2), (hx, (reach_m - hy) / 2))]
    return np.array([[[px, py, z], [sx, sy, half_z]] for (px, py), (sx, sy) in strips])
