"""Random disc fields: the scenario file a study runs is the problem the planner tests use."""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest

from swarmnav.models.disc_fields import disc_field_toml, draw_disc_field
from swarmnav.models.scenario import load_scenario, parse_scenario
from swarmnav.planners.problem import scenario_problem
from swarmnav.planners.random_fields import random_disc_field


@pytest.mark.parametrize("count, seed", [(10, 0), (25, 4), (40, 9)])
def test_the_scenario_file_plans_the_same_problem(count, seed, tmp_path):
    path = tmp_path / "field.toml"
    path.write_text(disc_field_toml(count, seed))
    from_file = scenario_problem(load_scenario(str(path)))
    direct = random_disc_field(count, seed)
    for field in dataclasses.fields(direct):
        assert getattr(from_file, field.name) == getattr(direct, field.name), field.name


def test_fields_are_deterministic_and_keep_their_gaps_and_endpoints_free():
    discs = draw_disc_field(40, 7)
    assert discs == draw_disc_field(40, 7) and discs != draw_disc_field(40, 8)
    assert len(discs) == 40
    for a, b in itertools.combinations(discs, 2):
        assert math.hypot(a.x_m - b.x_m, a.y_m - b.y_m) >= a.radius_m + b.radius_m + 0.1 - 1e-12
    scenario = parse_scenario(disc_field_toml(40, 7))
    reach = np.array([d.radius_m for d in discs]) + scenario.robot_radius_m + scenario.clearance_m
    for end in (scenario.start, scenario.goal):
        gaps = np.hypot([d.x_m - end.x_m for d in discs], [d.y_m - end.y_m for d in discs])
        assert np.all(gaps > reach)
