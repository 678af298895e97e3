"""The ``swarmnav study``, ``studies`` and ``report`` subcommands.

Heavy modules (the engines, pyarrow, matplotlib, Ray) are imported inside the run
functions, so that building the parser (every ``swarmnav`` command) stays fast.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path as FilePath

from swarmnav.sim import options  # noqa: E402  (light: argparse types only)
from swarmnav.sim.defaults import LOG_FORMATS

WORKERS_PER_CORE = 8  # --workers at most this many per core of the machine


def add_study_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="bundled study name (see `swarmnav studies`) or path to a study .toml")
    p.add_argument("--out", type=options.output_path, help="directory of the rows (default: studies/<study name>); run again to resume")
    p.add_argument("--workers", type=int, help="worker processes, or local Ray CPUs (default: the number of cores)")
    p.add_argument("--engine", choices=("local", "ray"), default="local",
                   help="local processes, or Ray tasks (needs the ray extra: pip install 'swarmnav[ray]')")
    p.add_argument("--address", help="with --engine ray: the cluster to join (default: a local instance)")
    p.add_argument("--logs", action="store_true", help="keep the MCAP log of every physics run in DIR/logs/")
    p.add_argument("--log-format", choices=LOG_FORMATS, default="swarmnav",
                   help="with --logs: swarmnav (Foxglove's schemas) or ros2 (CDR, standard ROS 2 types)")
    p.add_argument("--quick", action="store_true",
                   help="only the study's first quick_seeds seeds (a later full run into the same --out resumes)")
    p.add_argument("--claims-only", action="store_true",
                   help="only the arms the study's [[claims]] compare (their cells are the full study's: a later "
                        "full run into the same --out resumes)")
    p.add_argument("--retry-errors", action="store_true",
                   help="run again the cells whose row is an error (by default a resume runs only cells without a row)")
    p.add_argument("--json", action="store_true", help="print one JSON summary; no progress bar")
    from swarmnav.sim.options import add_trust_code_argument
    add_trust_code_argument(p)
    p.add_argument("--junit", type=options.output_path, metavar="FILE", help="write the study's rows as JUnit XML (one test suite per scenario, "
                   "a failure per row that is not a success)")
    p.add_argument("--min-success", type=_rate, metavar="RATE",
                   help="exit 5 when a configuration's (scenario, planner, navigator) success rate is below RATE")


def _rate(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a rate in [0, 1], got {text!r}") from None
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"expected a rate in [0, 1], got {text!r}")
    return value


def _first_stop(exc: BaseException) -> BaseException:
    """The Ctrl-C or SIGTERM that stopped the study: a native library may turn the CLI's ``SystemExit(143)``
    into one of its own on the way out (Ray's ``wait`` raises ``SystemExit(1)`` when a signal interrupts it),
    so the signal the CLI's handler recorded wins."""
    from swarmnav.cli import stop_signal
    if isinstance(exc, SystemExit) and stop_signal.received is not None:
        return SystemExit(128 + stop_signal.received)
    return exc


def run_study(args: argparse.Namespace) -> int:
    from swarmnav.models.errors import ConfigError
    from swarmnav.study.spec import load_study
    if args.workers is not None and args.workers < 1:
        raise ConfigError("--workers", f"must be at least 1, got {args.workers}")
    most = WORKERS_PER_CORE * (os.cpu_count() or 1)
    if args.workers is not None and args.workers > most:
        raise ConfigError("--workers", f"at most {most} ({WORKERS_PER_CORE} per core: each worker is a process of "
                                       f"its own), got {args.workers}")
    if args.address and args.engine != "ray":
        raise ConfigError("--address", "needs --engine ray")
    if args.engine == "ray":
        try:
            import ray  # noqa: F401
        except ImportError:
            raise ConfigError("--engine", "ray is not installed (pip install 'swarmnav[ray]')") from None
    from swarmnav.sim.options import check_output_file
    check_output_file(args.junit, "--junit")
    study = load_study(args.file, trust_code=args.trust_code)
    if args.quick:
        if study.quick_seeds is None:
            print(f"swarmnav: warning: study {study.name!r} has no quick_seeds: --quick runs the full study",
                  file=sys.stderr)
        study = study.quick()
    if args.claims_only:
        if not study.claims:
            raise ConfigError("--claims-only", f"study {study.name!r} has no [[claims]]")
        study = study.claims_only()
    from swarmnav.study.execute import run_study as execute
    out = args.out or str(FilePath("studies") / study.name)
    try:
        summary = execute(study, out, engine=args.engine, workers=args.workers, address=args.address,
                          logs=args.log_format if args.logs else False,
                          show_progress=not args.json and sys.stderr.isatty(), retry_errors=args.retry_errors)
    except (KeyboardInterrupt, SystemExit) as exc:  # Ctrl-C, or SIGTERM (the CLI's handler raises SystemExit)
        exc = _first_stop(exc)
        how = "Ctrl-C" if isinstance(exc, KeyboardInterrupt) else "SIGTERM" if exc.code == 143 else f"exit {exc.code}"
        print(f"swarmnav: study stopped ({how}); the rows of the finished cells are kept in {out}: run the same "
              "command to resume", file=sys.stderr)
        if isinstance(exc, KeyboardInterrupt):
            return 130
        raise exc from None
    if args.json:
        print(json.dumps(summary))
    else:
        print(f"{summary['study']}: {summary['cells']} cells, {summary['skipped']} already in {summary['out']}, "
              f"ran {summary['ran']} in {summary['wall_s']:.1f} s on {summary['engine']}; "
              f"{summary['failed']} failed "
              + (f"({', '.join(f'{k} {v}' for k, v in sorted(summary['outcomes'].items()) if k != 'ok')})"
                 if summary["failed"] else ""))
        print(f"rows: {FilePath(out) / 'runs.parquet'}  report: swarmnav report {out}")
    return _ci_checks(args, study.name, out)


def _ci_checks(args: argparse.Namespace, study: str, out: str) -> int:
    """``--junit`` and ``--min-success`` over every row of the folder (this run's and earlier ones')."""
    if not args.junit and args.min_success is None:
        return 0
    from swarmnav.study.junit import success_shortfalls, write_junit
    from swarmnav.study.rows import read_table
    rows = read_table(out).to_pylist()
    if args.junit:
        write_junit(study, rows, args.junit)
        print(f"junit: {args.junit}", file=sys.stderr if args.json else sys.stdout)
    if args.min_success is not None:
        shortfalls = success_shortfalls(rows, args.min_success)
        for line in shortfalls:
            print(f"swarmnav: expectation not met: --min-success: {line}", file=sys.stderr)
        if shortfalls:
            return 5
    return 0


def add_studies_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true")


def run_studies(args: argparse.Namespace) -> int:
    from swarmnav.study.grid import count_cells
    from swarmnav.study.spec import list_studies, load_study
    rows = []
    for name in list_studies():
        study = load_study(name)
        rows.append({"name": name, "mode": study.mode, "cells": count_cells(study),
                     "scenarios": [FilePath(s).stem for s in study.scenarios],
                     "planners": [p.label for p in study.planners], "claims": len(study.claims),
                     "description": study.description})
    if args.json:
        print(json.dumps(rows))
    else:
        for r in rows:
            print(f"{r['name']:<24} {r['mode']:<8} {r['cells']:>5} runs  {r['description']}")
    return 0


def add_report_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("dir", nargs="?", help="a study's output directory (holding runs.parquet)")
    p.add_argument("--out", type=options.output_path, help="HTML report path (default: DIR/report.html); the Markdown twin and claims.json "
                                 "go beside it")
    p.add_argument("--json", action="store_true", help="print the claims' verdicts (claims.json) instead")
    p.add_argument("--readme-table", nargs="+", metavar="PATH",
                   help="print the README's table of claims from these claims.json files (or folders holding them, "
                        "e.g. models/studies/results) instead of a report")
    p.add_argument("--readme", help="with --readme-table: replace the table in this README file instead")
    p.add_argument("--check-fresh", nargs="+", metavar="PATH",
                   help="check that these claims.json files (or folders of them, e.g. models/studies/results) were "
                        "produced by today's study files, component sources, scenarios and swarmnav version: "
                        "exit 5 naming each stale claim and what changed, 0 when all are fresh")
    p.add_argument("--names", action="store_true", help="with --check-fresh: print only the stale studies' names")
    p.add_argument("--ompl-log", type=options.output_path, metavar="OUT",
                    help="also write the rows as OMPL benchmark logs, OUT/<scenario>.log "
                   "(one experiment each), for `ompl_benchmark_statistics OUT/*.log -d bench.db` and Planner Arena")


def _readme_table(args: argparse.Namespace) -> int:
    from swarmnav.study.readme_table import block, read_documents, replace_block
    text = block(read_documents(args.readme_table))
    if args.readme:
        path = FilePath(args.readme)
        path.write_text(replace_block(path.read_text(encoding="utf-8"), text, str(path)), encoding="utf-8")
        print(f"claims table: {path}")
    else:
        print(text)
    return 0


def _check_fresh(args: argparse.Namespace) -> int:
    from swarmnav.study.provenance import check_fresh
    lines, stale, notes = check_fresh(args.check_fresh)
    if args.names:
        print(" ".join(stale))
        return 5 if stale else 0
    for line in lines:
        print(line)
    for note in notes:
        print(f"note: {note} (a dependency's version differs; not counted as stale)")
    if not stale:
        print("fresh: every claims.json matches today's inputs")
    return 5 if stale else 0


def run_report(args: argparse.Namespace) -> int:
    from swarmnav.models.errors import ConfigError
    if args.check_fresh:
        return _check_fresh(args)
    if args.names:
        raise ConfigError("--names", "needs --check-fresh")
    if args.readme_table:
        return _readme_table(args)
    if args.readme:
        raise ConfigError("--readme", "needs --readme-table")
    if args.dir is None:
        raise ConfigError("dir", "is required (a study's output directory), unless --readme-table")
    from swarmnav.study.report import write_report
    directory = FilePath(args.dir)
    if not (directory / "runs.parquet").is_dir():
        raise ConfigError("dir", "holds no runs.parquet (run `swarmnav study` first)", str(directory))
    html_path = FilePath(args.out) if args.out else directory / "report.html"
    markdown_path = write_report(directory, html_path)
    claims_path = html_path.parent / "claims.json"
    if args.json:
        print(claims_path.read_text(encoding="utf-8"), end="")
    else:
        print(f"report: {html_path}  markdown: {markdown_path}  claims: {claims_path}")
    if args.ompl_log:
        from swarmnav.study.ompl_log import write_ompl_logs
        logs = write_ompl_logs(directory, args.ompl_log)
        print(f"OMPL logs: {len(logs)} in {args.ompl_log}  (ompl_benchmark_statistics {args.ompl_log}/*.log -d bench.db)",
              file=sys.stderr if args.json else sys.stdout)
    return 0
