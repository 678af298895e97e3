"""The CrowdNav table of the docs (docs/crowds.md, moved from the README) is the one generated from the committed ``--suite crowdnav`` result."""

import json
from pathlib import Path

import pytest

from swarmnav.benchmarks import crowd_table
from swarmnav.benchmarks.crowd_table import PAPER, PROTOCOL, RESULT, block, current_block
from swarmnav.benchmarks.navigation_table import read_rows

REPO = Path(__file__).resolve().parents[1]


def test_the_readme_crowdnav_table_is_the_one_generated_from_the_committed_result(capsys):
    assert crowd_table.main([str(RESULT)] + (["--protocol", str(PROTOCOL)] if PROTOCOL.is_file() else [])
                            + (["--paper", str(PAPER)] if PAPER.is_file() else [])) == 0
    generated = capsys.readouterr().out.strip()
    assert current_block((REPO / "docs" / "crowds.md").read_text()) == generated, \
        "run `make readme-table` (docs/crowds.md and models/suites/results/crowdnav.json differ)"


@pytest.mark.parametrize("path", [RESULT, PROTOCOL, PAPER])
def test_the_committed_result_has_both_settings_and_no_oracle_where_the_humans_see_the_robot(path):
    if not path.is_file():
        pytest.skip(f"{path.name} not committed")
    rows = read_rows(path)
    invisible = [r for r in rows if r["robot_visible"] is False]
    visible = [r for r in rows if r["robot_visible"] is True]
    assert {r["navigator"] for r in invisible} - {"oracle"} == {r["navigator"] for r in visible}
    assert "oracle" not in {r["navigator"] for r in visible}
    assert "oracle" in {r["navigator"] for r in invisible} or path == PAPER  # the paper file's oracle is not shown
    assert all(r["oracle_solvable_runs"] == 0 and r["yardstick"].startswith("none") for r in visible)
    assert len({r["runs"] for r in rows}) == 1
    assert all(r["discomfort_frequency"] is not None for r in rows)


def test_the_table_follows_the_rows_and_a_bad_file_is_named(tmp_path, capsys):
    rows = read_rows(RESULT)
    changed = [dict(r, success_rate=0.123456) if r["navigator"] == "follow" else r for r in rows]
    assert "| `follow` | " in block(changed) and "| 0.123 |" in block(changed) and block(changed) != block(rows)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps([{"navigator": "x", "scenario": None}]))
    assert crowd_table.main([str(bad)]) == 2
    assert "robot_visible" in capsys.readouterr().err


@pytest.mark.parametrize("seen, methods", [(False, ["ORCA", "CADRL", "LSTM-RL", "SARL"]),
                                           (True, ["ORCA", "CADRL", "LSTM-RL", "SARL", "LM-SARL"])])
def test_every_published_method_has_a_line_found_or_not(seen, methods):
    lines = crowd_table.table_lines([], seen)
    for m in methods:
        assert any(line.startswith(f"| {m}, Chen et al. (2019)") for line in lines)


def test_the_protocol_comes_first_with_the_published_figures_and_the_sample_after_without_them():
    rows = read_rows(RESULT)
    protocol = [dict(r, runs=500) for r in rows if r["navigator"] in ("oracle", "follow")]
    text = block(rows, protocol)
    assert text.index("**CrowdNav's protocol**: 500 test cases") < text.index("**Every navigator** on")
    assert text.count("| SARL, Chen et al. (2019)") == 2  # once per setting
    assert text.rindex("| SARL, Chen et al. (2019)") < text.index("**Every navigator** on")
    assert block(rows).count("| SARL, Chen et al. (2019)") == 2  # no protocol file: beside the sample


def test_the_paper_navigators_rows_take_the_place_of_the_samples_of_the_same_label_and_setting(tmp_path, capsys):
    rows = read_rows(RESULT)
    paper = [dict(r, success_rate=0.654321) for r in rows if r["navigator"] in ("iaco_local", "oracle")]
    paper.append(dict(paper[0], navigator="iaco_local+new", arm_of="iaco_local", arm_params={"evade": True}))
    text = block(rows, None, paper)
    assert text.count("| `iaco_local` †") == 2 and text.count("| `iaco_local` |") == 0  # replaced in each setting
    assert text.count("| 0.654 |") == 3  # both iaco_local rows and the new arm, never the oracle's
    assert text.index("| `iaco_local+new` (`iaco_local`: evade=True) †") < text.index("| oracle (clairvoyant")
    assert "† From `models/suites/results/crowdnav-paper-navigators.json`" in text
    assert "†" not in block(rows)
    path = tmp_path / "paper.json"
    path.write_text(json.dumps(paper))
    assert crowd_table.main([str(RESULT), "--paper", str(path)]) == 0
    assert "| `iaco_local` †" in capsys.readouterr().out


def test_the_protocols_every_online_navigator_line_counts_each_navigator_at_its_best_and_names_the_missing():
    from swarmnav.benchmarks.crowd_table import coverage_line, online_navigators
    sample = [{"navigator": "follow", "success_rate": 0.5}, {"navigator": "dwa", "success_rate": 0.2},
              {"navigator": "mppi", "success_rate": 0.0}, {"navigator": "mppi+x", "arm_of": "mppi", "success_rate": 0.9},
              {"navigator": "oracle", "success_rate": 1.0}]
    names = online_navigators(sample)
    assert names == ["dwa", "mppi"]  # follow senses no human; an arm counts as its navigator; no oracle
    protocol = [{"navigator": "mppi", "success_rate": 0.5}, {"navigator": "mppi+x", "arm_of": "mppi",
                                                             "success_rate": 0.95}]
    line = coverage_line(protocol, names)
    assert ": not met;" in line and "`mppi+x` 0.950" in line and "not run on them: `dwa`" in line
    assert "`mppi` 0.500" not in line  # its best configuration stands for it
    line = coverage_line(protocol + [{"navigator": "dwa", "success_rate": 0.9}], names)
    assert ": met;" in line and "not run" not in line
    line = coverage_line(protocol + [{"navigator": "dwa", "success_rate": 0.89}], names)
    assert ": not met;" in line and "`dwa` 0.890" in line
