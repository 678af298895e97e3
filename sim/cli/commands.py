"""The subcommands implemented in their own modules: their options, and a run that imports the module.

Building the parser must stay light (``swarmnav scenarios`` is a whole process
of well under a second), so this module imports only argparse and the option
types: each ``run_*`` below imports its module (MuJoCo, SciPy, the planners,
the log formats) inside the function, when that subcommand is the one chosen.
The defaults that the modules below the CLI also use live in :mod:`sim.defaults`, once.
"""

from __future__ import annotations

import argparse
from typing import Callable

from swarmnav.sim import options
from swarmnav.sim.defaults import (  # noqa: F401  (re-exported: the CLI's own defaults)
    SINGLE_THREAD_ENVIRONMENT, DEFAULT_FPS, LOG_FORMATS, MIN_FPS, MAX_FPS, MIN_DPI, MAX_DPI, BENCH_SIM_QUICK,
    BENCH_ENV_QUICK, BENCH_RENDER_QUICK_FRAMES, BENCH_PLANNERS_SCENARIOS, BENCH_PLANNERS_PLANNERS,
    BENCH_PLANNERS_SAMPLING, BENCH_PLANNERS_SAMPLING_CHOICES, BENCH_NAVIGATION_QUICK_SCENARIOS, BENCH_STUDY_QUICK)
from swarmnav.models.scenario_limits import (MAX_BENCH_DURATION_S, MAX_BENCH_FRAMES, MAX_BENCH_REPEATS, MAX_BENCH_RUNS,
                                             MAX_BENCH_SEEDS, MAX_STUDY_RUNS, MAX_WORKERS)
from swarmnav.sim.options import add_trust_code_argument  # noqa: F401
from swarmnav.cli import study as study_cli

# The counts and durations of the benchmarks, each with its stated maximum (models/scenario_limits.py).
DURATION = options.float_in(0.0, MAX_BENCH_DURATION_S)
REPEATS = options.int_in(1, MAX_BENCH_REPEATS)
RUNS = options.int_in(1, MAX_BENCH_RUNS)
SEEDS = options.int_in(1, MAX_BENCH_SEEDS)
WORKERS = options.int_in(1, MAX_WORKERS)


def per_group_type(text: str) -> int | tuple[int, int]:
    """``--per-group``: ``N`` (N scenes spread over each group) or ``A:B`` (each group's scenes A to B-1, in seed
    order), every count within MAX_BENCH_SEEDS."""
    if ":" not in text:
        return SEEDS(text)
    first_text, _, end_text = text.partition(":")
    first, end = options.int_in(0, MAX_BENCH_SEEDS)(first_text), options.int_in(1, MAX_BENCH_SEEDS)(end_text)
    if end <= first:
        raise argparse.ArgumentTypeError(f"A:B needs A < B, got {text[:40]}")
    return first, end


per_group_type.__name__ = "N or A:B"

Adder = Callable[[argparse.ArgumentParser], None]
Runner = Callable[[argparse.Namespace], int]


def add_bench_sim_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--scenario", default="dense-field-30")
    parser.add_argument("--duration", type=DURATION, default=20.0, help="simulated seconds per measurement")
    parser.add_argument("--repeats", type=REPEATS, default=7, help="bare, closed-loop and logged runs back to back; medians over them (default 7)")
    parser.add_argument("--quick", action="store_true",
                        help="%g simulated seconds, %d repeats (under a minute)" % BENCH_SIM_QUICK)
    parser.add_argument("--json", action="store_true")


def run_bench_sim(args: argparse.Namespace) -> int:
    from swarmnav.benchmarks import sim
    return sim.run(args)


def add_bench_planners_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--scenarios", nargs="+", default=list(BENCH_PLANNERS_SCENARIOS), metavar="NAME")
    parser.add_argument("--planners", nargs="+", default=list(BENCH_PLANNERS_PLANNERS), choices=BENCH_PLANNERS_PLANNERS,
                        metavar="NAME", help=f"continuous planners among {', '.join(BENCH_PLANNERS_PLANNERS)}")
    parser.add_argument("--sampling", nargs="*", default=list(BENCH_PLANNERS_SAMPLING),
                        choices=BENCH_PLANNERS_SAMPLING_CHOICES, metavar="NAME",
                        help=f"OMPL planners among {', '.join(BENCH_PLANNERS_SAMPLING_CHOICES)}, given population x "
                        f"iterations collision checks (default {', '.join(BENCH_PLANNERS_SAMPLING)}; "
                        "none: --sampling alone)")
    parser.add_argument("--seeds", type=RUNS, default=10, help="runs per planner and scenario (default 10)")
    parser.add_argument("--population", type=options.int_in(1, 1_000_000), default=50)
    parser.add_argument("--iterations", type=options.int_in(1, 1_000_000), default=100)
    parser.add_argument("--clearance-m", type=options.float_in(0.0, 100.0, low_open=False), default=0.0,
                        help="clearance beyond the robot radius (default 0, as in the papers)")
    parser.add_argument("--peer-scenario", default="gwo-scenario-1")
    parser.add_argument("--peer-runs", type=options.int_in(0, MAX_BENCH_RUNS), default=3, help="mealpy runs per peer (0: none)")
    parser.add_argument("--modes", nargs="+", default=["paper", "robust"], choices=["paper", "robust"])
    parser.add_argument("--fields", type=options.int_in(0, MAX_BENCH_RUNS), default=10,
                        help="random disc fields of 10-40 discs (default 10; 0: none)")
    parser.add_argument("--out", type=options.output_path, metavar="DIR", help="keep the quality studies' rows in DIR/scenarios and DIR/fields "
                        "(study folders: `swarmnav report DIR/scenarios`); a folder that holds them already resumes. "
                        "Default: a temporary folder")
    parser.add_argument("--workers", type=WORKERS, default=1,
                        help="processes running the quality studies (default 1: in this process, plan times "
                        "measured alone and warm)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--quick", action="store_true",
                        help="gwo-scenario-1 and dense-field-30, 3 seeds, 1 peer run, 2 random fields")


def run_bench_planners(args: argparse.Namespace) -> int:
    from swarmnav.benchmarks import planners
    return planners.run(args)


def add_bench_grid_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--runs", type=RUNS, default=5, help="runs (seeds) per map and planner")
    parser.add_argument("--maps", nargs="*", help="map scenario names (default: every bundled [map] scenario)")
    parser.add_argument("--all-pairs", action="store_true",
                        help="plan every start/goal pair of each map's [map].pairs, not only the scenario's")
    parser.add_argument("--swarm-sample", type=RUNS, default=20,
                        help="Moving AI instances per map on which immas and iaco report their ratio")
    parser.add_argument("--out", type=options.output_path, metavar="DIR", help="keep the quality studies' rows in DIR/maps, DIR/restaurant and "
                        "DIR/movingai (study folders: `swarmnav report DIR/maps`); default: a temporary folder")
    parser.add_argument("--quick", action="store_true",
                        help="the two slowest maps, 2 runs, 50 Moving AI instances a map, 1 swarm sample (under a minute)")


def run_bench_grid(args: argparse.Namespace) -> int:
    from swarmnav.benchmarks import grid
    return grid.run(args)


def add_bench_render_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--scenario", default="dense-field-30")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--frames", type=options.int_in(1, MAX_BENCH_FRAMES), default=150)
    parser.add_argument("--camera", choices=("top", "chase", "follow"), default="top",
                        help="top: the whole arena; chase: behind the robot; follow: straight down on the robot")
    parser.add_argument("--compare-defaults", action="store_true",
                        help="also time MuJoCo's default quality (multisampling, shadows, reflections)")
    parser.add_argument("--quick", action="store_true", help=f"{BENCH_RENDER_QUICK_FRAMES} frames (a few seconds)")
    parser.add_argument("--json", action="store_true")


def run_bench_render(args: argparse.Namespace) -> int:
    from swarmnav.benchmarks import render
    return render.run(args)


def add_bench_env_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--scenario", default="dense-field-30")
    parser.add_argument("--duration", type=DURATION, default=20.0, help="simulated seconds per measurement")
    parser.add_argument("--repeats", type=REPEATS, default=3)
    parser.add_argument("--quick", action="store_true",
                        help="%g simulated s x %d repeats (overrides the two above)" % BENCH_ENV_QUICK)
    parser.add_argument("--json", action="store_true")


def run_bench_env(args: argparse.Namespace) -> int:
    from swarmnav.benchmarks import env
    return env.run(args)


def add_bench_navigation_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--seeds", type=SEEDS, default=5, help="world seeds per scenario (default 5)")
    parser.add_argument("--navigator", action="append", help="only these navigators (repeatable)")
    parser.add_argument("--scenario", action="append", help="only these scenarios (repeatable; default: the dyn-* suite)")
    parser.add_argument("--navigator-set", action="append", metavar="KEY=VALUE",
                        help="a parameter for every navigator that has it (repeatable), e.g. policy=module:function")
    parser.add_argument("--arm", action="append", metavar="LABEL:NAVIGATOR[:KEY=VALUE,...]",
                        help="one more row: a navigator under its own label with its own parameters (repeatable), "
                             "e.g. iaco_local+evade:iaco_local:evade=true; with no --navigator only the arms run "
                             "(and the oracle)")
    parser.add_argument("--arms", metavar="FILE.toml",
                        help="more rows from a data file: its [[navigators]] entries (name, label, params, as in a "
                             "study file), e.g. models/suites/barn-navigators.toml, BARN's configurations; a "
                             "parameter naming code is refused there")
    parser.add_argument("--map", choices=("known", "unknown"),
                        help="every run's static map: given in advance (known) or built from the laser (unknown); "
                        "default: each scenario's knowledge.map")
    parser.add_argument("--pose", choices=("truth", "odometry"),
                        help="every run's pose: the simulator's (truth) or wheel odometry; default: each scenario's")
    parser.add_argument("--by-scenario", action="store_true",
                        help="also one row per navigator and scenario, after the overall rows")
    parser.add_argument("--out", type=options.output_path, metavar="DIR", help="keep the runs (a study folder: `swarmnav report DIR`); "
                        "default: a temporary folder")
    parser.add_argument("--json", action="store_true", help="print the rows as JSON (no progress bar)")
    parser.add_argument("--suite", choices=("dyn", "papers", "dyn300", "barn", "barn-like", "crowdnav"),
                        default="dyn",
                        help="dyn: the dyn-* suite (default); papers: the papers' strategies beside replan + iaco "
                             "and dstar_replan, one row per run (sim/benchmarks/paper_navigation.py); dyn300: the "
                             "300 generated scenes of models/suites/dyn300.toml, by difficulty; barn: the 300 BARN "
                             "worlds under the challenge's protocol and score (sim/benchmarks/barn.py; --quick: its "
                             "50 test worlds x 10 runs); barn-like: BARN-like worlds at fresh seeds "
                             "(sim/benchmarks/barn_like.py; --barn-worlds A:B seeds, default 0:50); crowdnav: CrowdNav's "
                             "circle-crossing test cases, robot invisible and visible to the humans")
    parser.add_argument("--barn-dir", metavar="DIR", help="--suite barn: the BARN data (default: $SWARMNAV_BARN_DIR, "
                        "else ../shared/benchmarks/barn)")
    parser.add_argument("--barn-runs", type=options.positive_int, metavar="N",
                        help="--suite barn: runs per world (default 1; --quick: 10), run j >= 1 from a seeded start "
                             "jitter")
    parser.add_argument("--barn-worlds", metavar="test|all|A:B[:STEP]|I,J,...",
                        help="--suite barn: these worlds (default all 300; --quick: test, the 50 worlds 0, 6, ..., 294)")
    parser.add_argument("--barn-setup", choices=("auto", "stand-in"),
                        help="--suite barn / barn-like: auto (default): the protocol's Jackal, laser and unknown map "
                             "as far as installed; stand-in: a disc of the Jackal's inscribed radius, map known")
    parser.add_argument("--barn-oracle", action="store_true", default=None,
                        help="--suite barn / barn-like: also run the clairvoyant oracle (off by default there: it "
                             "succeeded in 7 of 50 stand-in runs on BARN's test worlds)")
    parser.add_argument("--barn-planner", metavar="NAME[:KEY=VALUE,...]",
                        help="--suite barn / barn-like: the known-map track, every run planned by this planner on the "
                             "map given (e.g. gwo:mode=robust, mmas:cell_m=0.15)")
    parser.add_argument("--quick", action="store_true",
                        help=f"1 world seed on {', '.join(BENCH_NAVIGATION_QUICK_SCENARIOS)} (under a minute); "
                             "with --suite dyn300: a stratified sample, 2 scenes per group")
    parser.add_argument("--per-group", type=per_group_type, metavar="N|A:B",
                        help="a generated suite only (--suite dyn300, crowdnav): a stratified sample of N scenes per "
                             "group, spread over the group (--quick: 2); A:B: each group's scenes A to B-1 in seed "
                             "order (with --seed-offset 500, --per-group 0:250 runs CrowdNav's validation cases "
                             "500-749)")
    parser.add_argument("--seed-offset", type=options.int_in(0, 2**62), default=0, metavar="N",
                        help="a generated suite only (--suite dyn300, crowdnav): every group's seeds shifted by N, a "
                             "held-out set of the same "
                             "families (no shipped verdicts: the oracle decides each scene in the run)")
    parser.add_argument("--sensor-model", choices=("detector", "rangefinder"),
                        help="a generated suite only (--suite dyn300, crowdnav): every scene with this sensing "
                             "(rangefinder: 12 at 1 m)")
    parser.add_argument("--workers", type=WORKERS, default=1,
                        help="local worker processes for the runs (default 1: in this process); with --engine "
                             "ray: the local instance's CPUs")
    parser.add_argument("--engine", choices=("local", "ray"), default="local",
                        help="where the runs go: local processes (default) or Ray (the study engines)")
    parser.add_argument("--address", help="with --engine ray: the cluster to join (default: a local instance)")


def run_bench_navigation(args: argparse.Namespace) -> int:
    from swarmnav.benchmarks import navigation
    if args.quick and args.suite not in ("dyn300", "barn", "barn-like"):
        args.seeds, args.scenario = 1, args.scenario or list(BENCH_NAVIGATION_QUICK_SCENARIOS)
    return navigation.run(args)


def add_bench_study_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--seeds", type=SEEDS, default=20, help="seeds per scenario (2 scenarios: 40 cells by default)")
    parser.add_argument("--iterations", type=options.int_in(1, 1_000_000), default=600,
                        help="GWO iterations per cell (default 600: about 75 ms a cell, so a worker's start-up of "
                             "about a second is small against the work, as in a real study)")
    parser.add_argument("--rounds", type=REPEATS, default=3,
                        help="rounds of 1 worker then 2, back to back; medians over them (default 3)")
    parser.add_argument("--no-ray", action="store_true", help="skip the Ray comparison")
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--quick", action="store_true",
                        help="%d seeds per scenario, %d GWO iterations, no Ray (under a minute)" % BENCH_STUDY_QUICK)
    parser.add_argument("--cells", type=options.int_in(1, MAX_STUDY_RUNS), nargs="+", metavar="N",
                        help="instead: how the driver scales, plan-only studies of about N cells each (astar and "
                             "straight on four scenarios, 2 workers), local and on Ray (unless --no-ray): cells/s, "
                             "the driver's peak memory, the ratio of each rate to the smallest study's; "
                             "e.g. --cells 10000 100000")


def run_bench_study(args: argparse.Namespace) -> int:
    from swarmnav.benchmarks import study
    if args.quick:
        (args.seeds, args.iterations), args.no_ray, args.rounds = BENCH_STUDY_QUICK, True, 1
    return study.run(args)


def add_bench_cli_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--runs", type=RUNS, default=5, help="processes of each kind (default 5)")
    parser.add_argument("--quick", action="store_true", help="3 processes of each kind")
    parser.add_argument("--json", action="store_true")


def run_bench_cli(args: argparse.Namespace) -> int:
    from swarmnav.benchmarks import cli_start
    return cli_start.run(args)


def add_bench_log_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--duration", type=DURATION, default=3000.0,
                        help="simulated seconds of the logged run (default 3000: about 750,000 messages)")
    parser.add_argument("--no-video", action="store_true", help="skip replay --video")
    parser.add_argument("--quick", action="store_true", help="a 300 s run (under a minute)")
    parser.add_argument("--json", action="store_true")


def run_bench_log(args: argparse.Namespace) -> int:
    from swarmnav.benchmarks import log
    return log.run(args)


def add_bench_odometry_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--quick", action="store_true", help="20 simulated seconds per run (default 60)")
    parser.add_argument("--json", action="store_true", help="one JSON object per run")
    parser.add_argument("--write", action="store_true",
                        help="also write models/suites/results/odometry.json and docs/sensing.md's table from it")


def run_bench_odometry(args: argparse.Namespace) -> int:
    from swarmnav.benchmarks import odometry
    return odometry.run(args)


def add_bench_sensed_map_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--scenario", action="append", metavar="NAME",
                        help="a scenario instead of dense-field-30 and gwo-scenario-1 (repeatable)")
    parser.add_argument("--only", metavar="NAME", help="only the runs of this navigator or planner")
    parser.add_argument("--json", action="store_true", help="one JSON object per run")
    parser.add_argument("--write", action="store_true",
                        help="also write models/suites/results/sensed_map.json and docs/sensing.md's table from it")


def run_bench_sensed_map(args: argparse.Namespace) -> int:
    from swarmnav.benchmarks import sensed_map
    return sensed_map.run(args)


def add_bench_defaults_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--seeds", type=options.positive_int, default=10, help="seeds 0..N-1 per case (default 10)")
    parser.add_argument("--planners", nargs="+", metavar="NAME", help="only these planners (default: every paper's)")
    parser.add_argument("--quick", action="store_true", help="3 seeds per case")
    parser.add_argument("--json", action="store_true")


def run_bench_defaults(args: argparse.Namespace) -> int:
    from swarmnav.benchmarks import paper_defaults
    return paper_defaults.run(args)


def add_log_info_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("log", help="an .mcap run log")
    parser.add_argument("--json", action="store_true", help="print the facts as JSON")


def run_log_info(args: argparse.Namespace) -> int:
    from swarmnav.cli import log as log_commands
    return log_commands.run_info(args)


def add_log_recover_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("source", metavar="IN", help="a (possibly truncated) .mcap file")
    parser.add_argument("target", metavar="OUT", type=options.output_path, help="the complete, indexed .mcap file to write")


def run_log_recover(args: argparse.Namespace) -> int:
    from swarmnav.cli import log as log_commands
    return log_commands.run_recover(args)


def add_replay_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("log", help="an .mcap run log")
    parser.add_argument("--video", type=options.output_path, metavar="OUT.mp4", help="render the run to an MP4 (offscreen EGL)")
    parser.add_argument("--camera", choices=("top", "chase", "follow"), default="top",
                        help="top: the whole arena; chase: behind the robot; follow: straight down on the robot")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--fps", type=float, default=DEFAULT_FPS, help="frames per simulated second, 0.1..240")
    parser.add_argument("--no-trail", action="store_true", help="do not draw the driven trajectory")
    parser.add_argument("--verify", action="store_true",
                        help="re-simulate from the log and compare every pose and range scan "
                             "(exit 4 if they differ)")
    parser.add_argument("--json", action="store_true", help="print the results as JSON")
    parser.add_argument("--navigator-set", action="append", metavar="KEY=VALUE",
                        help="with --verify: the code a log's navigator ran (policy=module:function), named "
                             "here because a log's own is never run without --trust-code")
    add_trust_code_argument(parser)


def run_replay(args: argparse.Namespace) -> int:
    from swarmnav.log import replay
    return replay.run(args)


def add_plot_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("log", help="an .mcap run log")
    parser.add_argument("-o", "--out", type=options.output_path, required=True, help="image to write (.png, .svg, .pdf)")
    parser.add_argument("--dpi", type=int, default=120, help=f"dots per inch, {MIN_DPI}..{MAX_DPI}")


def run_plot(args: argparse.Namespace) -> int:
    from swarmnav.log import plot
    return plot.run(args)


def add_foxglove_layout_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-o", "--out", type=options.output_path, metavar="FILE",
                         help="write the layout to FILE (default: print it)")
    parser.add_argument("--log-format", choices=LOG_FORMATS, default="swarmnav",
                        help="the layout for logs of this format (run --log-format)")


def run_foxglove_layout(args: argparse.Namespace) -> int:
    from swarmnav.log import foxglove_layout
    return foxglove_layout.run(args)


# (words, add the options, run, help): the CLI builds one subparser from each row.
MODULE_COMMANDS: list[tuple[tuple[str, ...], Adder, Runner, str]] = [
    (("bench", "sim"), add_bench_sim_arguments, run_bench_sim,
     "closed loop vs bare mj_step on the dense 30-cylinder scene"),
    (("bench", "planners"), add_bench_planners_arguments, run_bench_planners,
     "continuous planners against the exact optimum and mealpy"),
    (("bench", "grid"), add_bench_grid_arguments, run_bench_grid,
     "grid planners, Moving AI optima and the pathfinding peer"),
    (("bench", "render"), add_bench_render_arguments, run_bench_render, "offscreen rendering frames per second"),
    (("bench", "env"), add_bench_env_arguments, run_bench_env,
     "the Gymnasium environment vs the closed-loop runner and bare mj_step"),
    (("bench", "navigation"), add_bench_navigation_arguments, run_bench_navigation,
     "every navigator on the dynamic suite (dyn-*) x world seeds"),
    (("bench", "cli"), add_bench_cli_arguments, run_bench_cli,
     "start-up of `swarmnav scenarios` against a bare `python -c pass`"),
    (("bench", "log"), add_bench_log_arguments, run_bench_log,
     "write a long run log, then time and peak memory of each reader beside the mcap library's"),
    (("bench", "defaults"), add_bench_defaults_arguments, run_bench_defaults,
     "each paper's planners at their defaults on its scenarios: collision-free plans over N seeds"),
    (("bench", "odometry"), add_bench_odometry_arguments, run_bench_odometry,
     "wheel odometry's pose error against distance driven, per robot, clean and in hard contact"),
    (("bench", "sensed-map"), add_bench_sensed_map_arguments, run_bench_sensed_map,
     "every planning navigator with the map known and unknown on dense-field-30 and gwo-scenario-1"),
    (("log", "info"), add_log_info_arguments, run_log_info, "what a log holds"),
    (("log", "recover"), add_log_recover_arguments, run_log_recover, "rewrite a truncated log as a complete one"),
    (("replay",), add_replay_arguments, run_replay, "re-render or re-simulate a log"),
    (("plot",), add_plot_arguments, run_plot, "plot a log to PNG"),
    (("foxglove-layout",), add_foxglove_layout_arguments, run_foxglove_layout,
     "the Foxglove layout for run logs (3D scene, wheel speeds, range readings, events)"),
    (("study",), study_cli.add_study_arguments, study_cli.run_study,
     "run a study (scenarios x planners x navigators x seeds) into Parquet rows"),
    (("studies",), study_cli.add_studies_arguments, study_cli.run_studies, "list the bundled studies"),
    (("report",), study_cli.add_report_arguments, study_cli.run_report,
     "an HTML and Markdown report of a study's rows"),
    (("bench", "study"), add_bench_study_arguments, run_bench_study,
     "study harness: parallel efficiency, overhead per cell, Ray vs local"),
]
