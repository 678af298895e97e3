"""The feasible variants of Kamil, Mohamed & Olewi (2020) (issue 31): their stated clearance rule holds on the
committed files, and paper mode's ``abc`` and ``adl_abc`` plan them collision-free at their defaults."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

from swarmnav.models.scenario import load_scenario, parse_scenario
from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.optimal import OptimalPlanner
from swarmnav.planners.problem import scenario_problem
from swarmnav.planners.registry import make_planner

STUDIES = Path(__file__).parents[1] / "models" / "studies"
#: case -> (printed scenario, variant folder, the factor the rule gives)
CASES = {"A": ("adl-abc-path-1", "adl-abc-feasible", 0.7), "B": ("adl-abc-case-b-path-1", "adl-abc-case-b-feasible", 0.6)}
#: the rule: 0.1 m more clearance lengthens the exact shortest route by at most 5 %
EXTRA_CLEARANCE_M, MAX_DETOUR = 0.1, 1.05


def _variant(case: str, path: int):
    _, folder, _ = CASES[case]
    return load_scenario(str(STUDIES / folder / f"{folder}-path-{path}.toml"))


def _scaled(case: str, path: int, factor: float):
    """The variant's file with every disc at ``factor`` x its printed radius."""
    printed = [ob.radius_m for ob in load_scenario(CASES[case][0]).obstacles]
    radii = iter(printed)
    text = re.sub(r"(?m)^radius_m = .*$", lambda m: f"radius_m = {next(radii) * factor!r}",
                  _variant(case, path).source_text)
    return parse_scenario(text, source=f"case {case} path {path} x {factor}")


def _detour(scenario) -> float:
    """Shortest route 0.1 m further from the discs over the shortest route (inf: none)."""
    problem = scenario_problem(scenario)
    lengths = []
    for clearance in (0.0, EXTRA_CLEARANCE_M):
        try:
            path = OptimalPlanner().plan(dataclasses.replace(problem, clearance_m=clearance), np.random.default_rng(0))
            lengths.append(path.stats.length_m)
        except NoPathFound:
            lengths.append(float("inf"))
    return lengths[1] / lengths[0]


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_variants_are_the_printed_discs_at_the_factor_the_clearance_rule_gives(case):
    printed_name, _, factor = CASES[case]
    printed = load_scenario(printed_name)
    for path in (1, 2, 3):
        variant = _variant(case, path)
        assert variant.robot_radius_m == 0.05
        assert [(ob.x_m, ob.y_m) for ob in variant.obstacles] == [(ob.x_m, ob.y_m) for ob in printed.obstacles]
        assert [ob.radius_m for ob in variant.obstacles] == pytest.approx([factor * ob.radius_m
                                                                          for ob in printed.obstacles])
        assert _detour(variant) <= MAX_DETOUR, f"case {case} path {path} threads a slit at {factor}"
    # the next multiple of 0.05 up breaks the rule on some path (path 1 in both cases)
    assert _detour(_scaled(case, 1, factor + 0.05)) > MAX_DETOUR


@pytest.mark.parametrize(("planner", "case", "path"), [("abc", "A", 1), ("adl_abc", "B", 2)])
def test_paper_mode_plans_the_variants_collision_free_at_its_defaults(planner, case, path):
    """Issue 31's target: at least 4 of seeds 0-4 (``swarmnav bench defaults`` gives the count over 10)."""
    problem = scenario_problem(_variant(case, path))
    found = 0
    for seed in range(5):
        if found == 4:
            break                                   # the target is met; seed 4 would not change the verdict
        try:
            plan = make_planner(planner, {}).plan(problem, np.random.default_rng(seed))
        except NoPathFound:
            continue
        assert plan.stats.extra["mode"] == "paper" and problem.is_collision_free(plan.waypoints)
        found += 1
    assert found >= 4
