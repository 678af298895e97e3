"""The environment's observation and action specs (``dm_env.specs``).

The entries, shapes and bounds come from :class:`controllers.policy_interface.ObservationLayout`
and the values from its :class:`PolicyObserver`, which the ``policy`` navigator
uses too: what a policy sees in training is what it sees in ``swarmnav run``.
Names, units and bounds are documented there.  Every entry is a bounded float32
array; the action is a bounded float32 array too (the task reads it in float64).
"""

from __future__ import annotations

import numpy as np
from dm_env import specs

from swarmnav.controllers.kinematics import DriveGeometry
from swarmnav.controllers.policy_interface import OBSERVATION_DTYPE, ObservationLayout, action_bounds

ACTION_DTYPE = np.float32


def observation_specs(layout: ObservationLayout) -> dict[str, specs.BoundedArray]:
    """One bounded spec per entry of the observation dict."""
    return {key: specs.BoundedArray(shape, OBSERVATION_DTYPE, low.astype(OBSERVATION_DTYPE),
                                    high.astype(OBSERVATION_DTYPE), name=key)
            for key, (shape, low, high) in layout.bounds().items()}


def action_spec(mode: str, geometry: DriveGeometry) -> specs.BoundedArray:
    low, high = action_bounds(mode, geometry)
    name = "v_omega_normalised" if mode == "twist" else "wheel_speeds_rad_s"
    return specs.BoundedArray((2,), ACTION_DTYPE, low, high, name=name)
