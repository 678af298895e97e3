"""The ``swarmnav`` command line.

Exit codes: 0 the command ran (whether or not the goal was reached); 1 a bug
(an exception nothing anticipated: one line saying so and where the full
traceback was saved); 2 bad input (one line on stderr naming the file, the
field and the problem); 3 the planner found no path; 4 ``replay --verify`` found a
difference; 5 a CI check fell short (``run --expect``, ``study --min-success``).
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import signal
import sys
import threading
import time
import tomllib
from pathlib import Path as FilePath
from typing import Any, Callable

# Building the parser imports only light modules (swarmnav.cli.commands): each subcommand imports
# what it needs (MuJoCo, SciPy, the planners, the log formats) when it runs.
from swarmnav.models.errors import ConfigError
from swarmnav.planners.errors import PlanningError
from swarmnav.sim import options
from swarmnav.cli import stop_signal
from swarmnav.sim.options import parse_settings
from swarmnav.sim.defaults import LOG_FORMATS
from swarmnav.cli.commands import DEFAULT_FPS, MODULE_COMMANDS, SINGLE_THREAD_ENVIRONMENT, add_trust_code_argument

# As swarmnav.video.render does, before any subcommand imports mujoco (which reads it once, on import).
os.environ.setdefault("MUJOCO_GL", "egl")
for _name, _value in SINGLE_THREAD_ENVIRONMENT.items():  # before any subcommand imports NumPy
    os.environ.setdefault(_name, _value)

EXIT_OK, EXIT_BUG, EXIT_BAD_INPUT, EXIT_NO_PATH = 0, 1, 2, 3
# 4 is replay --verify's difference; 5: a run or study fell short of --expect / --min-success (a CI check).
EXIT_EXPECTATION = 5


# The commands that name planners, navigators or scenarios: they load the installed plugins first.
PLUGIN_COMMANDS = {"plan", "run", "study", "bench", "scenarios", "planners", "navigators", "replay"}


class UserError(Exception):
    """A bad command-line value or file that is not a scenario (exit 2)."""


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose errors are one line on stderr (and exit 2), like every other bad input."""

    def error(self, message: str):
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _load(args: argparse.Namespace):
    """The scenario (a bundled one, a plugin's: :func:`main` has loaded the plugins once for the command);
    ``--trust-code``: its code parameters may run; its own planner and navigator tables are checked on load,
    whatever ``--planner`` overrides.  ``run``'s ``--map`` / ``--pose`` override its ``[knowledge]``."""
    from swarmnav.calls import check_components
    from swarmnav.models.scenario import load_scenario
    scenario = load_scenario(args.scenario, args.trust_code)
    check_components(scenario, args.trust_code)
    if getattr(args, "map", None) or getattr(args, "pose", None):
        scenario = scenario.with_knowledge(getattr(args, "map", None), getattr(args, "pose", None))
    return scenario


def _episode_spec(args: argparse.Namespace, scenario):
    """The episode the command line asks for (``plan`` and ``run`` alike): the scenario, then ``--planner``/
    ``--set``, ``--navigator``/``--navigator-set`` and the two seeds on top."""
    from swarmnav.sim.episode import EpisodeSpec
    return EpisodeSpec(scenario, planner=args.planner, planner_params=parse_settings(args.set, "--set"),
                       navigator=args.navigator,
                       navigator_params=parse_settings(args.navigator_set, "--navigator-set"),
                       seed=args.seed, world_seed=args.world_seed)


def _blame_options(args: argparse.Namespace, exc: ConfigError) -> ConfigError:
    """A bad value given on the command line is reported against the option, not the scenario file."""
    options = {"planner.name": "--planner" if args.planner else None,
               "navigator.name": "--navigator" if args.navigator else None}
    options.update({f"planner.params.{key}": "--set" for key in parse_settings(args.set, "--set")})
    options.update({f"navigator.params.{key}": "--navigator-set"
                    for key in parse_settings(args.navigator_set, "--navigator-set")})
    option = options.get(exc.field)
    return ConfigError(exc.field, exc.problem, option) if option else exc


def cmd_scenarios(args: argparse.Namespace) -> int:
    from swarmnav.models.scenario import list_scenarios, load_scenario
    if getattr(args, "scenarios_command", None) == "generate":
        return cmd_generate(args)
    if getattr(args, "scenarios_command", None) == "info":
        return cmd_scenario_info(args)
    if getattr(args, "scenarios_command", None) == "import":
        return args.scenario_run(args)
    rows = []
    for name in list_scenarios():
        s = load_scenario(name)
        moving = sum(ob.moving for ob in s.obstacles)
        rows.append({"name": name, "obstacles": len(s.obstacles), "moving": moving,
                     "planner": s.planner_name, "description": s.description})
    if args.json:
        print(json.dumps(rows))
    else:
        for r in rows:
            print(f"{r['name']:<24} {r['obstacles']:>3} obstacles ({r['moving']} moving)  {r['description']}")
    return EXIT_OK


def cmd_scenario_info(args: argparse.Namespace) -> int:
    """``scenarios info SCENARIO``: its difficulty metrics and the clairvoyant oracle's verdict (sim/runtime/difficulty.py)."""
    from swarmnav.models.scenario import load_scenario
    from swarmnav.sim.difficulty import difficulty
    scenario = load_scenario(args.scenario)
    if args.world_seed is not None:
        scenario = scenario.with_world_seed(args.world_seed)
    info = difficulty(scenario)
    if args.json:
        print(json.dumps(info))
        return EXIT_OK
    for key, value in info.items():
        if key == "oracle":
            value = ", ".join(f"{k} {v}" for k, v in value.items())
        print(f"{key:<24} {value}")
    return EXIT_OK


def cmd_components(args: argparse.Namespace) -> int:
    """``swarmnav planners`` / ``swarmnav navigators``: names, parameters and defaults, description, package."""
    from swarmnav.sim.plugins import describe_components
    rows = describe_components(args.kind)
    if args.json:
        print(json.dumps(rows))
        return EXIT_OK
    for row in rows:
        origin = "" if row["package"] == "swarmnav" else f"  [{row['package']}]"
        print(f"{row['name']:<20} {row['description']}{origin}")
        for param in row["parameters"]:
            bounds = f" in {param['range']}" if "range" in param else \
                f" one of {', '.join(param['choices'])}" if "choices" in param else ""
            print(f"    {param['name']} = {param['default']!r} ({param['type']}{bounds})")
    return EXIT_OK


def cmd_generate(args: argparse.Namespace) -> int:
    """``scenarios generate KIND --seed N``: write (or print) a generated scenario; it must load back."""
    from dataclasses import fields
    from swarmnav.models.scenario import parse_scenario
    from swarmnav.models.scenario_generator import GeneratorOptions, generate
    options = GeneratorOptions(**{f.name: getattr(args, f.name) for f in fields(GeneratorOptions)
                                  if getattr(args, f.name, None) is not None})
    from swarmnav.calls import check_components
    text = generate(args.kind, args.seed, options)
    try:  # it must load back, its planner and navigator too
        check_components(parse_scenario(text, args.out or "<generated>"))
    except ConfigError as exc:
        option = {"planner.name": "--planner", "navigator.name": "--navigator"}.get(exc.field)
        raise ConfigError(option, exc.problem) if option else exc from None
    if args.out:
        out = FilePath(args.out)
        if out.exists() and not args.overwrite:
            raise UserError(f"{out}: --out: file exists (use --overwrite)")
        out.write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
    return EXIT_OK


def _add_generate_options(p: argparse.ArgumentParser) -> None:
    from swarmnav.models.scenario_generator import KINDS, GeneratorOptions
    p.add_argument("kind", metavar="KIND", help=f"one of: {', '.join(KINDS)}")
    p.add_argument("--seed", type=options.seed, required=True, help="the layout's seed (same seed, same file)")
    p.add_argument("--out", type=options.output_path, help="write the TOML here (default: print it)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing --out file")
    for name, kind in (("obstacles", int), ("speed_ratio", float), ("radius_min_m", float),
                       ("radius_max_m", float), ("arena_m", float), ("sensor_model", str), ("range_m", float),
                       ("sensor_count", int), ("robot_speed_m_s", float), ("time_limit_s", float),
                       ("planner", str), ("navigator", str), ("name", str), ("humans", int)):
        p.add_argument(f"--{name.replace('_', '-')}", dest=name, type=kind,
                       help=f"default: {getattr(GeneratorOptions(), name)!r}")
    p.add_argument("--robot-visible", dest="robot_visible", action="store_true", default=None,
                   help="crowdnav_* kinds: the humans see the robot and avoid it (default: they do not)")


def cmd_plan(args: argparse.Namespace) -> int:
    from swarmnav.sim.episode import plan_episode
    scenario = _load(args)  # the file's own errors name the file, never an option
    try:
        episode = plan_episode(_episode_spec(args, scenario))
    except ConfigError as exc:
        raise _blame_options(args, exc) from None
    out = episode.plan_summary()
    path = episode.path
    if args.json:
        print(json.dumps(out))
    else:
        print(f"{out['scenario']}: {out['planner']} (seed {out['seed']}) {len(path.waypoints)} waypoints, "
              f"{out['length_m']:.4f} m in {out['plan_time_s'] * 1000:.1f} ms, "
              f"{'collision-free' if out['collision_free'] else 'NOT collision-free'}")
        for x, y in path.waypoints:
            print(f"  {x:8.4f} {y:8.4f}")
    return EXIT_OK


def cmd_run(args: argparse.Namespace) -> int:
    from swarmnav.calls import run_spec
    options.check_output_file(args.json_out, "--json-out")
    if args.video:
        from swarmnav.video.render import check_video_size
        check_video_size(args.width, args.height, args.fps)  # before the plan: bad options fail at once
    scenario = _load(args)  # the file's own errors name the file, never an option
    try:
        outcome = run_spec(_episode_spec(args, scenario), waypoints=args.waypoints,
                           log=False if args.no_log else (args.out or True), overwrite=args.overwrite,
                           video=args.video, camera=args.camera, width=args.width, height=args.height, fps=args.fps,
                           stop_on_collision=True if args.stop_on_collision else None, live=args.live,
                           log_format=args.log_format,
                           on_live=lambda url: print(f"live view: {url} (Foxglove: Open connection > Foxglove "
                                                     "WebSocket)", file=sys.stderr))
    except ConfigError as exc:
        raise _blame_options(args, exc) from None
    out = outcome.to_dict()
    result, path = outcome.result, outcome.path
    if args.json_out:
        FilePath(args.json_out).write_text(json.dumps(out) + "\n", encoding="utf-8")
    if args.json:
        print(json.dumps(out))
    else:
        status = "reached the goal" if result.reached else f"did not reach the goal ({result.outcome})"
        if result.reached and result.outcome != "goal_reached":
            status += f", but {result.outcome}"
        given = out["plan"]["details"].get("given")  # a given path: nothing was planned
        print(f"{out['scenario']}: {'given path ' + repr(given) if given else out['planner']} + {out['navigator']} "
              f"(seed {out['seed']}, world seed "
              f"{out['world_seed']}) {status} in {result.sim_time_s:.2f} s sim "
              f"({result.wall_time_s:.2f} s wall); driven {result.path_length_m:.3f} m "
              f"({'given' if given else 'planned'} {path.stats.length_m:.3f} m); collisions {result.collisions}"
              + (f", first at {result.first_collision_s:.2f} s with {result.first_contact['obstacle']} at "
                 f"({result.first_contact['x_m']:.2f}, {result.first_contact['y_m']:.2f})"
                 if result.first_contact is not None else "")
              + f"; min clearance {result.min_clearance_m:.3f} m"
              + (f"; SPL {out['spl']:.3f}" if out.get("spl") is not None else ""))
        if outcome.log:
            print(f"log: {outcome.log}")
        if args.video:
            print(f"video: {args.video}")
        if args.json_out:
            print(f"summary (run --json): {args.json_out}")
    return expectation_exit(args.expect, outcome)


def expectation_exit(expect: str | None, outcome) -> int:
    """``--expect success|reached``: EXIT_EXPECTATION and one line on stderr when the run falls short."""
    if expect is None:
        return EXIT_OK
    met = outcome.success if expect == "success" else outcome.reached
    if met:
        return EXIT_OK
    result = outcome.result
    print(f"swarmnav: expectation not met: --expect {expect}: {outcome.episode.spec.scenario.name}: "
          f"{result.outcome}, {result.collisions} collision(s), {result.sim_time_s:.2f} s sim"
          + (f", first collision at {result.first_collision_s:.2f} s with {result.first_contact['obstacle']}"
             if result.first_contact is not None else "")
          + f"; log: {outcome.log or 'none'}", file=sys.stderr)
    return EXIT_EXPECTATION


def _add_run_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("scenario", help="bundled scenario name or path to a .toml file")
    p.add_argument("--planner", help="planner name (default: the scenario's)")
    p.add_argument("--seed", type=options.seed, help="the planner's and navigator's random seed (default: the scenario's)")
    p.add_argument("--world-seed", type=options.seed, help="seed of the random obstacle motions (default: the scenario's seed)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="planner parameter (repeatable)")
    p.add_argument("--navigator", help="navigator name (default: the scenario's, else follow)")
    p.add_argument("--navigator-set", action="append", metavar="KEY=VALUE", help="navigator parameter (repeatable)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_trust_code_argument(p)


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(
        prog="swarmnav", description="Plan, simulate, log and replay swarm path planners for a wheeled robot in MuJoCo.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("scenarios", help="list the bundled scenarios, or generate one")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_scenarios)
    scenario_commands = p.add_subparsers(dest="scenarios_command", metavar="generate|info|import")
    gen = scenario_commands.add_parser("generate", help="write a dynamic scenario (crossing, head_on, ...) from a seed")
    _add_generate_options(gen)
    info = scenario_commands.add_parser("info", help="difficulty metrics and the clairvoyant oracle's verdict")
    info.add_argument("scenario", metavar="SCENARIO", help="a bundled name or a .toml path")
    info.add_argument("--world-seed", type=options.seed, help="seed of the random obstacle motions (default: the scenario's)")
    info.add_argument("--json", action="store_true", help="print one JSON object")
    from swarmnav.cli import world_import
    imp = scenario_commands.add_parser("import", help="a Gazebo world's static cylinders and boxes as a scenario file")
    world_import.add_arguments(imp)
    imp.set_defaults(scenario_run=world_import.run)

    p = sub.add_parser("plan", help="plan a path for a scenario")
    _add_run_options(p)
    p.set_defaults(func=cmd_plan)

    p = sub.add_parser("run", help="plan and simulate a scenario in MuJoCo")
    _add_run_options(p)
    p.add_argument("--out", type=options.output_path, help="MCAP log path (default: logs/<scenario>_<planner>_seed<N>_<stamp>.mcap)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing --out file")
    p.add_argument("--no-log", action="store_true", help="write no MCAP log")
    p.add_argument("--log-format", choices=LOG_FORMATS, default="swarmnav",
                   help="swarmnav (Foxglove's schemas, the default) or ros2 (CDR, the standard ROS 2 types)")
    p.add_argument("--live", action="store_true", help="also serve the channels to Foxglove on 127.0.0.1")
    p.add_argument("--video", type=options.output_path, help="render an MP4 while running (offscreen EGL)")
    p.add_argument("--camera", default="top", choices=("top", "chase", "follow"),
                   help="top: the whole arena; chase: behind the robot; follow: straight down on the robot")
    p.add_argument("--width", type=int, default=640)
    p.add_argument("--height", type=int, default=480)
    p.add_argument("--fps", type=float, default=DEFAULT_FPS, help="frames per simulated second, 0.1..240")
    p.add_argument("--stop-on-collision", action="store_true", help="stop at the first collision")
    p.add_argument("--map", choices=("known", "unknown"),
                   help="the static map given in advance (known) or built from the laser as the robot drives "
                   "(unknown); default: the scenario's knowledge.map")
    p.add_argument("--pose", choices=("truth", "odometry"),
                   help="the pose the navigator sees: the simulator's (truth) or integrated wheel speeds "
                   "(odometry); default: the scenario's knowledge.pose")
    p.add_argument("--waypoints", metavar="FILE", help="drive this path instead of planning: CSV with x,y columns, "
                   "a JSON list of [x, y] pairs, or the output of `plan --json`")
    p.add_argument("--json-out", type=options.output_path, metavar="FILE", help="also write the `--json` object to FILE")
    p.add_argument("--expect", choices=("success", "reached"),
                   help=f"exit {EXIT_EXPECTATION} unless the goal is reached with no collision (success) or reached "
                   "at all (reached): a CI smoke check")
    p.set_defaults(func=cmd_run)

    for kind in ("planners", "navigators"):
        p = sub.add_parser(kind, help=f"list every {kind[:-1]} (bundled and installed plugins) with its parameters")
        p.add_argument("--json", action="store_true")
        p.set_defaults(func=cmd_components, kind=kind[:-1])

    groups: dict[str, argparse._SubParsersAction] = {}
    bench = sub.add_parser("bench", help="benchmarks that print figures")
    groups["bench"] = bench.add_subparsers(dest="bench_command", required=True, metavar="BENCH")
    log = sub.add_parser("log", help="inspect and repair MCAP logs")
    groups["log"] = log.add_subparsers(dest="log_command", required=True, metavar="LOGCMD")

    for words, add_arguments, run, help_text in MODULE_COMMANDS:
        parent = groups[words[0]] if len(words) > 1 else sub
        p = parent.add_parser(words[-1], help=help_text)
        add_arguments(p)
        p.set_defaults(func=run)
    return parser


@functools.cache
def _parser() -> argparse.ArgumentParser:
    """The parser, built once per process and reused (``parse_args`` leaves it as it was): a process that
    calls :func:`main` many times (the tests, a script) spent most of each call building it, with
    argparse's message look-ups for every option."""
    return build_parser()


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``swarmnav`` console script."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, stop_signal.exit_on_signal)
    parser = _parser()
    args = parser.parse_args(argv)
    if args.command in PLUGIN_COMMANDS:
        from swarmnav.sim.plugins import load_plugins
        load_plugins()
    func: Callable[[argparse.Namespace], int] = args.func
    try:
        return int(func(args) or 0)
    except ConfigError as exc:
        print(f"swarmnav: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except UserError as exc:
        print(f"swarmnav: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except BrokenPipeError:  # stdout closed early (e.g. piped into head): not an error of ours
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    except OSError as exc:  # an output or input path the file system refuses
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        print(f"swarmnav: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except PlanningError as exc:
        print(f"swarmnav: no path: {type(exc).__name__}: {exc}", file=sys.stderr)
        return EXIT_NO_PATH
    except KeyboardInterrupt:
        print("swarmnav: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # nothing anticipated it: a bug of ours, reported in one line
        print(f"swarmnav: bug: {_report_bug(exc)}", file=sys.stderr)
        return EXIT_BUG


def _report_bug(exc: Exception) -> str:
    """Save the full traceback of an unanticipated exception; one line saying what and where."""
    import tempfile
    import traceback

    frame = traceback.extract_tb(exc.__traceback__)[-1] if exc.__traceback__ else None
    where = f" at {FilePath(frame.filename).name}:{frame.lineno}" if frame else ""
    what = f"{type(exc).__name__}{where}: {exc}".replace("\n", " ")
    try:
        fd, name = tempfile.mkstemp(prefix=f"swarmnav-bug-{time.strftime('%Y%m%d-%H%M%S')}-", suffix=".txt")
        with os.fdopen(fd, "w", encoding="utf-8") as out:
            out.write(f"swarmnav {' '.join(sys.argv[1:])}\n")
            out.write("".join(traceback.format_exception(exc)))
        saved = f"full traceback saved to {name}"
    except OSError as save_error:
        saved = f"the traceback could not be saved ({save_error.strerror or save_error})"
    return f"{what} ({saved}; please report it)"


if __name__ == "__main__":
    sys.exit(main())
