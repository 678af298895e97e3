"""The navigation tables of the docs (docs/navigation.md) and the README's headline table (dyn300, also on
docs/results.md) are the ones generated from the committed results (dyn300, the dyn-* scenes)."""

import json
from pathlib import Path

import pytest

from swarmnav.benchmarks import navigation_table
from swarmnav.benchmarks.navigation_table import RESULT, RESULTS, block, current_block, read_rows, replace_block

REPO = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("result", RESULTS, ids=lambda p: p.name)
def test_the_docs_navigation_table_is_the_one_generated_from_the_committed_result(result, capsys):
    assert navigation_table.main([str(result)]) == 0
    generated = capsys.readouterr().out.strip()
    page = (REPO / "docs" / "navigation.md").read_text()
    assert current_block(page, result) == generated, \
        "run `make readme-table` (docs/navigation.md and models/suites/results differ)"


@pytest.mark.parametrize("page", ["README.md", "docs/results.md"])
def test_the_headline_table_is_the_one_generated_from_the_committed_dyn300_result(page, capsys):
    assert navigation_table.main([str(RESULT)]) == 0
    generated = capsys.readouterr().out.strip()
    assert current_block((REPO / page).read_text(), RESULT) == generated, \
        f"run `make readme-table` ({page} and models/suites/results/dyn300.json differ)"


def test_the_committed_dyn_result_runs_every_bundled_dyn_scene_for_every_default_navigator():
    from swarmnav.benchmarks.navigation import default_navigators
    rows = read_rows(RESULTS[1])
    assert [r["navigator"] for r in rows] == [n for n in default_navigators() if n != "oracle"] + ["oracle"]
    bundled = len(list((REPO / "models" / "scenarios").glob("dyn-*.toml")))
    assert {r["runs"] for r in rows} == {bundled * 5}


def test_the_committed_result_is_a_dyn300_run_of_every_default_navigator_beside_the_oracle():
    from swarmnav.benchmarks.navigation import default_navigators
    rows = read_rows(RESULT)
    names = [r["navigator"] for r in rows if not r.get("arm_of")]     # arms: rows of their own labels beside
    assert names == [n for n in default_navigators() if n != "oracle"] + ["oracle"]
    assert len({r["runs"] for r in rows}) == 1 and rows[0]["runs"] >= 22
    oracle = rows[-1]
    assert oracle["oracle_solvable_runs"] <= oracle["runs"] and oracle["verdict_mismatches"] is not None


def test_the_table_follows_the_rows_and_a_bad_file_is_named(tmp_path, capsys):
    rows = read_rows(RESULT)
    changed = [dict(r) for r in rows]
    changed[0]["solved_share"] = 0.123456
    assert "**0.123**" in block(changed) and block(changed) != block(rows)
    readme = tmp_path / "README.md"
    readme.write_text("before\n" + block(rows) + "\nafter\n")
    assert replace_block(readme.read_text(), block(changed), "README.md").startswith("before\n")
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"not": "rows"}))
    assert navigation_table.main([str(bad)]) == 2
    err = capsys.readouterr().err
    assert str(bad) in err and len(err.strip().splitlines()) == 1
    with pytest.raises(Exception, match="navigation-table markers for dyn300.json"):
        replace_block("no markers here", block(rows), "README.md")
    other = RESULTS[1]
    both = "a\n" + block(rows) + "\nb\n" + block(rows, other) + "\nc\n"
    assert current_block(replace_block(both, block(changed, other), "README.md", other), other) == block(changed, other)
    assert current_block(replace_block(both, block(changed, other), "README.md", other)) == block(rows)


def test_per_group_writes_that_many_scenes_of_each_group_and_needs_a_generated_suite(tmp_path, capsys):
    from swarmnav.benchmarks.navigation import write_suite
    from swarmnav.cli.main import main
    paths, suite = write_suite("dyn300", False, None, str(tmp_path), per_group=3)
    groups = list(dict.fromkeys(s.group for s in suite.scenes))
    names = [Path(p).stem for p in paths]
    assert len(names) == 3 * len(groups) and len(set(names)) == len(names)
    assert all(sum(name.startswith(f"d300-{g}-") for name in names) == 3 for g in groups)
    assert main(["bench", "navigation", "--per-group", "3"]) == 2
    assert "--per-group" in capsys.readouterr().err


def test_the_summary_under_a_table_is_computed_from_its_rows():
    from swarmnav.benchmarks.navigation_table import summary_lines, table_lines
    rows = [dict(r, sensor_model="detector") for r in read_rows(RESULT)]
    by_name = {r["navigator"]: r for r in rows}
    arm = dict(by_name["iaco_local"], navigator="iaco_local+evade", arm_of="iaco_local",
               arm_params={"evade": True}, solved_share=0.9)
    rows.insert(-1, arm)
    lines = summary_lines(rows)
    best = max((r for r in rows if r["navigator"] != "oracle"), key=lambda r: (r["solved_share"], r["time_score"]))
    assert f"`{best['navigator']}`, solves {best['solved_share']:.3f}" in lines[0]
    assert (": met)" in lines[0]) == (best["solved_share"] >= 0.95) != (": not met)" in lines[0])
    below = [r["navigator"] for r in rows if r["navigator"] not in ("oracle", "follow") and "arm_of" not in r
             and r["solved_share"] < 0.80]
    for name in below:
        assert f"`{name}` {by_name[name]['solved_share']:.3f}" in lines[1]
    assert "`follow`" not in lines[1]                                   # it never reads detections
    assert "(as `iaco_local+evade`: 0.900)" in lines[1]
    assert ("not met" in lines[1]) == bool(below) and lines[1].endswith(".")
    assert any("| iaco_local+evade (iaco_local: evade=true) |" in line for line in table_lines(rows))
    ranged = [dict(r, sensor_model="rangefinder", solved_share=0.5 if r["navigator"] != "oracle" else None)
              for r in rows]
    ranged_lines = summary_lines(ranged)
    assert "target ≥ 0.85: not met" in ranged_lines[0]
    assert not any("Every online" in line for line in ranged_lines)   # no such target with rangefinders


def test_the_committed_rangefinder_result_is_all_300_scenes_with_the_rangefinders():
    from swarmnav.models.suites import load_suite
    rows = read_rows(RESULTS[2])
    assert {r["sensor_model"] for r in rows} == {"rangefinder"}
    assert {r["runs"] for r in rows} == {len(load_suite("dyn300").scenes)}
    assert rows[-1]["navigator"] == "oracle" and rows[-1]["verdict_mismatches"] == 0


def test_the_speed_sentence_follows_the_run_figures():
    from swarmnav.benchmarks.navigation_table import summary_lines
    rows = [dict(r) for r in read_rows(RESULT)]
    speed = next(line for line in summary_lines(rows) if line.startswith("Speed"))
    slowest = min((r for r in rows if r.get("realtime_factor_cpu") is not None), key=lambda r: r["realtime_factor_cpu"])
    assert f"{slowest['realtime_factor_cpu']:.1f}× real time or more on CPU (`{slowest['navigator']}`" in speed
    mppi = next(r for r in rows if r["navigator"] == "mppi")
    mppi["mppi_every_step"] = dict(mppi["mppi_every_step"], cpu_us_per_step=1234.0)
    assert "`mppi` 1234 µs of CPU" in next(line for line in summary_lines(rows) if line.startswith("Speed"))
    bare = [{k: v for k, v in r.items() if k not in ("realtime_factor_cpu", "mppi_every_step", "oracle_search")}
            for r in rows]
    assert not any(line.startswith("Speed") for line in summary_lines(bare))
