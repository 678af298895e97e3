"""Aggregate claims (issue 31): a paper's average over many scenarios (Hasan et al. 2023's 30 pairs), tested
by the signed-rank test over per-scenario means, paired by scenario (sim/study/claims.py)."""

from __future__ import annotations

import numpy as np
import pytest

from swarmnav.models.errors import ConfigError
from swarmnav.study.claim_spec import Claim
from swarmnav.study.claims import CONTRADICTED, INCONCLUSIVE, REPRODUCES, UNDERPOWERED, verdicts
from swarmnav.study.readme_table import table_lines
from swarmnav.study.spec import load_study, parse_study


def _rows(label, scenario, values, outcome="ok"):
    return [{"scenario": scenario, "label": label, "planner": "x", "navigator_label": "follow", "seed": i,
             "world_seed": None, "outcome": outcome, "success": outcome == "ok",
             "plan_length_m": v if outcome == "ok" else None} for i, v in enumerate(values)]


def _claim(**kw):
    base = dict(id="c", statement="s", source="x", scenario="env*", metric="plan_length_m", better="lower",
                planner="A", than=("B",), test="signed_rank_scenarios")
    return Claim(**{**base, **kw})


def _study(scenarios: int, shift: float, seed: int = 0, seeds: int = 3):
    """A better by ``shift`` on each scenario, the scenarios' levels far apart (a rank-sum over pooled runs
    would drown the shift in them; pairing by scenario does not)."""
    rng = np.random.default_rng(seed)
    rows = []
    for k in range(scenarios):
        level = 10.0 * k
        rows += _rows("A", f"env{k}", level - shift + 0.01 * rng.random(seeds))
        rows += _rows("B", f"env{k}", level + 0.01 * rng.random(seeds))
    return rows + _rows("A", "other", [100.0] * seeds)      # a scenario the glob does not match: left out


def test_a_shift_on_every_scenario_reproduces_paired_by_scenario_and_reports_the_relative_difference():
    [claim] = verdicts([_claim()], _study(12, 0.5))
    pair = claim["pairs"][0]
    assert claim["verdict"] == REPRODUCES and pair["pairs"] == 12 and len(pair["scenarios"]) == 12
    assert claim["difference"] == pytest.approx(-0.5, abs=0.01) and claim["interval"][1] < 0
    mean_b = np.mean([10.0 * k for k in range(12)]) + 0.005
    assert claim["relative"] == pytest.approx(-0.5 / mean_b, rel=0.05)
    # the opposite claim is contradicted; no shift is inconclusive; three scenarios cannot reach alpha
    assert verdicts([_claim(better="higher")], _study(12, 0.5))[0]["verdict"] == CONTRADICTED
    assert verdicts([_claim()], _study(12, 0.0))[0]["verdict"] == INCONCLUSIVE
    assert verdicts([_claim()], _study(3, 0.5))[0]["verdict"] == UNDERPOWERED
    line = table_lines([{"study": "t", "seeds": 3, "seed_rule": {"seeds_needed": 10},
                         "claims": verdicts([_claim()], _study(12, 0.5))}])[2]
    assert "12 scenarios" in line and "%" in line


def test_a_scenario_only_one_side_completed_is_left_out_of_the_pairs():
    rows = _study(12, 0.5)
    rows = [r for r in rows if not (r["scenario"] == "env3" and r["label"] == "B")] + _rows("B", "env3", [1, 2, 3],
                                                                                             outcome="no_path")
    pair = verdicts([_claim()], rows)[0]["pairs"][0]
    assert pair["pairs"] == 11 and "env3" not in pair["scenarios"]


def test_an_aggregate_glob_must_match_two_scenarios_and_claims_only_runs_each_of_them(tmp_path):
    text = ('name = "agg"\nscenarios = ["gwo-scenario-1", "gwo-scenario-2"]\nmode = "plan"\nseeds = 2\n'
            '[[planners]]\nname = "straight"\n[[planners]]\nname = "optimal"\n'
            '[[claims]]\nid = "a"\nstatement = "s"\nsource = "x"\nscenario = "{glob}"\nmetric = "plan_length_m"\n'
            'better = "lower"\nplanner = "straight"\nthan = ["optimal"]\ntest = "signed_rank_scenarios"\n')
    study = parse_study(text.replace("{glob}", "gwo-scenario-*"), str(tmp_path / "agg.toml"))
    assert {arm[0] for arm in study.claims_only().claim_arms} == {"gwo-scenario-1", "gwo-scenario-2"}
    with pytest.raises(ConfigError, match="matches 1 of the study's scenarios"):
        parse_study(text.replace("{glob}", "gwo-scenario-1"), str(tmp_path / "agg.toml"))


def test_the_hasan_study_states_its_30_pair_averages():
    study = load_study("immas-environments")
    aggregate = [c for c in study.claims if c.test == "signed_rank_scenarios"]
    assert len(aggregate) >= 4
    arms = study.claims_only().claim_arms
    assert len({scenario for scenario, label, _ in arms if label == "mmas"}) == 30
