"""The stated maxima of a scenario (README "Limits").

Each is checked before anything of that size is allocated, so an oversized request is a
:class:`~swarmnav.models.errors.ConfigError` naming the field, not an exhausted memory.
"""

from __future__ import annotations

MAX_NAME_CHARS = 64            # ``name`` becomes part of the default log file name
MAX_SENSORS = 1080             # rangefinder beams: a 270 degree laser at 0.25 degree (Hokuyo UTM-30LX class)
MIN_ROBOT_RADIUS_M = 0.05      # smaller robots than the base scaled to 1/3 of its size are not modelled
MAX_GRID_CELLS = 16_000_000    # the planning grid: 200 x 200 m at 0.05 m per cell
MAX_CONTROL_STEPS = 1_000_000  # time_limit_s x control_hz (the runner keeps every pose): 5.5 h at 50 Hz
MAX_PHYSICS_STEPS = 200_000_000  # time_limit_s / timestep_s: 111 h at 500 Hz
MAX_TRACK_SAMPLES = 20_000_000   # control steps x moving obstacles (positions computed up front)
MIN_LENGTH_M = 0.001           # obstacle radii and heights, map cells, sensor range: MuJoCo's XML keeps ~6 digits
MIN_TIMESTEP_S = 1e-6
MAX_WALK_STEPS = 100_000       # random-walk periods over all walks, drawn up front (about 3 s of work)
