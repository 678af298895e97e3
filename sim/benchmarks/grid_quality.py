"""The quality tables of ``swarmnav bench grid``, run as studies.

Three plan-only studies, built in code and run by the study machinery
(:mod:`swarmnav.study`, the one episode function, the same Parquet rows as
``swarmnav study``), into ``OUT/maps``, ``OUT/restaurant`` and ``OUT/movingai``:

* ``bench-grid-maps``: every grid planner on the bundled 50 x 50 map scenarios, ``runs``
  seeds each (a planner that is the scenario's own gets the scenario's parameters); with
  ``--all-pairs`` also on a copy of each map scenario per ``[map].pairs`` entry (written to
  ``OUT/pair-scenarios``: the scenario's text with its name, start and goal replaced);
* ``bench-grid-restaurant``: M-ACO (Habib et al. (2021)'s waiter robot) on its home
  scenario beside A*, with how many runs' node baselines (the paper's Dijkstra links) collide;
* ``bench-grid-movingai``: ``immas`` and ``iaco`` on a sample of Moving AI benchmark
  instances written as scenario files (``OUT/movingai-scenarios``: the map file, 1 m cells,
  a robot that fills half a cell with its clearance, so the inflated map is the map), their
  raw cell-path length against the instance's published optimum.

The tables are computed from the rows alone; a run that failed or returned a colliding
path is a row, counted in ``runs`` (``feasible_runs`` says how many were collision-free).
"""

from __future__ import annotations

import json
import re
import statistics
from pathlib import Path as FilePath
from typing import Any

import numpy as np
from scipy import ndimage

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import list_scenarios, load_scenario
from swarmnav.planners.problem import scenario_problem
from swarmnav.benchmarks.planner_quality import arms, run_time_s
from swarmnav.study.execute import run_study_tables

GRID_PLANNERS = ("astar", "dijkstra", "theta_star", "dstar_lite", "immas", "iaco")
MOVINGAI_PLANNERS = ("immas", "iaco")
MOVINGAI_CELL_M = 1.0
MOVINGAI_CLEARANCE_M = 0.05  # robot radius + clearance = half a cell: the inflated map is the map itself


def map_scenarios(names: list[str] | None) -> list[str]:
    """The named scenarios with a map, or every bundled ``immas-*`` / ``iaco-*`` one with a map.

    Raises:
        ConfigError: a named scenario has no map (``--maps``).
    """
    out = []
    for name in names or list_scenarios():
        scenario = load_scenario(name)
        if scenario.boxes and (names or name.startswith(("immas-", "iaco-"))):
            out.append(name)
        elif names:
            raise ConfigError("--maps", f"scenario {name!r} has no map (box obstacles): bench grid plans on maps")
    return out


def _replace_line(text: str, key: str, value: str, source: str) -> str:
    pattern = re.compile(rf"^{key}\s*=.*$", re.MULTILINE)
    if len(pattern.findall(text)) != 1:
        raise ValueError(f"{source}: expected one top-level line '{key} = ...' to replace")
    return pattern.sub(lambda _: f"{key} = {value}", text, count=1)


def pair_scenario_toml(ref: str, index: int) -> tuple[str, str]:
    """(name, TOML) of scenario ``ref`` planned between the centres of its ``[map].pairs[index]`` cells."""
    scenario = load_scenario(ref)
    x0, y0, x1, y1 = scenario.map_pairs[index]
    cell = scenario.cell_m
    name = f"{scenario.name}-pair-{index}"
    text = _replace_line(scenario.source_text, "name", json.dumps(name), ref)
    text = _replace_line(text, "start", f"{{ x = {(x0 + 0.5) * cell!r}, y = {(y0 + 0.5) * cell!r}, "
                                        f"heading_deg = 0.0 }}", ref)
    text = _replace_line(text, "goal", f"{{ x = {(x1 + 0.5) * cell!r}, y = {(y1 + 0.5) * cell!r}, "
                                       f"tolerance_m = {scenario.goal_tolerance_m!r} }}", ref)
    return name, text


def movingai_scenario_toml(map_path: FilePath, shape: tuple[int, int], instance, index: int) -> tuple[str, str]:
    """(name, TOML) of one Moving AI instance on its map: 1 m cells, rows counted from the top in the file."""
    rows, cols = shape
    (r0, c0), (r1, c1) = instance.start_cell(), instance.goal_cell()
    name = f"movingai-{map_path.stem}-{index}"
    radius_m = 0.5 * MOVINGAI_CELL_M - MOVINGAI_CLEARANCE_M
    description = f"Moving AI instance {index} of {map_path.name}: published optimum {instance.optimal_length:.8f} cells."
    lines = [f"name = {json.dumps(name)}", f"description = {json.dumps(description)}",
             "seed = 0", "time_limit_s = 600.0",
             f"arena = {{ width_m = {cols * MOVINGAI_CELL_M!r}, height_m = {rows * MOVINGAI_CELL_M!r}, walls = false }}",
             f"robot = {{ radius_m = {radius_m!r}, max_speed_m_s = 0.2, clearance_m = {MOVINGAI_CLEARANCE_M!r} }}",
             f"start = {{ x = {(c0 + 0.5) * MOVINGAI_CELL_M!r}, y = {(rows - 1 - r0 + 0.5) * MOVINGAI_CELL_M!r}, "
             "heading_deg = 0.0 }",
             f"goal = {{ x = {(c1 + 0.5) * MOVINGAI_CELL_M!r}, y = {(rows - 1 - r1 + 0.5) * MOVINGAI_CELL_M!r}, "
             "tolerance_m = 0.1 }",
             "sensors = { count = 12, range_m = 0.4 }", 'planner = { name = "astar", params = {} }', "",
             "[map]", f"file = {json.dumps(str(map_path.resolve()))}", f"cell_m = {MOVINGAI_CELL_M!r}"]
    return name, "\n".join(lines) + "\n"


def _write(folder: FilePath, name: str, text: str) -> str:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return str(path)


def _extra(row: dict[str, Any]) -> dict[str, Any]:
    return json.loads(row["plan_extra"]) if row.get("plan_extra") else {}


def cell_clearance_m(ref: str) -> np.ndarray:
    """Each cell's distance to the nearest occupied cell of scenario ``ref``'s planning grid, in metres."""
    grid = scenario_problem(load_scenario(ref)).grid
    return ndimage.distance_transform_edt(~grid.occupied) * grid.cell_m


def _mean_at(clearance: np.ndarray, cells: list) -> float:
    idx = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    return float(np.mean(clearance[idx[:, 0], idx[:, 1]]))


def maps_study(args, out_dir: FilePath) -> list[dict[str, Any]]:
    """The map table: per map and grid planner, lengths against A*'s, raw lengths, cell clearance, time."""
    refs = map_scenarios(args.maps)
    if args.all_pairs:
        refs += [_write(out_dir / "pair-scenarios", *pair_scenario_toml(ref, k))
                 for ref in list(refs) for k in range(len(load_scenario(ref).map_pairs))]
    runs = run_study_tables({"name": "bench-grid-maps", "scenarios": refs, "mode": "plan", "seeds": args.runs,
                             "planners": [{"name": p} for p in GRID_PLANNERS]}, out_dir / "maps")
    by_arm = arms(runs)
    table = []
    for scenario in dict.fromkeys(r["scenario"] for r in runs):
        clearance = cell_clearance_m(next(r["scenario_ref"] for r in runs if r["scenario"] == scenario))
        astar = [r for r in by_arm.get((scenario, "astar"), []) if r["success"]]
        astar_len = astar[0]["plan_length_m"] if astar else None
        astar_raw = astar[0]["plan_raw_length_m"] if astar else None
        for planner in GRID_PLANNERS:
            arm = by_arm.get((scenario, planner), [])
            good = [r for r in arm if r["success"]]
            row = {"map": scenario, "planner": planner, "runs": len(arm), "feasible_runs": len(good),
                   "mean_plan_time_s": statistics.fmean(run_time_s(r) for r in arm) if arm else None,
                   "astar_length_m": astar_len, "astar_raw_length_m": astar_raw}
            if good:
                median = statistics.median(r["plan_length_m"] for r in good)
                raw = statistics.median(r["plan_raw_length_m"] for r in good)
                extras = [_extra(r) for r in good]
                row.update(median_length_m=median, ratio_to_astar=median / astar_len if astar_len else None,
                           median_raw_length_m=raw, raw_ratio_to_astar=raw / astar_raw if astar_raw else None,
                           mean_cell_clearance_m=statistics.fmean(_mean_at(clearance, e["raw_cells"])
                                                                  for e in extras))
                if planner == "immas":
                    row.update({k: extras[0][k] for k in ("gates_raised", "tunnels_closed", "moves", "total_arc_cost")})
                if planner == "iaco":
                    row.update(convergence_iteration=statistics.median(e["convergence_iteration"] for e in extras),
                               bends=statistics.median(e["bends"] for e in extras),
                               std_length_m=statistics.pstdev(r["plan_raw_length_m"] for r in good))
            table.append(row)
    return table


def restaurant_study(runs: int, out_dir: FilePath) -> list[dict[str, Any]]:
    """M-ACO on restaurant-table-2 beside A*: lengths, times, runs whose node baselines collide."""
    rows = run_study_tables({"name": "bench-grid-restaurant", "scenarios": ["restaurant-table-2"], "mode": "plan",
                             "seeds": runs, "planners": [{"name": "maco"}, {"name": "astar"}]},
                            out_dir / "restaurant")
    by_arm = arms(rows)
    maco = by_arm.get(("restaurant-table-2", "maco"), [])
    good = [r for r in maco if r["success"]]
    astar = [r for r in by_arm.get(("restaurant-table-2", "astar"), []) if r["success"]]
    astar_len = astar[0]["plan_length_m"] if astar else None
    median = statistics.median(r["plan_length_m"] for r in good) if good else None
    return [{"map": "restaurant-table-2", "planner": "maco", "runs": len(maco), "feasible_runs": len(good),
             "median_length_m": median, "astar_length_m": astar_len,
             "ratio_to_astar": median / astar_len if (median is not None and astar_len) else None,
             "mean_plan_time_s": statistics.fmean(run_time_s(r) for r in maco) if maco else None,
             "node_baseline_runs_colliding": sum(bool(_extra(r).get("dijkstra_colliding_links")) for r in good)}]


def movingai_study(sample: int, limit: int | None, out_dir: FilePath) -> dict[str, Any]:
    """``immas`` and ``iaco`` (seed 0) on ``sample`` instances of each Moving AI map (spread over the first
    ``limit``): raw cell-path length over the published optimum, and the runs that failed."""
    from swarmnav.models.grid_map import benchmark_sets, read_map, read_scenarios

    refs, optimum = [], {}
    for map_path, scen_path in benchmark_sets():
        shape = read_map(map_path).shape
        instances = [s for s in read_scenarios(scen_path) if s.map_name.endswith(map_path.name)][:limit]
        step = max(1, len(instances) // max(1, sample))
        for index, instance in list(enumerate(instances))[::step][:sample]:
            if instance.optimal_length == 0:
                continue
            name, text = movingai_scenario_toml(map_path, shape, instance, index)
            refs.append(_write(out_dir / "movingai-scenarios", name, text))
            optimum[name] = instance.optimal_length
    if not refs:
        return {}
    rows = run_study_tables({"name": "bench-grid-movingai", "scenarios": refs, "mode": "plan", "seeds": [0],
                             "planners": [{"name": p} for p in MOVINGAI_PLANNERS]}, out_dir / "movingai")
    out = {}
    for planner in MOVINGAI_PLANNERS:
        arm = [r for r in rows if r["planner"] == planner]
        ratios = [r["plan_raw_length_m"] / optimum[r["scenario"]] for r in arm if r["success"]]
        out[planner] = {"instances": len(arm), "failures": len(arm) - len(ratios),
                        "median": statistics.median(ratios) if ratios else None,
                        "max": max(ratios) if ratios else None}
    return out

