"""The README's navigation tables, generated from committed ``bench navigation --json`` results.

``python -m swarmnav.benchmarks.navigation_table [RESULT.json] [--readme FILE]`` prints the table (one row
per navigator and the oracle's, from the overall rows of the JSON that ``swarmnav bench navigation [--suite
dyn300] --json`` printed); with ``--readme FILE`` it replaces the lines between the markers that name that
result (:func:`begin_marker`, :data:`END`) in FILE instead.  The committed results are :data:`RESULTS`
(``models/suites/results/dyn300.json``: the 300-scene suite; ``dyn.json``: the bundled ``dyn-*`` scenes;
``dyn300-rangefinder.json``: the 300 scenes with the 12 rangefinders at 1 m); ``make
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
from swarmnav.models.marked_block import MarkedBlock

END = "<!-- end of navigation-table -->"
RESULTS_DIR = FilePath(__file__).resolve().parents[2] / "models" / "suites" / "results"
RESULT = RESULTS_DIR / "dyn300.json"
RESULTS = (RESULT, RESULTS_DIR / "dyn.json", RESULTS_DIR / "dyn300-rangefinder.json")


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
        name = (f"{r['navigator']} (clairvoyant yardstick)" if r["navigator"] == ORACLE
                else f"{r['navigator']} ({_arm_text(r)})" if r.get("arm_of") else r["navigator"])
        lines.append(f"| {name} | {r['runs']} | {_cell(r['success_rate'], '.3f')} | {_cell(r['collision_rate'], '.3f')} | "
                     f"{_cell(r['timeout_rate'], '.3f')} | {r['oracle_solvable_runs']} | **{_cell(solved, '.3f')}** | "
                     f"{_cell(r['time_score'], '.3f')} | {_cell(r['mean_spl'], '.3f')} | "
                     f"{_cell(r['mean_spl_solvable'], '.3f')} | {_cell(r['navigator_us_per_step'], '.0f')} | "
                     f"{_cell(r['realtime_factor'], '.1f')} |")
    return lines


def _arm_text(row: dict[str, Any]) -> str:
    """An arm's navigator and parameters, as ``--arm`` wrote them: ``iaco_local: evade=true``."""
    params = ", ".join(f"{k}={json.dumps(v)}" for k, v in sorted((row.get("arm_params") or {}).items()))
    return f"{row['arm_of']}: {params}" if params else row["arm_of"]


# Issue 23's targets, by the sensing of the run: the best navigator's share of the oracle-solvable scenes
# solved, and every online navigator's (one that reads detections; ``follow`` never does).
BEST_TARGET = {"detector": 0.95, "rangefinder": 0.85}
EVERY_ONLINE_TARGET = {"detector": 0.80}


def _met(value: float, target: float) -> str:
    return f"target ≥ {target:.2f}: {'met' if value >= target else 'not met'}"


def summary_lines(rows: list[dict[str, Any]]) -> list[str]:
    """The sentences the README prints under a table, computed from its rows (never written by hand): the best
    navigator's solved share, every online navigator's against its target (with its arms beside it), and the
    oracle's validation."""
    from swarmnav.controllers.navigators import NAVIGATORS
    sensing = rows[0].get("sensor_model") if rows else None
    contenders = [r for r in rows if r["navigator"] != ORACLE and r.get("solved_share") is not None]
    if not contenders:
        return []
    best = max(contenders, key=lambda r: (r["solved_share"], r["time_score"] or 0.0))
    text = (f"Sensing: {sensing or 'each scene its own'}. The best navigator, `{best['navigator']}`, solves "
            f"{best['solved_share']:.3f} of the oracle-solvable runs")
    if sensing in BEST_TARGET:
        text += f" ({_met(best['solved_share'], BEST_TARGET[sensing])})"
    lines = [text + "."]
    online = [r for r in contenders if getattr(NAVIGATORS.get(r.get("arm_of") or r["navigator"]),
                                               "uses_detections", True)]
    target = EVERY_ONLINE_TARGET.get(sensing)
    if target is not None:
        below = [r for r in online if not r.get("arm_of") and r["solved_share"] < target]
        parts = []
        for r in below:
            arms = [a for a in online if a.get("arm_of") == r["navigator"]]
            best_arm = max(arms, key=lambda a: a["solved_share"]) if arms else None
            parts.append(f"`{r['navigator']}` {r['solved_share']:.3f}" + (
                f" (as `{best_arm['navigator']}`: {best_arm['solved_share']:.3f})" if best_arm else ""))
        lines.append(f"Every online navigator at its defaults ≥ {target:.2f}: "
                     + ("met." if not below else "not met: " + "; ".join(parts) + "."))
    oracle = next((r for r in rows if r["navigator"] == ORACLE), None)
    lines += _speed_sentence(rows, oracle)
    if oracle is not None and oracle.get("success_on_solvable") is not None:
        lines.append(f"The oracle called {oracle['oracle_solvable_runs']} of {oracle['runs']} runs solvable and "
                     f"succeeded in physics on {oracle['success_on_solvable']:.3f} of them "
                     f"({_met(oracle['success_on_solvable'], 0.95)}).")
    return lines


def _speed_sentence(rows: list[dict[str, Any]], oracle: dict[str, Any] | None) -> list[str]:
    """The run's speed against issue 23's targets, from its speed figures (absent from a result without them):
    the slowest row's real-time factor on CPU, MPPI's CPU per control step, the oracle's longest search."""
    parts = []
    timed = [r for r in rows if r.get("realtime_factor_cpu") is not None]
    if timed:
        slow = min(timed, key=lambda r: r["realtime_factor_cpu"])
        parts.append(f"every row at {slow['realtime_factor_cpu']:.1f}× real time or more on CPU (`{slow['navigator']}` "
                     f"the slowest; target ≥ 30×)")
    mppi = next((r["mppi_every_step"] for r in rows if r.get("mppi_every_step")), None)
    if mppi:
        parts.append(f"`mppi` {mppi['cpu_us_per_step']:.0f} µs of CPU per control step optimising every step "
                     "(target ≤ 1,000)")
    if oracle is not None and oracle.get("oracle_search"):
        parts.append(f"the oracle's search at most {oracle['oracle_search']['max_s']:.2f} s a scene (target < 2 s)")
    return ["Speed (wall-clock figures depend on the load): " + "; ".join(parts) + "."] if parts else []


def block(rows: list[dict[str, Any]], result: FilePath = RESULT) -> str:
    summary = summary_lines(rows)
    return "\n".join([begin_marker(result), ""] + table_lines(rows) + ([""] + summary if summary else [])
                     + ["", END])


def markers(result: FilePath = RESULT) -> MarkedBlock:
    """The block of ``result``'s table in a page."""
    return MarkedBlock(begin_marker(result), END, f"navigation-table markers for {FilePath(result).name}")


def current_block(text: str, result: FilePath = RESULT) -> str | None:
    return markers(result).current(text)


def replace_block(text: str, new_block: str, source: str, result: FilePath = RESULT) -> str:
    return markers(result).replace(text, new_block, source)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m swarmnav.benchmarks.navigation_table",
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
