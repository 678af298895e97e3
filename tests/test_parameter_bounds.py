"""Every parameter of every registered planner and navigator is bounded (issue 21, item 5).

A property test feeds each component's numeric parameters extreme values (0,
negative, NaN, +-inf, 1e300, 2**64) on top of tiny budgets, on a tiny scenario,
and requires a result (a plan, or a short run for a navigator), a planning
failure (``NoPathFound``: exit 3) or a one-line ConfigError naming the parameter,
never any other exception, and never a hang (each example has a time guard).

50 examples per component in CI; set ``SWARMNAV_BOUNDS_EXAMPLES`` for more.
"""

from __future__ import annotations

import math
import os
import signal
from contextlib import contextmanager

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from swarmnav.controllers.navigators import NAVIGATORS, make_navigator
from swarmnav.models.errors import ConfigError
from swarmnav.models.parameters import numeric_parameters, parameter_ranges
from swarmnav.models.scenario import parse_scenario
from swarmnav.planners.errors import PlanningError
from swarmnav.planners.problem import scenario_problem
from swarmnav.planners.registry import PLANNERS, make_planner

EXAMPLES = int(os.environ.get("SWARMNAV_BOUNDS_EXAMPLES", "50"))
GUARD_S = 30  # a value that makes one example run longer than this is a missing bound

TINY = """
name = "tiny"
seed = 0
time_limit_s = 0.3
arena = { width_m = 3.0, height_m = 3.0, walls = false }
robot = { radius_m = 0.15, max_speed_m_s = 0.2 }
start = { x = 0.4, y = 0.4, heading_deg = 45.0 }
goal = { x = 2.6, y = 2.6, tolerance_m = 0.1 }
sensors = { count = 8, range_m = 0.4 }
planner = { name = "astar", params = {} }
sim = { cell_m = 0.1 }

[[obstacles]]
x = 1.5
y = 1.5
radius_m = 0.3

[[obstacles]]
x = 0.8
y = 2.0
radius_m = 0.15
motion = { kind = "linear", speed_m_s = 0.1, heading_deg = 0.0, at_edge = "reflect" }
"""

CONTINUOUS = {"population": 4, "iterations": 2, "samples": 16, "polish_rounds": 0, "fit_push_rounds": 0,
              "repair_rounds": 1}
TINY_BUDGETS = {
    "abc": {**CONTINUOUS, "mcn": 2}, "adl_abc": {**CONTINUOUS, "mcn": 2}, "gwo": CONTINUOUS, "pso": CONTINUOUS,
    "immas": {"iterations": 2, "max_evaluations": 200},
    "iaco": {"ants": 2, "iterations": 2}, "aco": {"ants": 2, "iterations": 2}, "mmas": {"ants": 2, "iterations": 2},
    "maco": {"ants": 2, "iterations": 2, "nodes": 5},
    "policy": {"policy": "reactive_policy:act"},
}
EXTREMES = [0, -1, 0.0, -0.5, math.nan, math.inf, -math.inf, 1e300, -1e300, 2**64, -(2**64)]


@contextmanager
def time_guard(seconds: int):
    def expire(signum, frame):
        raise TimeoutError(f"an example ran longer than {seconds} s: a parameter lacks a bound")
    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def settings_for(budgets: dict, data, names: tuple[str, ...]) -> dict:
    chosen = data.draw(st.lists(st.sampled_from(names), min_size=1, max_size=3, unique=True), label="parameters")
    params = dict(budgets)
    for name in chosen:
        params[name] = data.draw(st.sampled_from(EXTREMES), label=name)
    return params


def accepts(error: ConfigError, params: dict, budgets: dict) -> bool:
    """A one-line ConfigError naming one of the parameters it was given."""
    text = str(error)
    return "\n" not in text and any(error.field.endswith(f".params.{key}") for key in params)


@pytest.fixture(scope="module")
def tiny():
    scenario = parse_scenario(TINY, "<tiny>")
    return scenario, scenario_problem(scenario)


HYPOTHESIS = settings(max_examples=EXAMPLES, deadline=None, derandomize=True,
                      suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


@pytest.mark.parametrize("name", sorted(PLANNERS))
def test_every_planner_parameter_gives_a_result_or_one_config_error(tiny, name):
    names = numeric_parameters(PLANNERS[name])
    if not names:
        pytest.skip(f"{name} has no numeric parameter")
    scenario, problem = tiny
    budgets = TINY_BUDGETS.get(name, {})

    @HYPOTHESIS
    @given(data=st.data())
    def check(data):
        params = settings_for(budgets, data, names)
        with time_guard(GUARD_S):
            try:
                planner = make_planner(name, params, "<fuzz>")
            except ConfigError as error:
                assert accepts(error, params, budgets), str(error)
                return
            try:
                path = planner.plan(problem, np.random.default_rng(0))
            except PlanningError:
                return
            except ConfigError as error:
                assert accepts(error, params, budgets), str(error)
                return
        assert np.all(np.isfinite(path.waypoints))

    check()


@pytest.mark.parametrize("name", sorted(NAVIGATORS))
def test_every_navigator_parameter_gives_a_run_or_one_config_error(tiny, name, monkeypatch):
    from swarmnav.sim.episode import EpisodeSpec, plan_episode, run_episode
    from swarmnav.sim.scene import compile_scene

    monkeypatch.syspath_prepend(os.path.dirname(__file__))  # reactive_policy for the policy navigator
    names = numeric_parameters(NAVIGATORS[name])
    if not names:
        pytest.skip(f"{name} has no numeric parameter")
    scenario, _ = tiny
    scene = compile_scene(scenario)  # compiled once: every example runs on it
    budgets = TINY_BUDGETS.get(name, {})

    @HYPOTHESIS
    @given(data=st.data())
    def check(data):
        params = settings_for(budgets, data, names)
        with time_guard(GUARD_S):
            try:
                make_navigator(name, params, "<fuzz>")
                episode = run_episode(plan_episode(EpisodeSpec(scenario, navigator=name, navigator_params=params),
                                                   scene=scene))
            except ConfigError as error:
                assert accepts(error, params, budgets), str(error)
                return
        assert episode.result.sim_time_s > 0

    check()


@pytest.mark.parametrize("registry", [PLANNERS, NAVIGATORS], ids=["planners", "navigators"])
def test_every_numeric_parameter_declares_its_range(registry):
    missing = {name: sorted(set(numeric_parameters(cls)) - set(parameter_ranges(cls)))
               for name, cls in registry.items()}
    assert not {name: keys for name, keys in missing.items() if keys}


def test_one_declaration_per_parameter_gives_the_reader_its_checks_and_the_listing_its_rows():
    """A navigator's field (``param``) carries its range or choices; the reader (TOML, ``--set``) and
    ``navigators --json`` both take them from there, the safety layer's switches included."""
    import pathlib

    from swarmnav.controllers.navigators import make_driver, navigator_table
    from swarmnav.controllers.safety_layer import SafetyLayer
    with pytest.raises(ConfigError, match=r"navigator\.params\.strategy: unknown value 'fast' "
                                          r"\(expected one of: paper, wait_only\)"):
        make_navigator("iaco_local", {"strategy": "fast"})
    with pytest.raises(ConfigError, match=r"navigator\.params\.same_line_deg: must be in \[0, 90\), got 90"):
        make_navigator("iaco_local", {"same_line_deg": 90})
    with pytest.raises(ConfigError, match=r"navigator\.params\.time_before_collision_s: must be in \(0, 600\]"):
        make_driver("dwa", {"time_before_collision_s": 0.0})
    rows = {row["name"]: row for row in navigator_table("iaco_local")}
    assert rows["strategy"]["choices"] == ["paper", "wait_only"] and rows["same_line_deg"]["range"] == "[0, 90)"
    assert rows["evade"]["default"] is False and rows["evade_trigger_s"]["range"] == "[0, 600]"
    assert {row["name"]: row["default"] for row in navigator_table("replan")}["evade"] is True
    assert set(numeric_parameters(SafetyLayer)) <= set(parameter_ranges(SafetyLayer))
    # No navigator keeps a second declaration or a checking helper of its own, and no planner declares its
    # ranges in the older class-level dict: every parameter is one param(default, range|choices) field.
    root = pathlib.Path(__file__).resolve().parents[1]
    for path in (root / "controllers" / "navigators").glob("*.py"):
        text = path.read_text()
        assert "parameter_ranges" not in text and "def check_" not in text, path.name
    assert [path.name for path in (root / "planners").glob("*.py") if "parameter_ranges" in path.read_text()] == []


def test_a_value_out_of_range_names_the_field_and_the_range():
    with pytest.raises(ConfigError, match=r"navigator\.params\.horizon_s: must be in \(0, 10\], got 1e\+12"):
        make_navigator("dwa", {"horizon_s": 1e12})
    with pytest.raises(ConfigError, match=r"planner\.params\.iterations: must be in .*got 18446744073709551616"):
        make_planner("gwo", {"iterations": 2**64})


@pytest.mark.parametrize("line,field", [
    ("seeds = 1000000000000", "seeds"),
    ("seeds = [18446744073709551615]", "seeds[0]"),
    ("seeds = [-1]", "seeds[0]"),
    ("seeds = 2\nworld_seeds = 1000000000", "world_seeds"),
    ("seeds = 2\nwall_limit_s = inf", "wall_limit_s"),
    ("seeds = 2\ntime_limit_s = inf", "time_limit_s"),
    ("seeds = 90000\nworld_seeds = 90000", "seeds"),
])
def test_every_study_field_is_bounded(line, field):
    from swarmnav.study.spec import parse_study
    with pytest.raises(ConfigError) as caught:
        parse_study(f'scenarios = ["gwo-scenario-1"]\n{line}\n[[planners]]\nname = "gwo"\n', "s.toml")
    assert caught.value.field == field and "\n" not in str(caught.value)
