"""A hand-written reactive policy (not a trained network), for the ``policy`` navigator and the environment.

Heads for the goal; veers away from the nearest range hit ahead and, when the
observation has ``obstacles`` (the ``detector`` sensing model), from the nearest
sensed obstacle ahead, slowing down as it gets close.  ``act`` takes the
observation dict of :mod:`swarmnav.controllers.policy_interface` and returns a
normalised (v, omega), the ``twist`` action mode.

Run it through the command line with this folder on ``PYTHONPATH``::

    PYTHONPATH=tests swarmnav run dyn-crossing-3 --navigator policy --navigator-set policy=reactive_policy:act
"""

import numpy as np


def act(obs):
    distance_m, bearing_rad = (float(v) for v in obs["goal"])
    turn = 2.0 * bearing_rad
    speed = 1.0 if abs(bearing_rad) < 0.5 else 0.2
    ranges = obs["ranges"]
    angles = 2.0 * np.pi * np.arange(len(ranges)) / len(ranges)
    angles = np.where(angles > np.pi, angles - 2.0 * np.pi, angles)
    nearest = int(np.argmin(ranges))
    if ranges[nearest] < 1.0 and abs(angles[nearest]) < 1.6:
        turn -= np.sign(angles[nearest] or 1.0) * 3.0 * (1.0 - ranges[nearest])
        speed *= float(ranges[nearest])
    if "obstacles" in obs:
        for (x_m, y_m, vx_m_s, _, radius_m), valid in zip(obs["obstacles"], obs["obstacle_mask"]):
            gap_m = float(np.hypot(x_m, y_m) - radius_m)
            reach_m = 0.6 + 4.0 * max(-float(vx_m_s), 0.0)  # look further at what comes towards the robot
            if valid and x_m > 0.0 and gap_m < reach_m and gap_m < distance_m:
                turn -= np.sign(y_m or 1.0) * 3.0 * (reach_m - gap_m) / reach_m
                speed *= max(gap_m / reach_m, 0.1)
                break  # rows are nearest first
    return np.clip([speed, turn], -1.0, 1.0)
