"""``bench grid``'s quality tables come from study rows, and its scenario files pose the same problems."""

from __future__ import annotations

import argparse
import json

import numpy as np
import pandas as pd
import pytest

from swarmnav.models.grid_map import benchmark_sets, read_map, read_scenarios
from swarmnav.models.scenario import load_scenario, parse_scenario
from swarmnav.planners.improved_max_min_ant_system import ImprovedMaxMinAntSystemPlanner
from swarmnav.planners.problem import map_problem, scenario_problem
from swarmnav.planners.registry import make_planner
from swarmnav.benchmarks import grid
from swarmnav.benchmarks.grid_quality import movingai_scenario_toml, pair_scenario_toml
from swarmnav.cli.commands import add_bench_grid_arguments


def _instances(count: int):
    sets = benchmark_sets()
    if not sets:
        pytest.skip("no Moving AI benchmark files")
    for map_path, scen_path in sets:
        occupied = read_map(map_path)
        instances = [s for s in read_scenarios(scen_path) if s.map_name.endswith(map_path.name)]
        for index in range(0, len(instances), max(1, len(instances) // count))[:count]:
            if instances[index].optimal_length > 0:
                yield map_path, occupied, instances[index], index


def test_a_movingai_scenario_file_poses_the_published_instance(tmp_path):
    """A* from the scenario file finds the published optimum; IMMAS plans the same raw tour as on the
    instance's own grid problem (what the benchmark planned before it ran studies)."""
    for map_path, occupied, instance, index in _instances(3):
        name, text = movingai_scenario_toml(map_path, occupied.shape, instance, index)
        path = tmp_path / f"{name}.toml"
        path.write_text(text)
        problem = scenario_problem(load_scenario(str(path)))
        astar = make_planner("astar").plan(problem, np.random.default_rng(0))
        assert astar.stats.extra["raw_length_m"] == pytest.approx(instance.optimal_length, abs=1e-6)
        rows = occupied.shape[0]
        direct = map_problem(occupied[::-1], 1.0, (rows - 1 - instance.start_row, instance.start_col),
                             (rows - 1 - instance.goal_row, instance.goal_col))
        ours = ImprovedMaxMinAntSystemPlanner().plan(problem, np.random.default_rng(0)).stats.extra["raw_length_m"]
        theirs = ImprovedMaxMinAntSystemPlanner().plan(direct, np.random.default_rng(0)).stats.extra["raw_length_m"]
        assert ours == pytest.approx(theirs)


def test_a_pair_variant_moves_only_the_endpoints():
    scenario = load_scenario("iaco-simple")
    for index, (x0, y0, x1, y1) in enumerate(scenario.map_pairs):
        name, text = pair_scenario_toml("iaco-simple", index)
        variant = parse_scenario(text, "<pair>")
        assert variant.name == name and variant.boxes == scenario.boxes
        assert (variant.start.x_m, variant.start.y_m) == ((x0 + 0.5) * scenario.cell_m, (y0 + 0.5) * scenario.cell_m)
        assert (variant.goal.x_m, variant.goal.y_m) == ((x1 + 0.5) * scenario.cell_m, (y1 + 0.5) * scenario.cell_m)


def test_the_map_table_is_the_study_rows(tmp_path, capsys):
    parser = argparse.ArgumentParser()
    add_bench_grid_arguments(parser)
    args = parser.parse_args(["--maps", "iaco-simple", "--runs", "2", "--all-pairs", "--swarm-sample", "1",
                              "--out", str(tmp_path), "--json"])
    assert grid.run(args) == 0
    result = json.loads(capsys.readouterr().out)
    runs = pd.read_parquet(tmp_path / "maps" / "runs.parquet")
    scenarios = 1 + len(load_scenario("iaco-simple").map_pairs)
    assert len(runs) == scenarios * len(grid.GRID_PLANNERS) * 2 and runs.config_hash.is_unique
    for row in (r for r in result["rows"] if r["map"] != "restaurant-table-2"):
        arm = runs[(runs.scenario == row["map"]) & (runs.planner == row["planner"])]
        astar = runs[(runs.scenario == row["map"]) & (runs.planner == "astar")]
        assert row["runs"] == len(arm) and row["feasible_runs"] == int(arm.success.sum())
        assert row["median_length_m"] == pytest.approx(arm[arm.success].plan_length_m.median())
        assert row["ratio_to_astar"] == pytest.approx(row["median_length_m"] / astar.plan_length_m.iloc[0])
    maco = pd.read_parquet(tmp_path / "restaurant" / "runs.parquet")
    assert set(maco.planner) == {"maco", "astar"} and len(maco) == 4
    swarm = result["movingai"]["swarm_ratio_to_optimum"]
    assert all(v["instances"] >= 1 and (v["median"] is None or v["median"] >= 1 - 1e-9) for v in swarm.values())


def test_a_map_option_naming_a_scenario_without_a_map_is_one_line(capsys):
    from swarmnav.cli.main import main

    assert main(["bench", "grid", "--quick", "--maps", "gwo-scenario-1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--maps" in err and "gwo-scenario-1" in err
