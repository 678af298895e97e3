"""The control period and the time limit counted in it.

An episode runs whole control periods of ``k`` physics steps each.  A time limit
is a whole number of periods: one that is not (``time_limit_s = 0.051`` at
50 Hz) is refused with a one-line error rather than cut short to the last whole
period (it used to end after 0.04 s) or stretched to the next (0.06 s): either
would run the episode for another time than the one asked for.
"""

from __future__ import annotations

import math

import mujoco

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import Scenario

PERIOD_TOLERANCE = 1e-9  # relative: a limit this close to a whole number of periods is that number


def steps_per_control(scenario: Scenario, model: mujoco.MjModel) -> int:
    """Physics steps per control period."""
    return int(round(1.0 / (scenario.sim.control_hz * model.opt.timestep)))


def control_periods(time_limit_s: float, control_dt_s: float, field: str = "time_limit_s",
                    source: str | None = None) -> int:
    """The number of control periods in ``time_limit_s``; ``ConfigError`` (naming ``field`` and ``source``)
    when the limit is not a positive whole number of periods."""
    periods = time_limit_s / control_dt_s
    whole = round(periods) if math.isfinite(periods) else 0
    if whole < 1 or abs(periods - whole) > PERIOD_TOLERANCE * max(1.0, periods):
        shorter = math.floor(periods + PERIOD_TOLERANCE) * control_dt_s if math.isfinite(periods) else math.nan
        raise ConfigError(field, f"{time_limit_s:g} s is not a whole number of control periods ({control_dt_s:g} s):"
                                 f" the episode would end after {shorter:g} s", source)
    return whole
