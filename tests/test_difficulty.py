"""Difficulty metrics (sim/runtime/difficulty.py) and `scenarios info`."""

import json

import pytest

from swarmnav.models.scenario import parse_scenario
from swarmnav.models.scenario_generator import GeneratorOptions, generate
from swarmnav.cli.main import main
from swarmnav.sim.difficulty import difficulty


def scene(kind: str, **options) -> str:
    return generate(kind, 2, GeneratorOptions(arena_m=6.0, **options))


def test_more_and_faster_walkers_are_harder_on_every_dynamic_metric():
    calm = difficulty(parse_scenario(scene("crowd", obstacles=2, speed_ratio=0.3)))
    busy = difficulty(parse_scenario(scene("dense_crowd", obstacles=10, speed_ratio=1.0, radius_min_m=0.15,
                                           radius_max_m=0.25)))
    assert busy["survival_time_s"] < calm["survival_time_s"]
    assert busy["survivability"] > calm["survivability"]
    assert busy["dynamic_traversability"] < calm["dynamic_traversability"] <= 1.0


def test_walls_raise_static_density_and_dispersion_and_open_ground_has_none():
    open_ground = difficulty(parse_scenario(scene("crossing", obstacles=2)))
    corridor = difficulty(parse_scenario(scene("corridor", obstacles=2)))
    assert open_ground["static_density"] == 0.0 and open_ground["dispersion"] == 0.0
    assert corridor["static_density"] > 0.0 and corridor["dispersion"] > 0.0


def test_the_oracle_ratio_is_one_when_nothing_is_in_the_way_and_above_when_a_crosser_is():
    info = difficulty(parse_scenario(scene("crossing", obstacles=3, speed_ratio=0.8)))
    assert info["oracle"]["solvable"] and info["t_star_ratio"] >= 1.0


def test_scenarios_info_prints_json_and_names_a_bad_scenario(capsys, tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(scene("head_on", obstacles=1))
    assert main(["scenarios", "info", str(path), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert {"static_density", "dispersion", "survivability", "dynamic_traversability", "t_star_ratio"} <= set(info)
    assert main(["scenarios", "info", str(tmp_path / "missing.toml")]) == 2
    assert "missing.toml" in capsys.readouterr().err
