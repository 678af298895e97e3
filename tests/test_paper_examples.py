"""The docs' examples of the paper planners run as written (issue 31: "the README's examples all run"): the
Python API page's ``swarmnav.plan(...)`` line plans a collision-free path, and the paper planners' commands
at their defaults exit 0 on their papers' scenarios."""

from __future__ import annotations

import re
from pathlib import Path

import swarmnav

DOCS = Path(__file__).resolve().parents[1] / "docs"


def test_the_python_api_pages_plan_example_runs_collision_free():
    text = (DOCS / "reference" / "python-api.md").read_text(encoding="utf-8")
    call = re.search(r'swarmnav\.plan\("([\w-]+)", planner="(\w+)", params=(\{[^}]*\}), seed=(\d+)\)', text)
    assert call, "the page no longer shows a swarmnav.plan(...) example"
    scenario, planner, params, seed = call.group(1), call.group(2), eval(call.group(3), {}), int(call.group(4))
    planned = swarmnav.plan(scenario, planner=planner, params=params, seed=seed)
    assert planned.length_m > 0 and planned.problem.is_collision_free(planned.waypoints)


def test_abc_at_its_defaults_plans_abdulla_and_hadis_first_scenario(capsys):
    """(gwo's is tests/test_fair_comparison.py's; adl_abc's on Kamil et al.'s scenes tests/test_kamil_variants.py's.)"""
    from swarmnav.cli.main import main
    assert main(["plan", "gwo-scenario-1", "--planner", "abc", "--seed", "0"]) == 0
