"""The README's navigation tables, generated from committed ``bench navigation --json`` results.

``python -m swarmnav.sim.benchmarks.navigation_table [RESULT.json] [--readme FILE]`` prints the table (one row
per navigator and the oracle's, from the overall rows of the JSON that ``swarmnav bench navigation [--suite
dyn300] --json`` printed); with ``--readme FILE`` it replaces the lines between the markers that name that
result (:func:`begin_marker`, :data:`END`) in FILE instead.  The committed results are :data:`RESULTS`
(``models/suites/results/dyn300.json``: the 300-scene suite; ``dyn.json``: the bundled ``dyn-*`` scenes); ``make
readme-table`` regenerates the README's tables from them (the runs themselves are long and are not part of the
target).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path as FilePath
from typing import Any

from swarmnav.models.errors import ConfigError

END = "<!-- end of navigation-table -->"
RESULTS_DIR = FilePath(__file__).resolve().parents[2] / "models" / "suites" / "results"
RESULT = RESULTS_DIR / "dyn300.json"
RESULTS = (RESULT, RESULTS_DIR / "dyn.json")


def begin_marker(result: FilePath) -> str:
    """The README marker opening the table generated from ``result`` (named by its file name)."""
    return (f"<!-- navigation-table: generated from models/suites/results/{FilePath(result).name} by "
            "`make readme-table`; do not edit by hand -->")
ORACLE = "oracle"


def read_rows(path: FilePath) -> list[dict[str, Any]]:
    """The overall rows (``scenario`` null) of a ``bench navigation --json`` result."""
    try:
        rows = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ConfigError("navigation table", f"cannot read a bench navigation result ({exc})", str(path)) from None
    if not isinstance(rows, list) or not all(isinstance(r, dict) and "navigator" in r for r in rows):
        raise ConfigError("navigation table", "is not a `bench navigation --json` result (a list of rows)", str(path))
    return [r for r in rows if r.get("scenario") is None]


def _cell(value: Any, spec: str) -> str:
    return "–" if value is None else format(value, spec)


def table_lines(rows: list[dict[str, Any]]) -> list[str]:
    lines = ["| navigator | runs | success | collisions | timeouts | oracle-solvable | solved share | time score | "
             "SPL | SPL (solvable) | µs/step | × real time |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        solved = r["success_on_solvable"] if r["navigator"] == ORACLE else r["solved_share"]
        name = f"{r['navigator']} (clairvoyant yardstick)" if r["navigator"] == ORACLE else r["navigator"]
        lines.append(f"| {name} | {r['runs']} | {_cell(r['success_rate'], '.3f')} | {_cell(r['collision_rate'], '.3f')} | "
                     f"{_cell(r['timeout_rate'], '.3f')} | {r['oracle_solvable_runs']} | **{_cell(solved, '.3f')}** | "
                     f"{_cell(r['time_score'], '.3f')} | {_cell(r['mean_spl'], '.3f')} | "
                     f"{_cell(r['mean_spl_solvable'], '.3f')} | {_cell(r['navigator_us_per_step'], '.0f')} | "
                     f"{_cell(r['realtime_factor'], '.1f')} |")
    return lines


def block(rows: list[dict[str, Any]], result: FilePath = RESULT) -> str:
    return "\n".join([begin_marker(result), ""] + table_lines(rows) + ["", END])


def _span(text: str, result: FilePath) -> tuple[int, int]:
    start = text.find(begin_marker(result))
    end = text.find(END, start) if start >= 0 else -1
    return start, end


def current_block(text: str, result: FilePath = RESULT) -> str | None:
    start, end = _span(text, result)
    return None if start < 0 or end < start else text[start:end + len(END)]


def replace_block(text: str, new_block: str, source: str, result: FilePath = RESULT) -> str:
    start, end = _span(text, result)
    if start < 0 or end < start:
        raise ConfigError("--readme", f"has no navigation-table markers for {FilePath(result).name}", source)
    return text[:start] + new_block + text[end + len(END):]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m swarmnav.sim.benchmarks.navigation_table",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("result", nargs="?", default=str(RESULT), help="a `bench navigation --json` result")
    parser.add_argument("--readme", help="replace the table between the markers in this file")
    args = parser.parse_args(argv)
    try:
        result = FilePath(args.result)
        generated = block(read_rows(result), result)
        if args.readme:
            path = FilePath(args.readme)
            path.write_text(replace_block(path.read_text(encoding="utf-8"), generated, args.readme, result),
                            encoding="utf-8")
        else:
            print(generated)
    except ConfigError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
