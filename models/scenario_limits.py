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
MAX_STATIC_OBSTACLES = 10_000  # static [[obstacles]] (10,000 discs plan with astar and compile, tests/test_hostile_input.py)
MAX_TANGENT_GRAPH_DISCS = 300  # discs of an exact tangent graph (optimal, the SPL reference, robust guesses):
                               # its time grows ~n^3 (200 discs: 7 s, 500: 70 s, measured); the SPL of a run
                               # with more static discs is null
MAX_MOVING_OBSTACLES = 1_000   # moving [[obstacles]] (each a MuJoCo mocap body, tracked every control step)
MAX_INPUT_FILE_BYTES = 64_000_000  # any input file (scenario, study, suite, waypoints, map): checked before reading
MAX_NESTING_DEPTH = 32         # arrays or tables inside one another, in a file or a KEY=VALUE setting
MAX_SETTING_CHARS = 100_000    # one KEY=VALUE of --set, --navigator-set, --arm
MAX_SWEEP_VALUES = 100_000     # values of one swept parameter (a list in a study)
MAX_STUDY_RUNS = 2_000_000     # runs of one study (scenarios x settings x seeds), each a row; a sweep's settings
                               # (the product of its lists' lengths) are counted before any is expanded
MAX_COLONY_WALK_CELLS = 50_000_000  # ant colonies: ants x max_steps cells of one iteration's walks, drawn up front
# Benchmarks (bench ...): counts and durations a user can give on the command line
MAX_BENCH_REPEATS = 1_000      # bench sim/env --repeats, bench study --rounds
MAX_BENCH_RUNS = 1_000         # bench cli --runs, bench grid --runs/--swarm-sample, bench planners --seeds/--peer-runs/--fields
MAX_BENCH_FRAMES = 100_000     # bench render --frames
MAX_BENCH_SEEDS = 100_000      # bench navigation --seeds, --per-group, bench study --seeds
MAX_BENCH_DURATION_S = 20_000.0  # bench sim/env/log --duration (simulated seconds): MAX_CONTROL_STEPS at 50 Hz
MAX_WORKERS = 1_024            # --workers of a benchmark (a study's: 8 per core)
