"""`swarmnav bench sensed-map`: every planning navigator with the static map known and unknown, on the
scenes of issue 33's criterion (``dense-field-30`` and ``gwo-scenario-1``).

Each row is one run (``swarmnav run SCENE --navigator NAV --planner PLANNER --map MAP``, the scenario's seeds,
its own sensors: 12 rays of 0.4 m), the planner's and navigator's defaults but for :data:`PLANNER_PARAMS`:

* ``replan`` with each planner of :data:`REPLAN_PLANNERS` (the swarm planners of the papers, the grid colonies,
  the grid searches, the exact tangent graph and two of OMPL's);
* ``dstar_replan`` (D* Lite plans and repairs itself; the scenario's planner is not used);
* ``dwa``, ``velocity_obstacle`` and ``mppi`` with the scenario's planner (``astar``) for their guidance path.

The criterion: with the map unknown, every combination reaches the goal with no collision wherever it does
with the map known (:func:`unmet`), but for the exceptions named with their reason in :data:`UNMET`.
The table of docs/sensing.md between the ``sensed-map-table`` markers is :func:`block` of the committed
:data:`RESULTS` (``tests/test_sensed_map_table.py`` fails when they drift, and when a committed row is no
longer what the run gives).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from swarmnav.models.marked_block import MarkedBlock

RESULTS = Path(__file__).resolve().parents[2] / "models" / "suites" / "results" / "sensed_map.json"
PAGE = Path(__file__).resolve().parents[2] / "docs" / "sensing.md"
BEGIN = ("<!-- sensed-map-table: generated from models/suites/results/sensed_map.json by "
         "`swarmnav bench sensed-map --write`; do not edit by hand -->")
END = "<!-- end of sensed-map-table -->"
SCENES = ("gwo-scenario-1", "dense-field-30")
MAPS = ("known", "unknown")
REPLAN_PLANNERS = ("gwo", "pso", "abc", "adl_abc", "aco", "mmas", "iaco", "immas", "astar", "theta_star",
                   "dijkstra", "dstar_lite", "optimal", "rrt_connect", "prm_star")
LOCAL_NAVIGATORS = ("dstar_replan", "dwa", "velocity_obstacle", "mppi")
#: Planner parameters the matrix sets (both maps), and why (measured; docs/sensing.md).  RRT-Connect stops at its
#: first solution, a random route: on the sensed map each of its ~10 replans drew a new one (5-17 m), and with
#: the default single attempt dense-field-30 timed out with the map unknown (seeds 0 and 1; seed 2: 134.0 s).
#: The shortest of 4 attempts (MoveIt's ``num_planning_attempts``), on the same budget, reaches the goal.
PLANNER_PARAMS: dict[str, dict[str, Any]] = {"rrt_connect": {"attempts": 4}}
#: Combinations that succeed with the map known and not unknown, and why (measured; docs/sensing.md): none.
UNMET: dict[str, str] = {}


def combinations(scenes: tuple[str, ...] = SCENES) -> list[tuple[str, str, str | None]]:
    """(scene, navigator, planner or None for the scenario's) of the matrix, in the table's order."""
    pairs = [("replan", p) for p in REPLAN_PLANNERS] + [(n, None) for n in LOCAL_NAVIGATORS]
    return [(scene, navigator, planner) for navigator, planner in pairs for scene in scenes]


def run_one(scene: str, navigator: str, planner: str | None, map_knowledge: str) -> dict[str, Any]:
    """One run: its row (``planner`` None: the scenario's)."""
    import time

    from swarmnav.models.scenario import load_scenario
    from swarmnav.sim.episode import EpisodeSpec, run_episode

    scenario = load_scenario(scene).with_knowledge(map_knowledge)
    params = PLANNER_PARAMS.get(planner or "", {})
    wall0 = time.perf_counter()
    episode = run_episode(EpisodeSpec(scenario, planner=planner, navigator=navigator,
                                      planner_params=dict(params) or None))
    wall_s = time.perf_counter() - wall0
    result = episode.result
    summary = result.summary()
    return {"scenario": scene, "navigator": navigator, "planner": planner or scenario.planner_name,
            "planner_params": dict(params), "map": map_knowledge, "outcome": str(result.outcome), "success": bool(result.success),
            "collisions": int(result.collisions), "sim_time_s": round(float(result.sim_time_s), 2),
            "replans": int(summary.get("replans", 0) or 0), "wall_s": round(wall_s, 1)}


def benchmark(scenes: tuple[str, ...] = SCENES, only: str | None = None) -> list[dict[str, Any]]:
    """The rows of every combination (``only``: navigators or planners of that name), known then unknown."""
    return [run_one(scene, navigator, planner, m) for scene, navigator, planner in combinations(scenes)
            if only in (None, navigator, planner) for m in MAPS]


def unmet(rows: list[dict[str, Any]]) -> list[str]:
    """The combinations that succeed with the map known and not with it unknown."""
    by = {(r["scenario"], r["navigator"], r["planner"], r["map"]): r for r in rows}
    return [f"{s} {n} {p}" for (s, n, p, m), r in by.items()
            if m == "known" and r["success"] and not by.get((s, n, p, "unknown"), {}).get("success")]


def cell(row: dict[str, Any] | None) -> str:
    if row is None:
        return "-"
    if row["success"]:
        return f"goal {row['sim_time_s']:g} s"
    extra = f", {row['collisions']} coll." if row["collisions"] else ""
    return f"{row['outcome']}{extra}"


def table(rows: list[dict[str, Any]]) -> str:
    """The rows as a Markdown table: one line per navigator and planner, known / unknown per scene."""
    scenes = list(dict.fromkeys(r["scenario"] for r in rows))
    by = {(r["scenario"], r["navigator"], r["planner"], r["map"]): r for r in rows}
    head = "| navigator | planner | " + " | ".join(f"{s} known | {s} unknown" for s in scenes) + " |"
    lines = [head, "|---|---|" + "---|---|" * len(scenes)]
    params = {(r["navigator"], r["planner"]): r.get("planner_params") or {} for r in rows}
    for navigator, planner in dict.fromkeys((r["navigator"], r["planner"]) for r in rows):
        cells = [cell(by.get((s, navigator, planner, m))) for s in scenes for m in MAPS]
        named = "".join(f" ({k} = {v})" for k, v in params[navigator, planner].items())
        lines.append(f"| {navigator} | {planner}{named} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def block(rows: list[dict[str, Any]] | None = None) -> str:
    """The page's block (markers included) of ``rows``, by default the committed :data:`RESULTS`."""
    if rows is None:
        rows = json.loads(RESULTS.read_text(encoding="utf-8"))
    return f"{BEGIN}\n{table(rows)}\n{END}"


MARKERS = MarkedBlock(BEGIN, END, "sensed-map-table markers")
current_block = MARKERS.current


def write(rows: list[dict[str, Any]], page: Path) -> None:
    """``rows`` as :data:`RESULTS` (the wall times dropped: they are not deterministic) and the page's block."""
    kept = [{k: v for k, v in r.items() if k != "wall_s"} for r in rows]
    RESULTS.write_text(json.dumps(kept, indent=1) + "\n", encoding="utf-8")
    page.write_text(MARKERS.replace(page.read_text(encoding="utf-8"), block(kept), str(page)), encoding="utf-8")


def run(args) -> int:
    """``bench sensed-map [--scenario NAME ...] [--only NAME] [--json] [--write]``: the rows, as JSON lines or
    the Markdown table; one stderr line per combination that succeeds with the map known and not unknown, and
    exit 5 when one of them is not among the named exceptions (:data:`UNMET`)."""
    from swarmnav.models.errors import ConfigError
    names = set(REPLAN_PLANNERS) | set(LOCAL_NAVIGATORS) | {"replan"}
    if args.only is not None and args.only not in names:
        raise ConfigError("--only", f"must be one of {', '.join(sorted(names))}, got {args.only!r}")
    if args.write and (args.only is not None or args.scenario):  # refused before any run
        raise ConfigError("--write", "writes the whole matrix: not with --only or --scenario")
    from swarmnav.models.scenario import load_scenario
    for name in args.scenario or ():
        load_scenario(name)  # a bad name or file: one line naming it, exit 2, before any run
    rows = benchmark(tuple(args.scenario) if args.scenario else SCENES, only=args.only)
    if args.write:
        write(rows, PAGE)
    if args.json:
        for row in rows:
            print(json.dumps(row))
    else:
        print(table(rows))
    import sys
    missing = unmet(rows)
    for line in missing:
        why = f" (named: {UNMET[line]})" if line in UNMET else ""
        print(f"bench sensed-map: {line}: succeeds with the map known, not unknown{why}", file=sys.stderr)
    return 5 if set(missing) - set(UNMET) else 0
