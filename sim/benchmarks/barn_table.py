"""The BARN page's tables (``docs/barn.md``, once the README's), generated from the committed ``bench
navigation --suite barn --by-scenario --json`` results (``models/suites/results/barn*.json``) beside the
published figures.

``python -m swarmnav.benchmarks.barn_table [--readme FILE]`` prints the block (or replaces it between its
markers in FILE: ``docs/barn.md``); ``make readme-table`` runs it; ``tests/test_barn_table.py`` fails when the
page drifts from the JSON.  Every figure in the block is read from a result file or is a published one cited
beside it.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path as FilePath
from typing import Any

from swarmnav.models.errors import ConfigError
from swarmnav.models.marked_block import MarkedBlock

RESULTS_DIR = FilePath(__file__).resolve().parents[2] / "models" / "suites" / "results"
LISTED = (RESULTS_DIR / "barn-test50.json", RESULTS_DIR / "barn-test10-dwa-vo.json", RESULTS_DIR / "barn.json",
          RESULTS_DIR / "barn-like.json", RESULTS_DIR / "barn-jackal-test10.json",
          RESULTS_DIR / "barn-protocol-test10.json", RESULTS_DIR / "barn-protocol-test10-more.json",
          RESULTS_DIR / "barn-protocol-test50.json", RESULTS_DIR / "barn-like-protocol.json",
          RESULTS_DIR / "barn-like-protocol-navigators.json")
# then every other committed protocol result (barn-protocol-<navigator or label>.json), by name
RESULTS = LISTED + tuple(sorted(p for p in RESULTS_DIR.glob("barn-protocol-*.json") if p not in LISTED))
# compared: each BARN-like result (fresh worlds) against BARN's in its own setup (the 300 first: barn.json, then
# every navigator's all-300 protocol result; then 50 test worlds)
BARN_300, BARN_50 = (RESULTS[2],) + tuple(p for p in RESULTS if p.name.startswith("barn-protocol-all-")), (RESULTS[0], RESULTS[7])
FRESH = (RESULTS[3], RESULTS[8], RESULTS[9])
BEGIN = "<!-- barn-table: generated from models/suites/results/barn*.json by `make readme-table`; do not edit by hand -->"
END = "<!-- end of barn-table -->"
ORACLE = "oracle"
ONLINE_TARGET = 0.88  # issue 34: every online navigator's success, the published move_base DWA's
PROTOCOL_RUNS = 500   # the challenge's 50 test worlds x 10 runs
NOT_ONLINE = ("policy",)  # runs a policy the user supplies (--trust-code): no navigator of its own
CONFIGURATIONS = RESULTS_DIR.parent / "barn-navigators.toml"  # each navigator's BARN configuration, one entry each
# Published, on the same 50 test worlds x 10 runs (the challenge's report_test.py): the challenge repository's
# README (Daffan/the-barn-challenge at bf5a226f), as quoted in ../shared/benchmarks/barn/README.md.
PUBLISHED = [{"entry": "move_base + DWA, Gazebo, Jackal, map unknown (the challenge's baseline)",
              "source": "Daffan/the-barn-challenge README (commit bf5a226f), via ../shared/benchmarks/barn/README.md",
              "runs": 500, "success_rate": 0.88, "collision_rate": 0.048, "timeout_rate": 0.072,
              "barn_score": 0.1693, "mean_time_s": 33.47}]


def read_result(path: FilePath) -> list[dict[str, Any]]:
    try:
        rows = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ConfigError("barn table", f"cannot read a bench navigation result ({exc})", str(path)) from None
    if not isinstance(rows, list) or not all(isinstance(r, dict) and "barn_score" in r for r in rows):
        raise ConfigError("barn table", "is not a `bench navigation --suite barn --json` result", str(path))
    return rows


def _f(value: Any, spec: str) -> str:
    return "–" if value is None else format(value, spec)


def _worlds_runs(rows: list[dict[str, Any]]) -> tuple[int, int]:
    per_run = [r for r in rows if r.get("scenario") is not None]
    worlds = {r["world"] for r in per_run}
    runs = {(r["world"], r["run"]) for r in per_run}
    return len(worlds), (len(runs) // len(worlds) if worlds else 0)


def result_lines(path: FilePath, rows: list[dict[str, Any]]) -> list[str]:
    overall = [r for r in rows if r.get("scenario") is None]
    worlds, runs = _worlds_runs(rows)
    setup = overall[0]["barn_setup"] if overall else ""
    lines = [f"**`{path.name}`**: {worlds} worlds x {runs} run(s) each; {setup}.", "",
             "| navigator | runs | success | collisions | timeouts | BARN score | mean time to goal s |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for r in overall:
        name = f"{r['navigator']} (clairvoyant yardstick)" if r["navigator"] == ORACLE else r["navigator"]
        if r.get("navigator_params"):
            name += " (" + ", ".join(f"{k}={v}" for k, v in r["navigator_params"].items()) + ")"
        lines.append(f"| {name} | {r['runs']} | {r['success_rate']:.3f} | {r['collision_rate']:.3f} | "
                     f"{r['timeout_rate']:.3f} | {_f(r['barn_score'], '.4f')} | {_f(r['mean_time_to_goal_s'], '.2f')} |")
    contenders = [r for r in overall if r["navigator"] != ORACLE]
    if contenders:
        best = max(contenders, key=lambda r: (r["barn_score"] or 0.0, r["success_rate"]))
        lines += ["", f"Best by score: `{best['navigator']}`, {best['barn_score']:.4f} (success "
                      f"{best['success_rate']:.3f})."]
    return lines


def published_lines() -> list[str]:
    lines = ["Published on the same 50 test worlds x 10 runs:", "",
             "| entry | runs | success | collisions | timeouts | BARN score | mean time s | source |",
             "|---|---:|---:|---:|---:|---:|---:|---|"]
    for p in PUBLISHED:
        lines.append(f"| {p['entry']} | {p['runs']} | {p['success_rate']:.3f} | {p['collision_rate']:.3f} | "
                     f"{p['timeout_rate']:.3f} | {p['barn_score']:.4f} | {p['mean_time_s']:.2f} | {p['source']} |")
    return lines


def difficulty_lines(rows: list[dict[str, Any]]) -> list[str]:
    """Success against BARN's difficulty metrics, per navigator, from the per-run rows."""
    from swarmnav.benchmarks.barn_difficulty import METRICS, success_against_difficulty
    per_run = [r for r in rows if r.get("scenario") is not None and r.get("difficulty")]
    names = [n for n in dict.fromkeys(r["navigator"] for r in per_run)]
    if not per_run:
        return []
    lines = ["Success against difficulty (Spearman's rho of a world's success with the metric over the worlds; "
             "success in the lower / upper half of the worlds by the metric):", "",
             "| navigator | " + " | ".join(METRICS) + " |", "|---|" + "---:|" * len(METRICS)]
    for name in names:
        table = success_against_difficulty(per_run, name)
        cells = [f"{_f(table[k]['spearman'], '+.2f')} ({_f(table[k]['success_low_half'], '.2f')} / "
                 f"{_f(table[k]['success_high_half'], '.2f')})" for k in METRICS]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return lines


def fresh_lines(results: tuple[FilePath, ...]) -> list[str]:
    """Each BARN-like result's figures (fresh worlds) against BARN's in the same setup (the 300 when committed,
    else the 50 test worlds), navigator by navigator with the same parameters (issue 34's check: within 0.05)."""
    lines: list[str] = []
    for fresh_path in FRESH:
        if fresh_path in results and fresh_path.is_file():
            lines += _fresh_against_barn(fresh_path, results)
    return lines


def _key(row: dict[str, Any]) -> tuple[str, str]:
    """A row's navigator (an arm's own navigator, whatever its label) and its parameters."""
    return (row.get("arm_of") or row["navigator"],
            json.dumps(row.get("arm_params") or row.get("navigator_params") or {}, sort_keys=True))


def _fresh_against_barn(fresh_path: FilePath, results: tuple[FilePath, ...]) -> list[str]:
    fresh_rows = read_result(fresh_path)
    setups = {r["barn_setup"] for r in fresh_rows}
    files = [p for p in BARN_300 + BARN_50 if p in results and p.is_file()
             and setups & {r["barn_setup"] for r in read_result(p)}]  # the same setup only
    if not files:
        return []
    whole = [p for p in files if p in BARN_300] or files[:1]  # the 300 worlds where run, else the 50 test worlds
    base: dict[tuple[str, str], tuple[FilePath, dict[str, Any]]] = {}
    for path in whole:
        for r in read_result(path):
            if r.get("scenario") is None:
                base.setdefault(_key(r), (path, r))
    base_rows = read_result(whole[0])
    fresh = {_key(r): r for r in fresh_rows if r.get("scenario") is None}
    lines = []
    for key in [k for k in fresh if k in base]:
        (against, b), f = base[key], fresh[key]
        ds, dsc = f["success_rate"] - b["success_rate"], (f["barn_score"] or 0.0) - (b["barn_score"] or 0.0)
        if f["barn_setup"] != b["barn_setup"]:
            continue
        lines.append(f"BARN-like worlds (`{fresh_path.name}`) against BARN's (`{against.name}`), `{key[0]}`: success "
                     f"{f['success_rate']:.3f} vs "
                     f"{b['success_rate']:.3f} ({ds:+.3f}), score {f['barn_score']:.4f} vs {b['barn_score']:.4f} "
                     f"({dsc:+.4f}): {'within' if abs(ds) <= 0.05 and abs(dsc) <= 0.05 else 'NOT within'} 0.05.")
    if lines:
        from swarmnav.benchmarks.barn_difficulty import METRICS

        def means(rows: list[dict[str, Any]]) -> dict[str, float]:
            worlds = {r["world"]: r["difficulty"] for r in rows if r.get("scenario") is not None and r.get("difficulty")}
            return {k: sum(d[k] for d in worlds.values()) / len(worlds) for k in METRICS} if worlds else {}
        b, f = means(base_rows), means(fresh_rows)
        if b and f:
            lines.append("Their worlds' mean difficulty, BARN-like against BARN's: " + "; ".join(
                f"{k.replace('_', ' ')} {f[k]:.2f} vs {b[k]:.2f}" for k in METRICS) + ".")
    return lines + [""] if lines else []


def _protocol_rows(results: tuple[FilePath, ...]):
    """Each committed protocol row (``scenario`` None) with its result file and its navigator's per-run rows."""
    from swarmnav.benchmarks.barn import PROTOCOL_TEXT
    for path in results:
        if not path.is_file():
            continue
        rows = read_result(path)
        for r in rows:
            if r.get("scenario") is None and r.get("barn_setup") == PROTOCOL_TEXT:
                yield path, r, [x for x in rows if x.get("scenario") is not None and x["navigator"] == r["navigator"]]


def _label(r: dict[str, Any]) -> str:
    """The row's navigator with the parameters it ran (an arm's, else the row's own)."""
    params = r.get("arm_params") or r.get("navigator_params")
    return r["navigator"] + (" (" + ", ".join(f"{k}={v}" for k, v in params.items()) + ")" if params else "")


def configurations() -> dict[str, dict[str, Any]]:
    """navigator -> its BARN configuration's parameters (:data:`CONFIGURATIONS`)."""
    from swarmnav.benchmarks.navigation import read_arms
    return {arm.navigator: arm.params for arm in read_arms(str(CONFIGURATIONS))}


def _is_configuration(r: dict[str, Any], wanted: dict[str, dict[str, Any]]) -> bool:
    """Whether the row ran its navigator's BARN configuration (:func:`configurations`)."""
    base = r.get("arm_of") or r["navigator"]
    return base in wanted and (r.get("arm_params") or r.get("navigator_params") or {}) == wanted[base]


def online_navigators() -> list[str]:
    """The online navigators (they act on what they sense: ``uses_detections``), but :data:`NOT_ONLINE`."""
    from swarmnav.controllers.navigators import NAVIGATORS
    return [name for name, nav in NAVIGATORS.items()
            if getattr(nav, "uses_detections", False) and name not in NOT_ONLINE]


def online_lines(results: tuple[FilePath, ...]) -> list[str]:
    """Issue 34's "every online navigator" target from every committed protocol result on the test worlds: per
    online navigator (its own rows and its arms') the row with the most runs (on a tie, the row of its BARN
    configuration, :func:`configurations`, then the later), its worlds x runs and whether it is the protocol's full 500; the target is met only when every
    one has a 500-run row at 0.88 or more."""
    from swarmnav.benchmarks.barn import TEST_WORLDS
    wanted = configurations()
    chosen: dict[str, tuple[FilePath, dict[str, Any], int, int]] = {}
    for path, r, per_run in _protocol_rows(results):
        worlds = {x["world"] for x in per_run}
        barn_worlds = all(x["scenario"].startswith("barn-") for x in per_run)  # not BARN-like seeds
        if worlds and worlds <= set(TEST_WORLDS) and barn_worlds:
            base = r.get("arm_of") or r["navigator"]  # an arm (--arm LABEL:NAV:...) counts for its navigator
            if base not in chosen or _rank(r, wanted) >= _rank(chosen[base][1], wanted):
                chosen[base] = (path, r, len(worlds), r["runs"] // len(worlds))
    names = online_navigators()
    lines = ["Every online navigator under the protocol (map unknown, Jackal, its laser) on the challenge's test "
             "worlds: for each, its committed row (its own or an arm's) with the most runs; on a tie, the row of its "
             "configuration in `models/suites/barn-navigators.toml` (chosen on non-test worlds, never by these "
             "results), then the later file; the challenge's "
             f"protocol is 50 worlds x 10 runs = {PROTOCOL_RUNS} runs, and a smaller sample is marked so:", "",
             "| navigator | result file | worlds x runs | runs | success | collisions | timeouts | BARN score |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for name in names:
        if name not in chosen:
            lines.append(f"| {name} | none | – | 0 | – | – | – | – |")
            continue
        path, r, worlds, runs = chosen[name]
        label = _label(r)
        sample = "" if r["runs"] >= PROTOCOL_RUNS else f" (sample: {r['runs']} of the protocol's {PROTOCOL_RUNS})"
        lines.append(f"| {label} | `{path.name}` | {worlds} x {runs} | {r['runs']}{sample} | "
                     f"{r['success_rate']:.3f} | {r['collision_rate']:.3f} | {r['timeout_rate']:.3f} | "
                     f"{_f(r['barn_score'], '.4f')} |")
    short = [n for n in names if n not in chosen or chosen[n][1]["runs"] < PROTOCOL_RUNS]
    below = [n for n in names if n in chosen and chosen[n][1]["success_rate"] < ONLINE_TARGET]
    met = not short and not below
    why = []
    if below:
        why.append("below it: " + ", ".join(f"`{n}` {chosen[n][1]['success_rate']:.3f} ({chosen[n][1]['runs']} "
                                              f"runs)" for n in below))
    if short:
        why.append("not run on the protocol's 500: " + ", ".join(f"`{n}`" for n in short))
    lines += ["", f"Every online navigator's success ≥ {ONLINE_TARGET:.2f} (the published move_base DWA's) on the "
                  f"protocol's {PROTOCOL_RUNS} runs: " + ("met." if met else "not met (" + "; ".join(why) + ").")]
    return lines


def _rank(r: dict[str, Any], wanted: dict[str, dict[str, Any]]) -> tuple[int, bool]:
    """A row's claim to stand for its navigator: more runs first, then its BARN configuration's (a later file
    wins a full tie: the caller's ``>=``). Never its success: the row shown is not picked by its result."""
    return r["runs"], _is_configuration(r, wanted)


def all_worlds_lines(results: tuple[FilePath, ...]) -> list[str]:
    """Issue 34's "all 300 worlds run for every navigator": per online navigator (its own rows and its arms'), a
    committed protocol row whose runs cover every one of BARN's worlds (the one with the most runs), and whether
    every online navigator has one."""
    from swarmnav.benchmarks.barn import WORLD_COUNT
    wanted = configurations()
    chosen: dict[str, tuple[FilePath, dict[str, Any], float | None]] = {}
    for path, r, per_run in _protocol_rows(results):
        per_run = [x for x in per_run if x["scenario"].startswith("barn-")]
        if {x["world"] for x in per_run} == set(range(WORLD_COUNT)):
            base = r.get("arm_of") or r["navigator"]
            if base not in chosen or _rank(r, wanted) >= _rank(chosen[base][1], wanted):
                chosen[base] = (path, r, _cpu_min(per_run))
    names = online_navigators()
    lines = [f"All {WORLD_COUNT} worlds under the protocol, per online navigator (its committed row whose runs "
             "cover every world; CPU: the runs' own, simulated time over each run's real-time factor on CPU, the "
             "bench's overhead not counted):", "",
             "| navigator | result file | runs | success | collisions | timeouts | BARN score | CPU min |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for name in names:
        if name not in chosen:
            lines.append(f"| {name} | none | 0 | – | – | – | – | – |")
            continue
        path, r, cpu = chosen[name]
        label = _label(r)
        lines.append(f"| {label} | `{path.name}` | {r['runs']} | {r['success_rate']:.3f} | {r['collision_rate']:.3f} "
                     f"| {r['timeout_rate']:.3f} | {_f(r['barn_score'], '.4f')} | {_f(cpu, '.1f')} |")
    missing = [n for n in names if n not in chosen]
    lines += ["", f"All {WORLD_COUNT} worlds run for every online navigator: " + (
        "met." if not missing else "not met (none yet for " + ", ".join(f"`{n}`" for n in missing) + ").")]
    cpus = [chosen[n][2] for n in names if n in chosen]
    if cpus and all(c is not None for c in cpus):
        total = sum(cpus)
        whole = "every online navigator" if not missing else f"the online navigators run so far ({len(cpus)} of {len(names)})"
        lines.append(f"Their runs' own CPU, {whole}: {total:.1f} min, so at least {total / 2:.1f} min of wall time on "
                     f"2 cores (issue 34's speed target: all {WORLD_COUNT} worlds x every online navigator within "
                     "60 min on 2 cores; a lower bound, not a timed command).")
    return lines


def _cpu_min(per_run: list[dict[str, Any]]) -> float | None:
    """The runs' own CPU in minutes (simulated time over each run's real-time factor on CPU), None if unknown."""
    if not per_run or any(not r.get("realtime_factor_cpu") or r.get("time_s") is None for r in per_run):
        return None
    return sum(r["time_s"] / r["realtime_factor_cpu"] for r in per_run) / 60.0


def block(results: tuple[FilePath, ...] = RESULTS) -> str:
    lines = [BEGIN, ""]
    for path in results:
        if path.is_file():
            rows = read_result(path)
            lines += result_lines(path, rows) + [""]
            diff = difficulty_lines(rows)
            lines += (diff + [""]) if diff else []
    lines += (fresh_lines(results) + online_lines(results) + [""] + all_worlds_lines(results) + [""]
              + published_lines() + ["", END])
    return "\n".join(lines)


MARKERS = MarkedBlock(BEGIN, END, "barn-table markers")
replace_block, current_block = MARKERS.replace, MARKERS.current


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m swarmnav.benchmarks.barn_table",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--readme", help="replace the block between the markers in this file")
    args = parser.parse_args(argv)
    try:
        generated = block()
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
