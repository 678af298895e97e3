"""MuJoCo's sensors and state as plain numbers: the one place their conventions are converted.

* Rangefinders: MuJoCo reports -1 for no hit and, with a cutoff, clips values to
  [-cutoff, cutoff]; here both a miss and a hit at or beyond the cutoff become
  ``inf`` ("nothing in range"), distances from the sensor site.  The logger,
  replay and plots take ranges from here and never see MuJoCo's raw values.
* The base pose: yaw from the free joint's quaternion.
* The base twist: forward speed and turn rate in the base frame (MuJoCo gives a
  free joint's linear velocity in the world frame and its angular velocity in
  the body frame).
"""

from __future__ import annotations

import math

import numpy as np


def ranges_from_sensors(raw: np.ndarray, cutoff_m: float) -> np.ndarray:
    """MuJoCo rangefinder values -> metres, with ``inf`` for "nothing in range".

    A dozen beams every control step: one pass over a list costs less than
    NumPy's masks (the same values; a NaN stays NaN).
    """
    inf = math.inf
    if cutoff_m > 0:
        return np.array([inf if r < 0.0 or r >= cutoff_m else r for r in np.asarray(raw, dtype=float).tolist()])
    return np.array([inf if r < 0.0 else r for r in np.asarray(raw, dtype=float).tolist()])


def yaw_from_quaternion(w: float, x: float, y: float, z: float) -> float:
    """Heading (rotation about world z) of a wxyz quaternion."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def base_twist(qvel: np.ndarray, dof_adr: int, heading_rad: float) -> tuple[float, float]:
    """(forward speed m/s, turn rate rad/s) of a free-joint base moving in the plane."""
    vx, vy = float(qvel[dof_adr]), float(qvel[dof_adr + 1])
    return vx * math.cos(heading_rad) + vy * math.sin(heading_rad), float(qvel[dof_adr + 5])
