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
    values = raw.tolist() if type(raw) is np.ndarray and raw.dtype == np.float64 else \
        np.asarray(raw, dtype=float).tolist()
    if cutoff_m > 0:
        return np.array([inf if r < 0.0 or r >= cutoff_m else r for r in values])
    return np.array([inf if r < 0.0 else r for r in values])


def yaw_from_quaternion(w: float, x: float, y: float, z: float) -> float:
    """Heading (rotation about world z) of a wxyz quaternion."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def base_twist(vx_m_s: float, vy_m_s: float, wz_rad_s: float, heading_rad: float) -> tuple[float, float]:
    """(forward speed m/s, turn rate rad/s) of a free-joint base moving in the plane, from its world-frame
    linear velocity (``qvel[0:2]``), its body-frame angular velocity about z (``qvel[5]``) and its heading."""
    return vx_m_s * math.cos(heading_rad) + vy_m_s * math.sin(heading_rad), wz_rad_s
