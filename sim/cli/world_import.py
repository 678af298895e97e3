"""``swarmnav scenarios import WORLD.world[.gz]``: a Gazebo world's static cylinders and boxes as a scenario
file (:mod:`models.world_scenario`); a bad file is one line on stderr and exit 2."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path as FilePath

from swarmnav.models.errors import ConfigError


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("world", metavar="WORLD", help="an SDF world file, .world / .sdf, gzip-compressed or not")
    p.add_argument("--robot", metavar="NAME", help="the robot model of the scenario (robot = { model = NAME }; "
                   "default: the scenario default robot)")
    p.add_argument("--start", metavar="X,Y,HEADING", help="start in the world's frame, metres and degrees "
                   "(default: BARN's -2.25,3,90)")
    p.add_argument("--goal", metavar="X,Y[,TOL]", help="goal in the world's frame and its tolerance in metres "
                   "(default: BARN's -2.25,13,1)")
    p.add_argument("--name", help="the scenario's name (default: the file's stem)")
    p.add_argument("--time-limit-s", type=float, help="the run's time limit (default: BARN's 100 s)")
    p.add_argument("--out", metavar="FILE.toml", help="write the scenario here (default: print it)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing --out file")


def _numbers(text: str, option: str, counts: tuple[int, ...]) -> tuple[float, ...]:
    import math
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise ConfigError(option, f"expected comma-separated numbers, got {text!r}") from None
    if len(values) not in counts or not all(math.isfinite(v) for v in values):
        raise ConfigError(option, f"expected {' or '.join(map(str, counts))} finite numbers, got {text!r}")
    return values


def run(args: argparse.Namespace) -> int:
    from swarmnav.models.world_scenario import (BARN_GOAL, BARN_START, BARN_TIME_LIMIT_S, ImportSettings,
                                                import_world, _stem)
    start = _numbers(args.start, "--start", (3,)) if args.start else BARN_START
    goal = _numbers(args.goal, "--goal", (2, 3)) if args.goal else BARN_GOAL
    if len(goal) == 2:
        goal = (*goal, BARN_GOAL[2])
    if args.time_limit_s is not None and not args.time_limit_s > 0:
        raise ConfigError("--time-limit-s", f"must be positive, got {args.time_limit_s:g}")
    if args.out and FilePath(args.out).exists() and not args.overwrite:
        raise ConfigError("--out", "file exists (use --overwrite)", args.out)
    tables = {"robot": {"model": args.robot}} if args.robot else {}
    settings = ImportSettings(name=args.name or _stem(args.world), start=start, goal=goal,
                              time_limit_s=args.time_limit_s or BARN_TIME_LIMIT_S, tables=tables)
    imported = import_world(args.world, settings)
    left_out = ", ".join(f"{n} {why}" for why, n in imported.world.skipped.items())
    note = (f"{args.world}: {len(imported.world.cylinders)} cylinders, {len(imported.world.blocks)} boxes"
            + (f"; not imported: {left_out}" if left_out else ""))
    if args.out:
        FilePath(args.out).write_text(imported.text, encoding="utf-8")
        print(f"{note} -> {args.out}")
    else:
        sys.stdout.write(imported.text)
        print(note, file=sys.stderr)
    return 0
