"""Fuzzing the scenario parser with Hypothesis (issue 9).

Documents are built from the schema: a valid scenario with every motion kind,
then random edits that put wrong types, extreme numbers (0, negative, NaN,
+-inf, 1e300), strings with control characters and path separators, arrays
and tables where scalars belong, delete keys and add unknown ones.  Every
document must give a Scenario or a ConfigError naming a field in one line,
never any other exception.

200 examples in CI; set ``SWARMNAV_FUZZ_EXAMPLES`` for more.
"""

import copy
import json
import math
import os

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import Scenario, parse_scenario

EXAMPLES = int(os.environ.get("SWARMNAV_FUZZ_EXAMPLES", "200"))

VALID = {
    "name": "fuzz", "description": "schema seed", "seed": 3, "time_limit_s": 20.0,
    "arena": {"width_m": 6.0, "height_m": 6.0, "walls": True},
    "robot": {"radius_m": 0.15, "max_speed_m_s": 0.2, "clearance_m": 0.05},
    "start": {"x": 0.5, "y": 0.5, "heading_deg": 45.0},
    "goal": {"x": 5.5, "y": 5.5, "tolerance_m": 0.1},
    "sensors": {"count": 12, "range_m": 0.4},
    "planner": {"name": "astar", "params": {}},
    "navigator": {"name": "follow", "params": {}},
    "sim": {"timestep_s": 0.002, "control_hz": 50.0, "stop_on_collision": False, "cell_m": 0.05},
    "obstacles": [
        {"x": 3.0, "y": 3.0, "radius_m": 0.5, "height_m": 0.5},
        {"x": 1.5, "y": 4.0, "radius_m": 0.3,
         "motion": {"kind": "linear", "speed_m_s": 0.1, "heading_deg": 10.0, "at_edge": "reflect"}},
        {"x": 4.0, "y": 1.5, "radius_m": 0.3,
         "motion": {"kind": "random_walk", "step_m": 0.2, "period_s": 1.0}},
        {"x": 4.5, "y": 4.0, "radius_m": 0.2,
         "motion": {"kind": "waypoints", "speed_m_s": 0.1, "points": [[4.5, 2.0], [2.0, 2.0]]}},
    ],
}

NUMBERS = st.sampled_from([0, -1, 1, 0.0, -0.0, -5.5, 1e-300, 1e300, -1e300, 2**63 - 1, -(2**63),
                           math.nan, math.inf, -math.inf, 0.5, 1e6, 1e-9])
HOSTILE_TEXT = st.text(alphabet=st.characters(exclude_categories=("Cs",)), max_size=20) | st.sampled_from(
    ["", "..", "../../etc/x y", "a/b", "a\\b", "nul\x00byte", "tab\tnew\nline", "\x7f", "x" * 200,
     "random_walk", "linear", "waypoints", "astar", "reflect", "stop"])
SCALARS = NUMBERS | HOSTILE_TEXT | st.booleans() | st.floats(allow_nan=True, allow_infinity=True) \
    | st.integers(min_value=-(2**63), max_value=2**63 - 1)
VALUES = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=3)
                      | st.dictionaries(st.sampled_from(["x", "y", "kind", "bogus", "radius_m"]), inner, max_size=3),
                      max_leaves=6)


def paths(doc, prefix=()):
    """Every (key path) in a document, tables and arrays included."""
    items = doc.items() if isinstance(doc, dict) else enumerate(doc) if isinstance(doc, list) else ()
    for key, value in items:
        yield prefix + (key,)
        yield from paths(value, prefix + (key,))


@st.composite
def documents(draw):
    doc = copy.deepcopy(VALID)
    for _ in range(draw(st.integers(min_value=1, max_value=4))):
        all_paths = list(paths(doc))
        if not all_paths:
            break
        path = draw(st.sampled_from(all_paths))
        parent = doc
        for key in path[:-1]:
            parent = parent[key]
        action = draw(st.sampled_from(["replace", "replace", "replace", "delete", "extra"]))
        if action == "replace":
            parent[path[-1]] = draw(VALUES)
        elif action == "delete":
            del parent[path[-1]]
        elif isinstance(parent, dict):
            parent[draw(HOSTILE_TEXT.filter(bool))] = draw(VALUES)
        else:
            parent.append(draw(VALUES))
    return doc


def toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    return "{" + ", ".join(f"{toml_value(str(k))} = {toml_value(v)}" for k, v in value.items()) + "}"


def to_toml(doc: dict) -> str:
    """Top-level keys one per line, tables inline (TOML 1.0)."""
    lines = []
    for key, value in doc.items():
        if key == "obstacles" and isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            continue
        lines.append(f"{toml_value(str(key))} = {toml_value(value)}")
    obstacles = doc.get("obstacles")
    if isinstance(obstacles, list) and obstacles and all(isinstance(v, dict) for v in obstacles):
        for ob in obstacles:
            lines.append("[[obstacles]]")
            lines += [f"{toml_value(str(k))} = {toml_value(v)}" for k, v in ob.items()]
    return "\n".join(lines) + "\n"


def test_the_unedited_schema_document_is_a_valid_scenario():
    scenario = parse_scenario(to_toml(VALID), "<fuzz>")
    assert scenario.name == "fuzz" and len(scenario.obstacles) == 4


@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(documents())
def test_every_document_is_a_scenario_or_a_config_error_naming_a_field(doc):
    text = to_toml(doc)
    try:
        scenario = parse_scenario(text, "<fuzz>")
    except ConfigError as exc:
        assert exc.field, f"no field named for {text!r}"
        assert "\n" not in str(exc) and "\r" not in str(exc), str(exc)
    else:
        assert isinstance(scenario, Scenario)
        assert len(scenario.discs_at(0.0)) == len(scenario.obstacles)
