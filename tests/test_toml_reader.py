"""The one TOML reader (models/toml_table.py) behind scenario, study and suite files and component parameters.

Table-driven: a valid document of each kind with one malformed value (a wrong type, a number out of range,
an unknown key) exits 2 (or raises ConfigError) with one line naming the file, the field's dotted path and
the problem.  Hypothesis: any value of a wrong type in a numeric field of each kind is a ConfigError naming
exactly that field.
"""

import copy
import json
import math
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.suites import load_suite
from swarmnav.models.toml_table import TomlTable, parse_toml, within
from swarmnav.planners.registry import make_planner
from swarmnav.cli.main import main
from swarmnav.study.spec import parse_study

SCENARIO = {
    "name": "reader", "seed": 1, "time_limit_s": 30.0,
    "arena": {"width_m": 6.0, "height_m": 6.0, "walls": True},
    "robot": {"radius_m": 0.15, "clearance_m": 0.05},
    "start": {"x": 0.5, "y": 0.5}, "goal": {"x": 5.5, "y": 5.5, "tolerance_m": 0.1},
    "sensors": {"count": 12, "range_m": 0.4},
    "planner": {"name": "gwo", "params": {"iterations": 5}},
    "sim": {"control_hz": 50.0, "stop_on_collision": False},
    "obstacles": [{"x": 3.0, "y": 3.0, "radius_m": 0.5},
                  {"x": 4.0, "y": 1.5, "radius_m": 0.3,
                   "motion": {"kind": "random_walk", "step_m": 0.2, "period_s": 1.0}}],
}
STUDY = {
    "scenarios": ["gwo-scenario-1"], "seeds": 2, "wall_limit_s": 60.0, "budget": {"evaluations": 500},
    "planners": [{"name": "gwo", "params": {"iterations": 5}}],
    "paper": [{"scenario": "gwo-scenario-1", "planner": "gwo", "metric": "plan_length_m", "value": 14.1}],
}
SUITE = {
    "name": "reader", "version": 1, "defaults": {"arena_m": 8.0, "obstacles": 2},
    "groups": [{"name": "cross", "kind": "crossing", "seeds": [0, 2], "options": {"speed_ratio": 0.5}}],
}
DOCUMENTS = {"scenario": SCENARIO, "study": STUDY, "suite": SUITE}


def toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    return "{" + ", ".join(f"{toml_value(str(k))} = {toml_value(v)}" for k, v in value.items()) + "}"


def edited(kind: str, path: tuple, value) -> dict:
    """The kind's valid document with the value at ``path`` replaced (or added)."""
    doc = copy.deepcopy(DOCUMENTS[kind])
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    parent[path[-1]] = value
    return doc


def write(folder: Path, kind: str, doc: dict) -> Path:
    path = folder / f"{kind}.toml"
    path.write_text("".join(f"{toml_value(k)} = {toml_value(v)}\n" for k, v in doc.items()), encoding="utf-8")
    return path


def load(kind: str, path: Path):
    """Read a file of the kind with its own reader, and a scenario's planner from its parameters (what the
    commands call)."""
    text = path.read_text(encoding="utf-8")
    if kind == "scenario":
        scenario = parse_scenario(text, str(path))
        return make_planner(scenario.planner_name, scenario.planner_params, scenario.source_path, trust_code=False)
    if kind == "study":
        return parse_study(text, str(path))
    return load_suite(str(path))


@pytest.mark.parametrize("kind", DOCUMENTS)
def test_the_unedited_documents_load(kind, tmp_path):
    assert load(kind, write(tmp_path, kind, DOCUMENTS[kind])) is not None


# (kind, where in the document, the malformed value, the field named, a word of the problem)
MALFORMED = [
    ("scenario", ("arena", "width_m"), "wide", "arena.width_m", "expected a number"),
    ("scenario", ("sensors", "count"), 0, "sensors.count", "must be in [1, "),
    ("scenario", ("robot", "clearance_m"), -0.1, "robot.clearance_m", "must not be negative"),
    ("scenario", ("time_limit_s",), math.inf, "time_limit_s", "must be finite"),
    ("scenario", ("obstacles", 1, "motion", "period_s"), 0.0, "obstacles[1].motion.period_s", "must be positive"),
    ("scenario", ("obstacles", 1, "motion", "kind"), "teleport", "obstacles[1].motion.kind", "unknown value"),
    ("scenario", ("sim", "stop_on_collision"), 1, "sim.stop_on_collision", "expected true or false"),
    ("scenario", ("goal", "colour"), "red", "goal.colour", "unknown key"),
    ("scenario", ("obstacles", 0, "bogus"), 1, "obstacles[0].bogus", "unknown key"),
    ("scenario", ("planner", "params"), 3, "planner.params", "expected a table"),
    ("scenario", ("planner", "params", "iterations"), "many", "planner.params.iterations", "expected an integer"),
    ("scenario", ("planner", "params", "iterations"), -3, "planner.params.iterations", "must be in"),
    ("scenario", ("planner", "params", "wolves"), 3, "planner.params.wolves", "unknown parameter"),
    ("study", ("wall_limit_s",), "long", "wall_limit_s", "expected a number"),
    ("study", ("wall_limit_s",), 0, "wall_limit_s", "must be in (0, 1e+06]"),
    ("study", ("seeds",), [0, -1], "seeds[1]", "must be in [0, 9223372036854775807]"),
    ("study", ("mode",), "fast", "mode", "unknown value"),
    ("study", ("paired_seeds",), "yes", "paired_seeds", "expected true or false"),
    ("study", ("budget", "evaluations"), 0, "budget.evaluations", "must be at least 1"),
    ("study", ("budget", "colour"), 1, "budget.colour", "unknown key"),
    ("study", ("planners", 0, "colour"), 1, "planners[0].colour", "unknown key"),
    ("study", ("planners", 0, "params", "iterations"), "many", "planners[0].params.iterations", "expected an"),
    ("study", ("planners", 0, "params", "iterations"), -3, "planners[0].params.iterations", "must be in"),
    ("study", ("paper", 0, "value"), "high", "paper[0].value", "expected a number"),
    ("study", ("colour",), 1, "colour", "unknown key"),
    ("study", ("time_limit_s",), 0.051, "time_limit_s", "not a whole number of control periods (0.02 s) for scenario"),
    ("study", ("time_limit_s",), 1e12, "time_limit_s", "physics steps (at most"),
    ("suite", ("version",), "one", "version", "expected an integer"),
    ("suite", ("defaults", "obstacles"), "three", "defaults.obstacles", "expected an integer"),
    ("suite", ("defaults", "arena_m"), 2.0, "defaults.arena_m", "must exceed"),
    ("suite", ("groups", 0, "options", "speed_ratio"), -1.0, "groups[0].options.speed_ratio", "must be in (0, 100]"),
    ("suite", ("groups", 0, "options", "wolves"), 3, "groups[0].options.wolves", "unknown generator option"),
    ("suite", ("groups", 0, "seeds"), [5, 2], "groups[0].seeds", "first < end"),
    ("suite", ("groups", 0, "colour"), 1, "groups[0].colour", "unknown key"),
    ("suite", ("colour",), 1, "colour", "unknown key"),
]


@pytest.mark.parametrize("kind, where, value, field, problem", MALFORMED,
                         ids=[f"{c[0]}:{c[3]}={c[2]!r}" for c in MALFORMED])
def test_a_malformed_value_is_one_line_naming_the_file_and_the_field(kind, where, value, field, problem, tmp_path,
                                                                      capsys):
    path = write(tmp_path, kind, edited(kind, where, value))
    with pytest.raises(ConfigError) as info:
        load(kind, path)
    assert (info.value.source, info.value.field) == (str(path), field)
    assert problem in info.value.problem and "\n" not in str(info.value)
    if kind != "suite":  # a suite is named on the command line by its bundled name only
        argv = ["plan", str(path)] if kind == "scenario" else ["study", str(path), "--out", str(tmp_path / "out")]
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"{path}: {field}: " in err and problem in err


def test_a_command_line_parameter_names_its_field(capsys):
    assert main(["plan", "gwo-scenario-1", "--planner", "gwo", "--set", "iterations=-1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "planner.params.iterations: must be in" in err


@pytest.mark.parametrize("kind", DOCUMENTS)
def test_malformed_toml_names_the_file_and_toml(kind, tmp_path):
    path = tmp_path / f"{kind}.toml"
    path.write_text('name = "unterminated\n', encoding="utf-8")
    with pytest.raises(ConfigError) as info:
        load(kind, path)
    assert (info.value.source, info.value.field) == (str(path), "toml") and "\n" not in str(info.value)


# Numeric fields of each kind (a list is a valid value of none of them).
NUMERIC = {
    "scenario": [("arena", "width_m"), ("robot", "radius_m"), ("start", "x"), ("goal", "tolerance_m"),
                 ("sensors", "count"), ("sensors", "range_m"), ("sim", "control_hz"), ("time_limit_s",), ("seed",),
                 ("obstacles", 0, "radius_m"), ("obstacles", 1, "motion", "step_m"),
                 ("planner", "params", "iterations")],
    "study": [("wall_limit_s",), ("time_limit_s",), ("clearance_m",), ("budget", "evaluations"),
              ("paper", 0, "value")],
    "suite": [("version",), ("defaults", "obstacles"), ("defaults", "arena_m"),
              ("groups", 0, "options", "speed_ratio")],
}
FIELDS = [(kind, where) for kind, wheres in NUMERIC.items() for where in wheres]
WRONG_TYPES = (st.text(max_size=12) | st.booleans() | st.lists(st.integers(0, 9), min_size=1, max_size=3)
               | st.dictionaries(st.sampled_from(["a", "x"]), st.integers(0, 9), max_size=2))


def dotted(where: tuple) -> str:
    return "".join(f"[{k}]" if isinstance(k, int) else (f".{k}" if i else k) for i, k in enumerate(where))


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(FIELDS), WRONG_TYPES)
def test_a_value_of_the_wrong_type_is_a_config_error_naming_exactly_its_field(case, value):
    kind, where = case
    with tempfile.TemporaryDirectory() as folder:
        path = write(Path(folder), kind, edited(kind, where, value))
        with pytest.raises(ConfigError) as info:
            load(kind, path)
    assert (info.value.source, info.value.field) == (str(path), dotted(where)), str(info.value)
    assert "\n" not in str(info.value)


def test_a_table_reports_the_first_unread_key_and_a_key_that_does_not_read_as_one():
    table = TomlTable({"x": 1.0, "z": 2, "y": 3}, "start", "f.toml")
    assert table.number("x") == 1.0
    with pytest.raises(ConfigError, match=r"^f\.toml: start\.y: unknown key$"):
        table.close()
    with pytest.raises(ConfigError, match=r"^f\.toml: start\.'\\n': unknown key$"):
        TomlTable({"\n": 1}, "start", "f.toml").close()


def test_bounds_and_defaults_of_the_getters():
    top = parse_toml("a = 3\nb = 2.5\nc = 5.0\n", "f.toml")
    assert top.integer("a", bounds=within(1, 3)) == 3 and top.number("missing", 7.5) == 7.5
    with pytest.raises(ConfigError, match=r"^f\.toml: b: must be at most 2, got 2\.5$"):
        top.number("b", bounds=within(-math.inf, 2))
    with pytest.raises(ConfigError, match=r"^f\.toml: c: expected an integer, got 5\.0$"):
        top.integer("c")
    with pytest.raises(ConfigError, match=r"^f\.toml: d: is required$"):
        top.string("d")
