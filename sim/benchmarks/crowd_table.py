"""The README's CrowdNav table, generated from the committed ``bench navigation --suite crowdnav --json`` result.

``python -m swarmnav.benchmarks.crowd_table [RESULT.json] [--protocol FULL.json] [--paper PAPER.json] [--readme FILE]``
prints (or, with ``--readme``, writes between its markers) the full protocol's tables when there is one
(``crowdnav-500.json``: 500 cases per setting), then every navigator's on a sample of the cases, the rows of the
paper navigators' own result (``crowdnav-paper-navigators.json``: ``iaco_local`` and ``immas_stepwise``, run apart)
in place of the sample's rows of the same label and setting, marked †; per table one
table per setting (the robot invisible to the humans, then visible), our rows
first, then the figures Chen, Liu, Kreiss and Alahi (2019) publish for the same setting (5 ORCA humans, circle
crossing, 500 test cases), under :data:`PUBLISHED_SOURCE`.  ``make readme-table`` runs it; a test fails when the
README and the result differ.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path as FilePath
from typing import Any

from swarmnav.models.errors import ConfigError
from swarmnav.models.marked_block import MarkedBlock
from swarmnav.benchmarks.navigation_table import RESULTS_DIR, read_rows

RESULT = RESULTS_DIR / "crowdnav.json"  # every navigator on a sample of the cases
PROTOCOL = RESULTS_DIR / "crowdnav-500.json"  # CrowdNav's full protocol (500 cases per setting), where it was run
PAPER = RESULTS_DIR / "crowdnav-paper-navigators.json"  # the paper navigators' rows on the sample, run apart
FROM_PAPER = "from_paper_result"  # the key marking a row taken from PAPER
BEGIN = ("<!-- crowdnav-table: generated from models/suites/results/crowdnav.json by `make readme-table`; "
         "do not edit by hand -->")
END = "<!-- end of crowdnav-table -->"
ORACLE = "oracle"

# (success, collision, time to goal s, discomfort frequency); None: not found.  Chen et al. (2019), ICRA,
# Table I (robot invisible) and the visible setting's table, as transcribed by a third-party reading note found
# with `search` (the paper's own table text was not in the corpus: figures not checked against the PDF).
PUBLISHED_SOURCE = ("Chen, Liu, Kreiss and Alahi (2019), Table I and the visible-setting table, as transcribed "
                    "in a third-party reading note (not checked against the paper)")
PUBLISHED = {
    False: [("ORCA", (0.43, 0.57, 10.86, None)), ("CADRL", (0.78, 0.22, 10.80, None)),
            ("LSTM-RL", (0.95, 0.03, 11.82, None)), ("SARL", (1.00, 0.00, 10.55, None))],
    True: [("ORCA", (0.99, None, 12.29, None)), ("CADRL", None), ("LSTM-RL", None), ("SARL", None),
           ("LM-SARL", (1.00, 0.00, 10.59, 0.03))],
}


def _cell(value: Any, spec: str) -> str:
    return "–" if value is None else format(value, spec)


def table_lines(rows: list[dict[str, Any]], seen: bool, published: bool = True) -> list[str]:
    lines = [f"Robot {'visible' if seen else 'invisible'} to the humans"
             + (" (no clairvoyant yardstick: the humans react to the robot)" if seen else "") + ":", "",
             "| method | runs | success | collision | timeout | time to goal s | discomfort | min separation m | "
             "path irregularity rad/m | solved share | × real time (CPU) |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        name = f"{r['navigator']} (clairvoyant yardstick)" if r["navigator"] == ORACLE else f"`{r['navigator']}`"
        if r.get("arm_of"):
            name += f" (`{r['arm_of']}`: " + ", ".join(f"{k}={v}" for k, v in sorted(r["arm_params"].items())) + ")"
        if r.get(FROM_PAPER):
            name += " †"
        solved = r["success_on_solvable"] if r["navigator"] == ORACLE else r.get("solved_share")
        lines.append(f"| {name} | {r['runs']} | {_cell(r['success_rate'], '.3f')} | "
                     f"{_cell(r['collision_rate'], '.3f')} | {_cell(r['timeout_rate'], '.3f')} | "
                     f"{_cell(r['mean_time_to_goal_s'], '.2f')} | "
                     f"{_cell(r['discomfort_frequency'], '.3f')} | {_cell(r['mean_min_separation_m'], '.3f')} | "
                     f"{_cell(r['mean_path_irregularity_rad_m'], '.3f')} | {_cell(solved, '.3f')} | "
                     f"{_cell(r.get('realtime_factor_cpu'), '.1f')} |")
    for method, figures in PUBLISHED[seen] if published else ():
        if figures is None:
            lines.append(f"| {method}, Chen et al. (2019) | 500 | not found | | | | | | | | |")
            continue
        success, collision, time_s, discomfort = figures
        lines.append(f"| {method}, Chen et al. (2019) | 500 | {_cell(success, '.2f')} | {_cell(collision, '.2f')} | "
                     f"– | {_cell(time_s, '.2f')} | {_cell(discomfort, '.2f')} | – | – | – | – |")
    return lines


BEST_TARGET = 0.99  # issue 35: the best navigator's success, with discomfort below DISCOMFORT_TARGET
DISCOMFORT_TARGET = 0.05
ONLINE_TARGET = 0.90  # every online navigator's success
CROWD_TARGET_US = 50.0
REALTIME_TARGET = 30.0


def _online(base: str) -> bool:
    """Whether a navigator (by name) senses the humans: the every-online-navigator target's navigators."""
    from swarmnav.controllers.navigators import NAVIGATORS
    return bool(getattr(NAVIGATORS.get(base), "uses_detections", True))


def online_navigators(rows: list[dict[str, Any]]) -> list[str]:
    """The online navigators (each by name, in the rows' order) that have a row among ``rows``."""
    names = [r.get("arm_of") or r["navigator"] for r in rows if r["navigator"] != ORACLE]
    return [n for n in dict.fromkeys(names) if _online(n)]


def coverage_line(part: list[dict[str, Any]], names: list[str]) -> str:
    """The full protocol's every-online-navigator line: each of ``names`` at its best configuration among
    ``part``'s rows, and those with no row of the full protocol."""
    best_of: dict[str, dict[str, Any]] = {}
    for r in part:
        base = r.get("arm_of") or r["navigator"]
        if r["navigator"] != ORACLE and r["success_rate"] > best_of.get(base, {"success_rate": -1.0})["success_rate"]:
            best_of[base] = r
    ran = [best_of[n] for n in names if n in best_of]
    below = [r for r in ran if r["success_rate"] < ONLINE_TARGET]
    missing = [n for n in names if n not in best_of]
    verdict = "met" if not below and not missing else "not met"
    text = (f"Every online navigator ≥ {ONLINE_TARGET:.2f} on these cases (each at its best configuration here): "
            f"{verdict}; " + ", ".join(f"`{r['navigator']}` {r['success_rate']:.3f}" for r in ran))
    if missing:
        text += "; not run on them: " + ", ".join(f"`{n}`" for n in missing)
    return text + "."


def summary_lines(part: list[dict[str, Any]], seen: bool, every: bool = True,
                  online: list[str] | None = None) -> list[str]:
    """The targets of one setting, computed from its rows (never written by hand); ``every``: the rows hold every
    navigator, so the every-online-navigator lines apply; else, with ``online`` (the names of every online
    navigator), the line says how each of them stands on these rows."""
    from swarmnav.controllers.navigators import NAVIGATORS
    contenders = [r for r in part if r["navigator"] != ORACLE]
    if not contenders:
        return []
    best = max(contenders, key=lambda r: (r["success_rate"], -(r["discomfort_frequency"] or 0.0)))
    met = best["success_rate"] >= BEST_TARGET and (best["discomfort_frequency"] or 0.0) < DISCOMFORT_TARGET
    lines = [f"Robot {'visible' if seen else 'invisible'}: the best, `{best['navigator']}`, succeeds in "
             f"{best['success_rate']:.3f} of its {best['runs']} runs with discomfort "
             f"{best['discomfort_frequency']:.4f} (target ≥ {BEST_TARGET:.2f} with discomfort < "
             f"{DISCOMFORT_TARGET:.2f}: {'met' if met else 'not met'})."]
    if not every and online:
        lines.append(coverage_line(part, online))
    elif not every:
        lines.append("Every online navigator ≥ 0.90: see the sample below (the full protocol ran "
                     + ", ".join(f"`{r['navigator']}`" for r in contenders) + " only).")
    online = [] if not every else [r for r in contenders if not r.get("arm_of")
              and getattr(NAVIGATORS.get(r["navigator"]), "uses_detections", True)]
    below = [r for r in online if r["success_rate"] < ONLINE_TARGET]
    if every:
        lines.append(f"Every online navigator at its defaults ≥ {ONLINE_TARGET:.2f}: " + (
            "met." if not below else "not met: " + ", ".join(f"`{r['navigator']}` {r['success_rate']:.3f}"
                                                             for r in below) + "."))
    if every and any(r.get("arm_of") for r in contenders):  # each navigator at its best configuration of the rows
        best_of: dict[str, dict[str, Any]] = {}
        for r in contenders:
            base = r.get("arm_of") or r["navigator"]
            if getattr(NAVIGATORS.get(base), "uses_detections", True) and \
                    r["success_rate"] > best_of.get(base, {"success_rate": -1.0})["success_rate"]:
                best_of[base] = r
        below = [r for r in best_of.values() if r["success_rate"] < ONLINE_TARGET]
        lines.append(f"Every online navigator at its defaults or in a named configuration above ≥ "
                     f"{ONLINE_TARGET:.2f}: " + ("met." if not below else "not met: " + ", ".join(
                         f"`{r['navigator']}` {r['success_rate']:.3f}" for r in below) + "."))
    timed = [r for r in part if r.get("realtime_factor_cpu") is not None]
    if timed:
        slow = min(timed, key=lambda r: r["realtime_factor_cpu"])
        verdict = "met" if slow["realtime_factor_cpu"] >= REALTIME_TARGET else "not met"
        lines.append(f"Real time on CPU: every row at {slow['realtime_factor_cpu']:.1f}× or more "
                     f"(`{slow['navigator']}` the slowest; target ≥ {REALTIME_TARGET:g}×: {verdict}).")
    crowd = next((r["crowd_step"] for r in part if r.get("crowd_step")), None)
    if crowd:
        worst = max(crowd[k]["cpu_us_per_agent_step"] for k in ("orca", "social_force"))
        lines.append(f"Agents: {crowd['orca']['cpu_us_per_agent_step']:.1f} µs (ORCA) and "
                     f"{crowd['social_force']['cpu_us_per_agent_step']:.1f} µs (social force) of CPU per agent per "
                     f"control step with {crowd['agents']} agents (target ≤ {CROWD_TARGET_US:g} µs: "
                     f"{'met' if worst <= CROWD_TARGET_US else 'not met'}).")
    return lines


def _cases(rows: list[dict[str, Any]]) -> str:
    runs = sorted({r["runs"] for r in rows if r["navigator"] != ORACLE})
    return " or ".join(str(n) for n in runs)


def merged(rows: list[dict[str, Any]], paper: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """``rows`` with each of ``paper``'s rows (but its oracle's) in place of the row of the same label and
    setting, or after the last navigator's row of its setting when there is none; taken rows are marked
    (:data:`FROM_PAPER`)."""
    out = list(rows)
    for r in paper:
        if r["navigator"] == ORACLE:
            continue
        taken = {**r, FROM_PAPER: True}
        same = [i for i, o in enumerate(out) if o["navigator"] == r["navigator"]
                and o.get("robot_visible") is r.get("robot_visible")]
        if same:
            out[same[0]] = taken
            continue
        last = [i for i, o in enumerate(out)
                if o["navigator"] != ORACLE and o.get("robot_visible") is r.get("robot_visible")]
        out.insert(last[-1] + 1 if last else len(out), taken)
    return out


def block(rows: list[dict[str, Any]], protocol: list[dict[str, Any]] | None = None,
          paper: list[dict[str, Any]] | None = None) -> str:
    """The generated text: ``protocol`` (CrowdNav's 500 cases per setting, beside the published figures) first
    when given, then ``rows`` (every navigator on a sample of the cases) with ``paper``'s rows (see
    :func:`merged`)."""
    rows = merged(rows, paper or [])
    out = [BEGIN, ""]
    if protocol:
        out += [f"**CrowdNav's protocol**: {_cases(protocol)} test cases per setting "
                f"(`{PROTOCOL.relative_to(RESULTS_DIR.parents[2]).as_posix()}`).", ""]
        for seen in (False, True):
            part = [r for r in protocol if r.get("robot_visible") is seen]
            if part:
                online = online_navigators([r for r in rows if r.get("robot_visible") is seen])
                out += table_lines(part, seen) + [""] + summary_lines(part, seen, every=False, online=online) + [""]
        out += [f"**Every navigator** on {_cases(rows)} of the 500 test cases per setting "
                f"(`{RESULT.relative_to(RESULTS_DIR.parents[2]).as_posix()}`).", ""]
    for seen in (False, True):
        part = [r for r in rows if r.get("robot_visible") is seen]
        if part:
            out += table_lines(part, seen, published=not protocol) + [""] + summary_lines(part, seen) + [""]
    if any(r.get(FROM_PAPER) for r in rows):
        out += [f"† From `{PAPER.relative_to(RESULTS_DIR.parents[2]).as_posix()}` (the paper navigators' rows on the "
                "same cases, run apart), in place of this file's row of the same label.", ""]
    out += [f"Published figures: {PUBLISHED_SOURCE}; their robot is holonomic, ours a differential drive in "
            "MuJoCo.", "", END]
    return "\n".join(out)


MARKERS = MarkedBlock(BEGIN, END, "crowdnav-table markers")
current_block = MARKERS.current


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m swarmnav.benchmarks.crowd_table",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("result", nargs="?", default=str(RESULT), help="a `bench navigation --suite crowdnav --json`")
    parser.add_argument("--protocol", default=str(PROTOCOL) if PROTOCOL.is_file() else None,
                        help="the full protocol's result, shown first (default: models/suites/results/"
                             "crowdnav-500.json when it exists)")
    parser.add_argument("--paper", default=str(PAPER) if PAPER.is_file() else None,
                        help="the paper navigators' rows, in place of the sample's of the same label (default: "
                             "models/suites/results/crowdnav-paper-navigators.json when it exists)")
    parser.add_argument("--readme", help="replace the table between the markers in this file")
    args = parser.parse_args(argv)
    try:
        rows = read_rows(FilePath(args.result))
        protocol = read_rows(FilePath(args.protocol)) if args.protocol else None
        paper = read_rows(FilePath(args.paper)) if args.paper else None
        for name, found in ((args.result, rows), (args.protocol, protocol or [{"robot_visible": 0}]),
                            (args.paper, paper or [{"robot_visible": 0}])):
            if not any("robot_visible" in r for r in found):
                raise ConfigError("crowdnav table", "has no robot_visible rows (not a --suite crowdnav result)",
                                  name)
        generated = block(rows, protocol, paper)
        if args.readme:
            path = FilePath(args.readme)
            path.write_text(MARKERS.replace(path.read_text(encoding="utf-8"), generated, args.readme),
                            encoding="utf-8")
        else:
            print(generated)
    except ConfigError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
