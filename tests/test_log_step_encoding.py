"""The per-step encodings written without NumPy or ``dumps`` give the same values and text."""

import math

import numpy as np

from swarmnav.log.format import dumps, scan_from_ranges, scan_list_from_ranges
from swarmnav.log.messages import controller_json, wheels_json


def test_the_scan_list_is_scan_from_ranges_bit_for_bit():
    rng = np.random.default_rng(0)
    for _ in range(200):
        ranges = rng.uniform(0.0, 3.0, int(rng.integers(0, 16)))
        ranges[rng.random(ranges.size) < 0.3] = np.inf
        ranges[rng.random(ranges.size) < 0.05] = -np.inf
        offset = float(rng.uniform(0.0, 0.3))
        fast, reference = np.array(scan_list_from_ranges(ranges, offset)), scan_from_ranges(ranges, offset)
        assert fast.tobytes() == reference.tobytes()          # NaN where infinite, the same sums elsewhere


def test_step_json_is_what_dumps_writes_for_finite_and_non_finite_values():
    keys = ("command_left_rad_s", "command_right_rad_s", "measured_left_rad_s", "measured_right_rad_s")
    for values in ((1.0, -2.5, 0.1, 1e-300), (math.inf, 0.0, 1.0, 2.0), (math.nan, 0.0, 0.0, 0.0),
                   (1.7e308, 1.7e308, 0.0, 0.0)):                   # the last overflows the finite check
        assert wheels_json(values[:2], values[2:]) == dumps(dict(zip(keys, values)))
    for linear, angular in ((0.2, -0.7), (math.inf, 0.0), (1.7e308, 1.7e308)):
        assert controller_json(linear, angular, 3) == dumps(
            {"linear_m_s": linear, "angular_rad_s": angular, "waypoint_index": 3})
