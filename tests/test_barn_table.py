"""The BARN block of the docs (docs/barn.md, moved from the README) is generated from the committed results (models/suites/results/barn*.json): it
fails when either drifts from the other, and checks that the figures are the rows' own."""

import json
from pathlib import Path

from swarmnav.benchmarks import barn_table
from swarmnav.benchmarks.barn_difficulty import success_against_difficulty

README = Path(__file__).resolve().parent.parent / "docs" / "barn.md"  # the page that holds the block


def test_readme_block_is_generated_from_the_committed_results():
    assert barn_table.current_block(README.read_text(encoding="utf-8")) == barn_table.block()


def test_committed_results_are_barn_runs_with_their_scores():
    present = [p for p in barn_table.RESULTS if p.is_file()]
    assert present, "no committed BARN result"
    for path in present:
        rows = json.loads(path.read_text(encoding="utf-8"))
        overall = {r["navigator"]: r for r in rows if r["scenario"] is None}
        for name, row in overall.items():
            runs = [r for r in rows if r["scenario"] is not None and r["navigator"] == name]
            assert len(runs) == row["runs"]  # one per-run row for every run counted
            assert abs(sum(r["barn_score"] for r in runs) / len(runs) - row["barn_score"]) < 1e-12
            assert abs(sum(r["success_rate"] for r in runs) / len(runs) - row["success_rate"]) < 1e-12
            assert all(0.0 <= r["barn_score"] <= 0.5 and (r["barn_score"] > 0) == (r["success_rate"] == 1.0)
                       for r in runs)


def test_success_against_difficulty_reads_the_rows():
    rows = [{"navigator": "n", "world": w, "success_rate": float(w < 2),
             "difficulty": {k: float(w) for k in ("distance_to_closest_obstacle", "average_visibility",
                                                  "dispersion", "characteristic_dimension", "tortuosity")}}
            for w in range(4)]
    table = success_against_difficulty(rows, "n")
    assert table["dispersion"] == {"spearman": -0.8944, "success_low_half": 1.0, "success_high_half": 0.0}


def _protocol_result(path, navigator, worlds, runs, successes, params=None):
    """A committed-result stand-in: per-run rows on ``worlds`` x ``runs``, the first ``successes`` succeeding."""
    from swarmnav.benchmarks.barn import PROTOCOL_TEXT
    per_run = []
    for i, (w, j) in enumerate((w, j) for w in worlds for j in range(runs)):
        ok = float(i < successes)
        per_run.append({"scenario": f"barn-{w:03d}-r{j}", "navigator": navigator, "world": w, "run": j, "runs": 1,
                        "success_rate": ok, "collision_rate": 1.0 - ok, "timeout_rate": 0.0, "barn_score": 0.2 * ok,
                        "barn_setup": PROTOCOL_TEXT, "navigator_params": params or {}})
    n = len(per_run)
    overall = {"scenario": None, "navigator": navigator, "runs": n, "success_rate": successes / n,
               "collision_rate": 1.0 - successes / n, "timeout_rate": 0.0, "barn_score": 0.2 * successes / n,
               "barn_setup": PROTOCOL_TEXT, "navigator_params": params or {}, "mean_time_to_goal_s": 10.0}
    path.write_text(json.dumps([overall] + per_run), encoding="utf-8")
    return path


def test_every_online_navigator_target_needs_the_500_runs_of_each(tmp_path):
    from swarmnav.benchmarks.barn import TEST_WORLDS
    names = barn_table.online_navigators()
    assert "dwa" in names and "mppi" in names and "follow" not in names and "oracle" not in names
    full = tuple(_protocol_result(tmp_path / f"barn-protocol-{n}.json", n, TEST_WORLDS, 10, 450) for n in names)
    assert barn_table.online_lines(full)[-1].endswith(": met.")  # 450 / 500 = 0.90 each
    # dwa's only a 50-run sample, however good: not met, and its row says it is a sample
    sample = _protocol_result(tmp_path / "barn-protocol-dwa.json", "dwa", TEST_WORLDS, 1, 50, {"footprint": "box"})
    lines = barn_table.online_lines(full[:names.index("dwa")] + (sample,) + full[names.index("dwa") + 1:])
    assert any("dwa (footprint=box)" in line and "50 x 1" in line and "(sample: 50 of the protocol's 500)" in line
               for line in lines)
    assert "not met" in lines[-1] and "`dwa`" in lines[-1]
    # one navigator below 0.88 on its 500: not met, named with its figure
    low = _protocol_result(tmp_path / "barn-protocol-mppi.json", "mppi", TEST_WORLDS, 10, 430)
    lines = barn_table.online_lines(full[:names.index("mppi")] + (low,) + full[names.index("mppi") + 1:])
    assert "`mppi` 0.860 (500 runs)" in lines[-1]
    # a row on worlds that are not all test worlds is not a protocol figure on the test worlds
    off = _protocol_result(tmp_path / "barn-protocol-x.json", "replan", (1, 7), 250, 500)
    assert "| replan | none |" in "\n".join(barn_table.online_lines((off,)))


def test_an_arm_counts_for_its_navigator(tmp_path):
    from swarmnav.benchmarks.barn import TEST_WORLDS
    path = _protocol_result(tmp_path / "barn-protocol-arm.json", "iaco_local+barn", TEST_WORLDS, 1, 48)
    rows = json.loads(path.read_text(encoding="utf-8"))
    rows[0].update(arm_of="iaco_local", arm_params={"footprint": "box"})
    path.write_text(json.dumps(rows), encoding="utf-8")
    lines = "\n".join(barn_table.online_lines((path,)))
    assert "| iaco_local+barn (footprint=box) | `barn-protocol-arm.json` | 50 x 1 |" in lines
    assert "| iaco_local | none |" not in lines


def test_all_worlds_target_needs_a_row_over_every_world_for_each_online_navigator(tmp_path):
    from swarmnav.benchmarks.barn import TEST_WORLDS, WORLD_COUNT
    names = barn_table.online_navigators()
    every = tuple(_protocol_result(tmp_path / f"barn-protocol-all-{n}.json", n, range(WORLD_COUNT), 1, 290)
                  for n in names)
    lines = barn_table.all_worlds_lines(every)
    assert lines[-1].endswith(": met.")  # the stand-ins carry no CPU figure: no CPU line
    assert sum(line.startswith("| ") and "| 300 | 0.967 |" in line for line in lines) == len(names)
    # with each run's simulated time and CPU real-time factor: 300 runs x 10 s / 5 = 10 min per navigator
    timed = []
    for path in every:
        rows = json.loads(path.read_text(encoding="utf-8"))
        for r in rows:
            r.update(time_s=10.0, realtime_factor_cpu=5.0)
        timed.append(tmp_path / ("timed-" + path.name))
        timed[-1].write_text(json.dumps(rows), encoding="utf-8")
    lines = barn_table.all_worlds_lines(tuple(timed))
    assert lines[-1].startswith(f"Their runs' own CPU, every online navigator: {10.0 * len(names):.1f} min, so at "
                                f"least {5.0 * len(names):.1f} min")
    # the test worlds alone are not all the worlds: that navigator has none, named in the verdict
    test50 = _protocol_result(tmp_path / "barn-protocol-replan.json", "replan", TEST_WORLDS, 10, 500)
    lines = barn_table.all_worlds_lines(tuple(p for p in every if "replan" not in p.name) + (test50,))
    assert "| replan | none |" in "\n".join(lines) and "`replan`" in lines[-1] and "not met" in lines[-1]


def test_on_equal_runs_the_row_of_the_barn_configuration_stands_for_its_navigator_whatever_its_success(tmp_path):
    """A second configuration run as often never replaces the one models/suites/barn-navigators.toml declares
    for the navigator, even with a higher success: the row shown is not picked by its test result."""
    from swarmnav.benchmarks.barn import TEST_WORLDS
    declared = barn_table.configurations()["mppi"]
    other = dict(declared, samples=declared["samples"] + 1)
    mine = _protocol_result(tmp_path / "barn-protocol-a.json", "mppi", TEST_WORLDS, 10, 420, declared)
    better = _protocol_result(tmp_path / "barn-protocol-b.json", "mppi", TEST_WORLDS, 10, 480, other)
    for order in ((mine, better), (better, mine)):
        text = "\n".join(barn_table.online_lines(order))
        assert "`barn-protocol-a.json` | 50 x 10 | 500 | 0.840" in text, order
    # more runs still win: the declared configuration's 50-run sample gives way to another's 500 runs
    sample = _protocol_result(tmp_path / "barn-protocol-c.json", "mppi", TEST_WORLDS, 1, 50, declared)
    assert "`barn-protocol-b.json`" in "\n".join(barn_table.online_lines((better, sample)))


def test_fresh_worlds_are_compared_with_the_300_of_the_same_navigator_and_parameters(tmp_path, monkeypatch):
    """A BARN-like row (an arm, under any label) is set against the all-300 protocol row of its own navigator with
    the same parameters, whichever file holds it; another configuration of that navigator is not compared."""
    from swarmnav.benchmarks.barn import PROTOCOL_TEXT, WORLD_COUNT
    params = {"footprint": "box", "cost_weight": 10}
    all300 = _protocol_result(tmp_path / "barn-protocol-all-replan.json", "replan", range(WORLD_COUNT), 1, 294, params)
    fresh = tmp_path / "barn-like-protocol-navigators.json"

    def row(label, arm_params, success):
        return {"scenario": None, "navigator": label, "arm_of": "replan", "arm_params": arm_params,
                "navigator_params": arm_params, "runs": 50, "success_rate": success, "barn_score": 0.4,
                "barn_setup": PROTOCOL_TEXT}
    fresh.write_text(json.dumps([row("replan+barn", params, 0.90), row("replan+other", {"cost_weight": 3}, 0.5)]))
    monkeypatch.setattr(barn_table, "BARN_300", (all300,))
    monkeypatch.setattr(barn_table, "BARN_50", ())
    lines = [x for x in barn_table._fresh_against_barn(fresh, (all300, fresh)) if x.startswith("BARN-like")]
    assert lines == ["BARN-like worlds (`barn-like-protocol-navigators.json`) against BARN's "
                     "(`barn-protocol-all-replan.json`), `replan`: success 0.900 vs 0.980 (-0.080), score 0.4000 vs "
                     "0.1960 (+0.2040): NOT within 0.05."]
