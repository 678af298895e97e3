"""`bench navigation --arms FILE.toml` and BARN's configurations as data (models/suites/barn-navigators.toml):
the file holds the configurations the committed BARN results ran, and a bad arms file is one line, exit 2."""

import json
from pathlib import Path

import pytest

from swarmnav.benchmarks.navigation import read_arms
from swarmnav.cli.main import main
from test_barn import needs_barn

ROOT = Path(__file__).resolve().parents[1]
CONFIGURATIONS = ROOT / "models/suites/barn-navigators.toml"
RESULTS = ROOT / "models/suites/results"


def _protocol_configurations() -> dict[str, list[dict]]:
    """navigator -> the parameters of every committed BARN protocol row of 50 runs or more."""
    out: dict[str, list[dict]] = {}
    for path in sorted(RESULTS.glob("barn-protocol-*.json")) + [RESULTS / "barn.json"]:
        for row in json.loads(path.read_text()):
            if row["scenario"] is None and row["runs"] >= 50 and row.get("navigator_params"):
                out.setdefault(row.get("arm_of") or row["navigator"], []).append(row["navigator_params"])
    return out


def test_every_configuration_of_the_file_is_one_the_committed_results_ran():
    arms = read_arms(str(CONFIGURATIONS))
    ran = _protocol_configurations()
    assert sorted(a.navigator for a in arms) == sorted(ran), "one configuration per navigator with BARN results"
    for arm in arms:
        assert arm.params in ran[arm.navigator], f"{arm.label}: no committed BARN row ran {arm.params}"


@pytest.mark.parametrize("text, field", [
    ('[[navigators]]\nname = "mppi"\nparams = { samples = [100, 300] }\n', "navigators[0].params.samples: a list"),
    ('[[navigators]]\nname = "mppi"\nparams = { samplez = 3 }\n', "navigators[0].params.samplez: unknown parameter"),
    ('[[navigators]]\nname = "oracle"\n', "navigators[0].name: 'oracle' is the yardstick"),
    ('[[navigators]]\nname = "policy"\nparams = { policy = "os:system" }\n', "navigators[0].params.policy: names code"),
    ('[[navigators]]\nname = "dwa"\n[[navigators]]\nname = "dwa"\n', "navigators[1].label: label 'dwa' is used twice"),
    ('navigator = 1\n', "navigator"),
    ('[[navigators]]\nname = "dwa"\nlabel = "' + "x" * 100_000 + '"\n', "navigators[0].label: must be at most"),
    ('[[navigators]]\nname = "dwa"\nlabel = "../up"\n', "navigators[0].label:"),
])
def test_a_bad_arms_file_is_one_line_naming_the_file_and_the_field(tmp_path, capsys, text, field):
    path = tmp_path / "arms.toml"
    path.write_text(text)
    assert main(["bench", "navigation", "--suite", "barn", "--barn-worlds", "1", "--arms", str(path), "--json"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{path}: {field}" in err


def test_a_missing_arms_file_is_one_line(tmp_path, capsys):
    assert main(["bench", "navigation", "--arms", str(tmp_path / "none.toml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--arms: file does not exist" in err


@needs_barn
def test_an_arms_file_row_runs_under_its_label_with_its_parameters(tmp_path, capsys):
    path = tmp_path / "arms.toml"
    path.write_text('[[navigators]]\nname = "dstar_replan"\nlabel = "d*"\n'
                    'params = { footprint = "box", cost_weight = 10, max_decel_m_s2 = 2 }\n')
    assert main(["bench", "navigation", "--suite", "barn", "--barn-worlds", "1", "--arms", str(path), "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["navigator"] for r in rows] == ["d*"]
    assert rows[0]["navigator_params"] == {"footprint": "box", "cost_weight": 10, "max_decel_m_s2": 2}
    assert rows[0]["runs"] == 1 and rows[0]["success_rate"] + rows[0]["collision_rate"] + rows[0]["timeout_rate"] == 1
