"""``swarmnav bench cli``: the whole ``swarmnav scenarios`` process against a bare ``python -c pass``.

Each kind of process is started ``--runs`` times, interleaved (bare, ``swarmnav
--help``, ``swarmnav scenarios``), with the same interpreter and environment;
the figures are medians of wall time from ``Popen`` to exit.  ``--help`` builds
the whole parser and nothing else; ``scenarios`` also loads and checks every
bundled scenario.  Target (issue 14): ``scenarios`` under 0.3 s; the excess
over the bare interpreter is the part this project owns.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

from swarmnav.benchmarks.figures import print_figures

TARGET_SCENARIOS_S = 0.3


def _command() -> list[str]:
    """The console script beside this interpreter, else the module (the same ``main``)."""
    script = Path(sys.executable).parent / "swarmnav"
    return [str(script)] if script.exists() else [sys.executable, "-m", "swarmnav.cli"]


def _wall_s(argv: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    return time.perf_counter() - t0


def benchmark_cli(runs: int) -> dict[str, float | int | bool]:
    kinds = {"bare": [sys.executable, "-c", "pass"], "help": _command() + ["--help"],
             "scenarios": _command() + ["scenarios"]}
    for argv in kinds.values():  # warm the file cache and the bytecode once
        _wall_s(argv)
    times: dict[str, list[float]] = {kind: [] for kind in kinds}
    for _ in range(runs):
        for kind, argv in kinds.items():
            times[kind].append(_wall_s(argv))
    bare, help_s, scenarios = (statistics.median(times[k]) for k in ("bare", "help", "scenarios"))
    return {"runs": runs, "bare_python_s": bare, "help_s": help_s, "scenarios_s": scenarios,
            "scenarios_over_bare_s": scenarios - bare, "help_over_bare_s": help_s - bare,
            "scenarios_vs_bare": scenarios / bare, "target_scenarios_s": TARGET_SCENARIOS_S,
            "meets_target": scenarios < TARGET_SCENARIOS_S}


def run(args: argparse.Namespace) -> int:
    print_figures(benchmark_cli(3 if args.quick else args.runs), args.json)
    return 0
