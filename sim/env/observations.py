"""The environment's observation and action specs (``dm_env.specs``).

The values themselves come from :class:`controllers.policy_interface.PolicyObserver`,
which the ``policy`` navigator uses too: what a policy sees in training is what
it sees in ``swarmnav run``.  Names, shapes and units are documented there.
"""

from __future__ import annotations

import numpy as np
from dm_env import specs

from swarmnav.controllers.kinematics import DriveGeometry
from swarmnav.controllers.policy_interface import action_bounds


def observation_specs(range_count: int, path_waypoints: int) -> dict[str, specs.Array]:
    """One spec per entry of the observation dict; ``path`` only when ``path_waypoints`` > 0."""
    out: dict[str, specs.Array] = {
        "ranges": specs.BoundedArray((range_count,), np.float64, 0.0, 1.0, name="ranges"),
        "goal": specs.BoundedArray((2,), np.float64, [0.0, -np.pi], [np.inf, np.pi], name="goal"),
        "velocity": specs.Array((2,), np.float64, name="velocity"),
    }
    if path_waypoints > 0:
        out["path"] = specs.Array((path_waypoints, 2), np.float64, name="path")
    return out


def action_spec(mode: str, geometry: DriveGeometry) -> specs.BoundedArray:
    low, high = action_bounds(mode, geometry)
    name = "v_omega_normalised" if mode == "twist" else "wheel_speeds_rad_s"
    return specs.BoundedArray((2,), np.float64, low, high, name=name)
