"""The README's navigation table, generated from a committed ``bench navigation --json`` result.

``python -m swarmnav.sim.benchmarks.navigation_table [RESULT.json] [--readme FILE]`` prints the table (one row
per navigator and the oracle's, from the overall rows of the JSON that ``swarmnav bench navigation --suite
dyn300 --json`` printed); with ``--readme FILE`` it replaces the lines between :data:`BEGIN` and :data:`END`
in FILE instead.  The committed result is :data:`RESULT` (``models/suites/results/dyn300.json``); ``make
readme-table`` regenerates the README's table from it (the run itself is long and is not part of the target).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path as FilePath
from typing import Any

from swarmnav.models.errors import ConfigError

BEGIN = "<!-- navigation-table: generated from models/suites/results/dyn300.json by `make readme-table`; do not edit by hand -->"
END = "<!-- end of navigation-table -->"
RESULT = FilePath(__file__).resolve().parents[2] / "models" / "suites" / "results" / "dyn300.json"
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


def block(rows: list[dict[str, Any]]) -> str:
    return "\n".join([BEGIN, ""] + table_lines(rows) + ["", END])


def current_block(text: str) -> str | None:
    start, end = text.find(BEGIN), text.find(END)
    return None if start < 0 or end < start else text[start:end + len(END)]


def replace_block(text: str, new_block: str, source: str) -> str:
    start, end = text.find(BEGIN), text.find(END)
    if start < 0 or end < start:
        raise ConfigError("--readme", "has no navigation-table markers", source)
    return text[:start] + new_block + text[end + len(END):]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m swarmnav.sim.benchmarks.navigation_table",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("result", nargs="?", default=str(RESULT), help="a `bench navigation --json` result")
    parser.add_argument("--readme", help="replace the table between the markers in this file")
    args = parser.parse_args(argv)
    try:
        generated = block(read_rows(FilePath(args.result)))
        if args.readme:
            path = FilePath(args.readme)
            path.write_text(replace_block(path.read_text(encoding="utf-8"), generated, args.readme), encoding="utf-8")
        else:
            print(generated)
    except ConfigError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
