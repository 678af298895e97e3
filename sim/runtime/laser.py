"""A scanning 2-D laser: every beam cast from one origin with ``mj_multiRay``, once per control step.

The disc robot's 12-ray ring stays MuJoCo rangefinder sensors (one per rim site, as the papers' robot has).
A laser (``sensors.fov_deg`` below 360, or any catalogue robot whose beams start at its laser site) has no
sensor: MuJoCo computes every sensor at every physics step, so 270 rangefinders cost 2.6 ms per control step
of 10 physics steps where one ``mj_multiRay`` of the same 270 beams costs 0.22 ms (``swarmnav bench sim
--json``, ``laser_cast`` line; the measurement is in the README).  Conventions are those of
:func:`sim.sensing.ranges_from_sensors`: distances from the origin, ``inf`` for nothing within the range.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from swarmnav.sim.scene import CompiledScene


class LaserCaster:
    """Casts a compiled scene's laser in one ``MjData``.

    Args:
        scene: a scene with a laser (``scene.laser_site_id >= 0``).
        data: the ``MjData`` the beams are cast in (the stepper's).
    """

    def __init__(self, scene: CompiledScene, data: mujoco.MjData):
        if scene.laser_site_id < 0:
            raise ValueError("the scene has no laser (its rangefinders are sensors)")
        self.model, self.data = scene.model, data
        self.site = scene.laser_site_id
        self.exclude_body = int(scene.model.site_bodyid[self.site])  # the base: beams pass out of the chassis
        angles = np.asarray(scene.range_angles_rad, dtype=float)
        self.count = len(angles)
        self.cutoff_m = float(scene.range_cutoff_m)
        self._cos, self._sin = np.cos(angles), np.sin(angles)
        self._vec = np.zeros((self.count, 3))
        self._geom = np.zeros(self.count, dtype=np.int32)
        self._dist = np.zeros(self.count)

    def scan(self, heading_rad: float) -> np.ndarray:
        """(K,) ranges now, for a base heading ``heading_rad`` (the positions are brought up to date first:
        after ``mj_step`` MuJoCo's are those of the step's start, and the mocap obstacles were just moved)."""
        model, data = self.model, self.data
        mujoco.mj_kinematics(model, data)
        c, s = math.cos(heading_rad), math.sin(heading_rad)
        vec = self._vec
        np.multiply(self._cos, c, out=vec[:, 0])
        vec[:, 0] -= self._sin * s
        np.multiply(self._cos, s, out=vec[:, 1])
        vec[:, 1] += self._sin * c
        dist = self._dist
        mujoco.mj_multiRay(model, data, data.site_xpos[self.site], vec.reshape(-1), None, 1, self.exclude_body,
                           self._geom, dist, None, self.count, self.cutoff_m)
        return np.where((dist < 0.0) | (dist >= self.cutoff_m), math.inf, dist)
