"""Defaults and bounds that the command line and the modules below it share (the CLI's options, the plot,
the video, the study workers, the benchmarks).

They live here, below the CLI, so that nothing but the CLI imports the CLI (``sim/cli/commands.py`` and
``sim/cli/main.py`` import these names from here).  Plain constants: importing this module costs nothing.
"""

from __future__ import annotations

# NumPy's BLAS and OpenMP on one thread, for the CLI and every study worker (set before NumPy loads).  The
# planners' matrices are small: with another process busy on a 2-core machine, OpenBLAS's threads made a
# robust GWO plan on a 40-disc field 0.03-0.37 s instead of 0.033 s.  A value already set in the environment wins.
SINGLE_THREAD_ENVIRONMENT = {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
                             "NUMEXPR_NUM_THREADS": "1", "VECLIB_MAXIMUM_THREADS": "1"}
LOG_FORMATS = ("swarmnav", "ros2")  # --log-format of run and study --logs; each is its MCAP profile (swarmnav.log.format)
DEFAULT_FPS = 30.0  # frames per simulated second of a video (run --video, replay --video)
MIN_FPS, MAX_FPS = 0.1, 240.0  # --fps bounds: each simulated second is MAX_FPS frames at most
MIN_DPI, MAX_DPI = 10, 600  # plot: 600 dpi is 4800 x 6300 pixels (about 120 MB of RGBA)
BENCH_SIM_QUICK = (5.0, 5)  # bench sim --quick: simulated seconds, repeats (under a minute)
BENCH_ENV_QUICK = (4.0, 2)  # bench env --quick: a smoke run of the same measurement (noisier figures)
BENCH_RENDER_QUICK_FRAMES = 40
BENCH_PLANNERS_SCENARIOS = ("gwo-scenario-1", "gwo-scenario-2", "gwo-scenario-3",
                            "adl-abc-path-1", "adl-abc-path-2", "adl-abc-path-3",
                            "dense-field-30", "restaurant-table-2", "restaurant-table-5")
BENCH_PLANNERS_PLANNERS = ("abc", "adl_abc", "gwo", "pso")
BENCH_PLANNERS_SAMPLING = ("rrt_star", "informed_rrt_star", "bit_star", "prm_star")  # OMPL's, run by default
# Every OMPL planner `bench planners --sampling` can name (planners/sampling_ompl.py, planners/ompl_geometric.py).
BENCH_PLANNERS_SAMPLING_CHOICES = (*BENCH_PLANNERS_SAMPLING, "rrt", "rrt_connect", "kpiece1", "bkpiece1", "lbkpiece1",
                                   "prm", "fmt_star", "bfmt_star", "aorrtc")
# bench navigation --quick: one world seed on one scenario of each generated kind.
BENCH_NAVIGATION_QUICK_SCENARIOS = ("dyn-crossing-1", "dyn-head-on-1", "dyn-overtake-1", "dyn-crowd-1")
BENCH_STUDY_QUICK = (10, 300)  # bench study --quick: seeds per scenario, GWO iterations; no Ray
