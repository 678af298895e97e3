"""Evidence a paper can cite (issue 31): the seed rule and underpowered verdicts, single values for
deterministic planners, the difference's interval, recorded inputs and the freshness check, --claims-only,
and the report's counts."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from swarmnav.cli.main import main
from swarmnav.study import power
from swarmnav.study.claim_spec import Claim
from swarmnav.study.claims import CONTRADICTED, INCONCLUSIVE, REPRODUCES, UNDERPOWERED, claims_document, verdicts
from swarmnav.study.grid import count_cells, expand
from swarmnav.study.readme_table import RESULTS_DIR
from swarmnav.study.report_tables import merge_identical
from swarmnav.study.spec import load_study

REPO = Path(__file__).resolve().parents[1]


def _rows(label, values, planner="x", scenario="s", outcome="ok"):
    return [{"scenario": scenario, "label": label, "planner": planner, "navigator_label": "follow", "seed": i,
             "world_seed": None, "outcome": outcome, "success": outcome == "ok",
             "plan_length_m": v if outcome == "ok" else None} for i, v in enumerate(values)]


def _claim(**kw):
    base = dict(id="c", statement="s", source="x", scenario="s", metric="plan_length_m", better="lower",
                planner="A", than=("B",), test="rank_sum")
    return Claim(**{**base, **kw})


def test_the_seed_rule_is_the_smallest_n_that_can_reach_alpha_after_holm_and_at_least_ten():
    # two-sided exact signed-rank: the smallest p with n pairs is 2 / 2^n
    assert power.smallest_p("signed_rank", 7, 7) == pytest.approx(2 / 2 ** 7)
    # 12 pairs in a study: alpha / m = 0.00417 needs 2 / 2^n below it, n = 9; at least 10 seeds in any case
    assert power.seeds_needed("signed_rank", 12, 0.05) == 10
    assert power.seeds_needed("signed_rank", 40, 0.05) == 11          # 2 / 2^11 < 0.05 / 40 < 2 / 2^10
    assert power.seeds_needed("fisher", 10_000, 0.05) > 10 == power.seeds_needed("fisher", 1, 0.05)
    assert power.can_reach("rank_sum", 3, 3, 1, 0.05) and not power.can_reach("rank_sum", 2, 2, 1, 0.05)


def test_a_run_that_cannot_reach_alpha_is_underpowered_not_inconclusive():
    few = _rows("A", [1.0, 1.1]) + _rows("B", [5.0, 5.1])
    [claim] = verdicts([_claim()], few)
    assert claim["verdict"] == UNDERPOWERED and claim["a12"] == 1.0 and not claim["pairs"][0]["reachable"]
    # the same shift with ten a side reproduces; no shift with ten a side is inconclusive
    rng = np.random.default_rng(1)
    many = _rows("A", 1 + rng.random(10)) + _rows("B", 5 + rng.random(10))
    assert verdicts([_claim()], many)[0]["verdict"] == REPRODUCES
    same = _rows("A", rng.random(10)) + _rows("B", rng.random(10))
    assert verdicts([_claim()], same)[0]["verdict"] == INCONCLUSIVE
    # no completed run on a side: nothing can be tested, underpowered
    failed = _rows("A", [1.0] * 10) + _rows("B", [0.0] * 10, outcome="no_path")
    assert verdicts([_claim()], failed)[0]["verdict"] == UNDERPOWERED


def test_deterministic_sides_count_once_and_compare_single_values():
    rows = _rows("A", [5.0] * 10, planner="astar") + _rows("B", [6.0] * 10, planner="immas")
    [claim] = verdicts([_claim()], rows)
    pair = claim["pairs"][0]
    assert pair["test"] == "single_values" and pair["n"] == [1, 1] and claim["single_values"]
    assert claim["verdict"] == REPRODUCES and claim["p_holm"] != claim["p_holm"]  # NaN: no test
    assert claim["difference"] == -1.0
    # the opposite claim is contradicted by the same single values
    assert verdicts([_claim(planner="B", than=("A",))], rows)[0]["verdict"] == CONTRADICTED


def test_a_deterministic_side_against_a_stochastic_one_is_a_one_sample_signed_rank_test():
    rng = np.random.default_rng(2)
    others = 6 + rng.random(12)
    rows = _rows("A", [5.0] * 12, planner="immas") + _rows("B", others, planner="mmas")
    [claim] = verdicts([_claim()], rows)
    pair = claim["pairs"][0]
    assert pair["test"] == "one_sample" and pair["n"] == [1, 12]
    assert pair["p"] == pytest.approx(stats.wilcoxon(others - 5.0).pvalue) and claim["verdict"] == REPRODUCES
    # a stochastic planner that varies is never single-valued, even with a deterministic name's neighbour
    varied = _rows("A", 5 + rng.random(12), planner="immas")
    assert verdicts([_claim()], varied + _rows("B", others, planner="mmas"))[0]["pairs"][0]["test"] == "rank_sum"


def test_the_difference_is_claimed_minus_other_with_a_bootstrap_interval_around_it():
    rng = np.random.default_rng(3)
    a, b = 1 + rng.random(15), 2 + rng.random(15)
    [claim] = verdicts([_claim()], _rows("A", a) + _rows("B", b))
    assert claim["difference"] == pytest.approx(a.mean() - b.mean())
    low, high = claim["interval"]
    assert low < claim["difference"] < high < 0
    assert verdicts([_claim()], _rows("A", a) + _rows("B", b))[0]["interval"] == [low, high]  # seeded


def test_claims_json_states_the_seed_rule_and_whether_the_run_met_it():
    rng = np.random.default_rng(4)
    document = claims_document("t", [_claim()], _rows("A", rng.random(4)) + _rows("B", rng.random(4)))
    rule = document["seed_rule"]
    assert rule["seeds_needed"] == 10 and rule["seeds_run"] == 4 and not rule["met"] and rule["pairs"] == 1


def test_claims_only_runs_just_the_arms_the_claims_compare():
    study = load_study("maco-p0")
    only = study.claims_only()
    cells = expand(only)
    assert count_cells(only) == len(cells) == 2 * 2 * len(study.seeds)
    assert {(c.scenario_name, c.label) for c in cells} == {
        (c.scenario, label) for c in study.claims for label in (c.planner, *c.than)}
    full = {c.config_hash for c in expand(study)}
    assert {c.config_hash for c in cells} <= full  # the same cells: a full run into the folder resumes


def test_errored_arms_are_never_merged_as_identical_configurations():
    rows = lambda nav: [{"label": "gwo", "navigator_label": nav, "seed": s, "world_seed": None,  # noqa: E731
                         "outcome": "error", "success": False} for s in range(3)]
    merged, sentences = merge_identical({"gwo": rows("follow"), "gwo + replan": rows("replan")})
    assert list(merged) == ["gwo", "gwo + replan"] and sentences == []


def test_the_ompl_log_marks_a_found_plan_solved_and_the_drive_separately():
    from swarmnav.study.ompl_log import PHYSICS_PROPERTIES, RUN_PROPERTIES, _run_values
    row = {"outcome": "ok", "success": False, "plan_waypoints": "[[0, 0], [1, 1]]", "plan_time_s": 0.1,
           "plan_collision_free": True, "plan_length_m": 1.4142, "seed": 0, "reached": False, "collisions": 2}
    values = dict(zip([n for n, _ in RUN_PROPERTIES + PHYSICS_PROPERTIES], _run_values(row, None, True)))
    assert values["solved"] is True and values["drive success"] is False and values["collisions"] == 2
    none = dict(row, outcome="no_path", plan_waypoints=None)
    assert dict(zip([n for n, _ in RUN_PROPERTIES], _run_values(none, None, False)))["solved"] is False


def test_the_report_summary_counts_collisions_and_timeouts_as_not_successful(tmp_path, monkeypatch):
    from swarmnav.study import figures, report
    rows = [{"scenario": "s", "label": "a", "planner": "x", "navigator_label": "follow", "seed": i,
             "world_seed": None, "outcome": "ok", "success": i == 0, "mode": "physics", "collisions": i % 2,
             "plan_length_m": 1.0} for i in range(4)]
    monkeypatch.setattr(report, "load_rows", lambda directory: (rows, []))  # the summary, not Parquet reading
    monkeypatch.setattr(report, "_against_oracle", lambda doc, runs: None)
    for name in ("box_plots", "outcome_bars", "paths"):
        monkeypatch.setattr(figures, name, lambda *a, **k: None)
    monkeypatch.setattr(figures, "anytime_figure", lambda *a, **k: (None, ""))
    markdown = report.write_report(tmp_path, tmp_path / "report.html").read_text()
    assert "4 runs, 1 successful, 3 not (of which 0 produced no result" in markdown


def test_equal_single_values_are_equal_not_inconclusive():
    from swarmnav.study.claims import EQUAL
    rows = _rows("A", [5.0] * 10, planner="immas") + _rows("B", [5.0] * 10, planner="immas")
    assert verdicts([_claim()], rows)[0]["verdict"] == EQUAL


def test_a_resume_after_a_source_change_keeps_the_old_inputs_so_the_verdicts_read_stale(tmp_path, capsys):
    from swarmnav.study.execute import resumed_inputs
    (tmp_path / "runs.parquet").mkdir()
    old = {"study_file": {"path": "s.toml", "sha256": "a"}, "sources": {"planners/gwo.py": "1"},
           "scenarios": {"x.toml": "s"}, "versions": {"swarmnav": "0.1.0"}}
    same = dict(old, study_file={"path": "s.toml", "sha256": "b"}, sources={"planners/gwo.py": "1", "planners/new.py": "3"})
    assert resumed_inputs(old, same, tmp_path)["sources"] == same["sources"]  # a claim added, a new arm: fine
    changed = dict(old, sources={"planners/gwo.py": "2"})
    kept = resumed_inputs(old, changed, tmp_path)
    assert kept["sources"] == old["sources"] and "planners/gwo.py changed" in capsys.readouterr().err
    assert resumed_inputs(old, changed, tmp_path / "empty") == changed  # no rows yet: today's inputs
