"""Studies against the clairvoyant oracle: rows of dynamic scenes carry its verdict, a time score and the
difficulty metrics, each scene measured once (sim/study/yardstick.py); the report's navigator table is
computed from those rows, never counts an unsolvable scene against a navigator, and draws success against
a difficulty metric (sim/study/against_oracle.py)."""

import csv
import json
import shutil
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from swarmnav.models.scenario_generator import GeneratorOptions, generate
from swarmnav.sim import palette
from swarmnav.cli.main import main
from swarmnav.study.against_oracle import binned_success
from swarmnav.study.rows import RUN_SCHEMA, RUNS, load_runs, part_name
from swarmnav.study.yardstick import FILE, Yardstick

# Two scenes the oracle solves and one it cannot: the same kind of crossing with too little time to arrive.
SCENES = {"cross": ("crossing", 1, {"obstacles": 2}), "headon": ("head_on", 2, {"obstacles": 1}),
          "short": ("crossing", 3, {"obstacles": 2, "time_limit_s": 6.0})}
STUDY = """
name = "against-oracle"
scenarios = ["cross.toml", "headon.toml", "short.toml"]
mode = "physics"
seeds = 1
[[planners]]
name = "astar"
[[navigators]]
name = "follow"
[[navigators]]
name = "velocity_obstacle"
"""


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    base = tmp_path_factory.mktemp("against-oracle")
    for name, (kind, seed, extra) in SCENES.items():
        text = generate(kind, seed, GeneratorOptions(arena_m=6.0, name=name, **extra))
        (base / f"{name}.toml").write_text(text, encoding="utf-8")
    (base / "study.toml").write_text(STUDY, encoding="utf-8")
    out = base / "out"
    assert main(["study", str(base / "study.toml"), "--out", str(out), "--workers", "1", "--json"]) == 0
    assert main(["report", str(out)]) == 0
    return base, out


def table(out: Path, name: str = "navigation-against-oracle") -> dict[str, dict[str, str]]:
    with open(out / "report_files" / "tables" / f"{name}.csv", encoding="utf-8") as f:
        return {r["navigator"]: r for r in csv.DictReader(f)}


def test_rows_carry_the_oracles_verdict_time_score_and_difficulty_of_their_scene(study):
    _, out = study
    rows = load_runs(out)
    assert len(rows) == 6
    by_scene = {}
    for r in rows:
        by_scene.setdefault(r["scenario"], []).append(r)
    assert {r["oracle_verdict"] for r in by_scene["short"]} == {"unsolvable"}
    assert {r["oracle_reason"] for r in by_scene["short"]} == {"time_limit"}
    for r in by_scene["short"]:
        assert r["time_score"] is None and r["oracle_t_star_s"] is None
    for name in ("cross", "headon"):
        for r in by_scene[name]:
            assert r["oracle_verdict"] == "solvable" and r["oracle_cell_m"] == 0.1
            assert 0 < r["oracle_t_star_s"] < r["sim_time_s"] + 60
            assert (r["time_score"] > 0) == bool(r["success"]) and r["time_score"] <= 1.0
            assert r["t_star_ratio"] >= 1.0 - 1e-9          # moving obstacles never make the arrival earlier
    for scene_rows in by_scene.values():                  # one measurement per scene: equal on every row of it
        for key in ("survivability", "dynamic_traversability", "static_density", "dispersion", "oracle_t_star_s"):
            assert len({r[key] for r in scene_rows}) == 1
        assert 0 <= scene_rows[0]["dynamic_traversability"] <= 1
    assert any(r["success"] for r in rows) and not all(r["success"] for r in rows)


def test_each_scene_is_measured_once_and_a_resume_measures_nothing_again(study):
    base, out = study
    scenes = json.loads((out / FILE).read_text(encoding="utf-8"))["scenes"]
    assert len(scenes) == len(SCENES)                    # 3 scenes for 6 rows
    yardstick = Yardstick(out)
    for name in SCENES:
        assert yardstick.scene(str(base / f"{name}.toml"), None)["scenario"] == name
    assert yardstick.computed == 0
    copy = base / "renamed.toml"                          # the same bytes under another name: the same scene
    shutil.copy(base / "cross.toml", copy)
    assert yardstick.scene(str(copy), None)["oracle_verdict"] == "solvable" and yardstick.computed == 0


def _rewrite(out: Path, change) -> None:
    """A later part with some rows changed (the readers keep the last row of a cell)."""
    rows = pq.read_table(out / RUNS).to_pylist()
    changed = [change(dict(r)) for r in rows]
    changed = [r for r in changed if r is not None]
    pq.write_table(pa.Table.from_pylist(changed, schema=RUN_SCHEMA), out / RUNS / part_name("test", 0))


def test_the_navigator_table_is_computed_from_the_rows(study, tmp_path):
    _, out = study
    rows = load_runs(out)
    before = table(out)
    for navigator, shown in before.items():
        mine = [r for r in rows if (r["navigator_label"] or "follow") == navigator]
        solvable = [r for r in mine if r["oracle_verdict"] == "solvable"]
        assert int(shown["runs"]) == len(mine) == 3
        assert int(shown["oracle-solvable runs"]) == len(solvable) == 2
        assert int(shown["unsolvable runs"]) == 1 and int(shown["undecided runs"]) == 0
        assert float(shown["success (%)"]) == pytest.approx(100 * sum(r["success"] for r in mine) / 3)
        assert float(shown["solved of solvable (%)"]) == pytest.approx(100 * sum(r["success"] for r in solvable) / 2)
        assert float(shown["time score"]) == pytest.approx(sum(r["time_score"] for r in solvable) / 2)
    # Flip the rows: a success on the unsolvable scene moves success only; a failure on a solvable one both.
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)

    def flip(r):
        if r["navigator"] == "velocity_obstacle":
            r["success"] = not r["success"]
            return r
        return None
    _rewrite(copy, flip)
    assert main(["report", str(copy)]) == 0
    after = table(copy)["velocity_obstacle"]
    vo = [r for r in rows if r["navigator"] == "velocity_obstacle"]
    flipped_solvable = [not r["success"] for r in vo if r["oracle_verdict"] == "solvable"]
    assert float(after["success (%)"]) == pytest.approx(100 * sum(not r["success"] for r in vo) / 3)
    assert float(after["solved of solvable (%)"]) == pytest.approx(100 * sum(flipped_solvable) / 2)
    assert table(copy)["follow"] == before["follow"]


def test_runs_on_unsolvable_scenes_never_enter_the_solved_share_or_the_time_score(study, tmp_path):
    _, out = study
    rows = load_runs(out)
    assert not any(r["success"] for r in rows if r["oracle_verdict"] == "unsolvable")   # failed, as they must
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)

    def succeed_on_the_unsolvable(r):                     # the other way round: they would then raise the score
        if r["oracle_verdict"] != "unsolvable":
            return None
        r.update(success=True, time_to_goal_s=5.0)
        return r
    _rewrite(copy, succeed_on_the_unsolvable)
    assert main(["report", str(copy)]) == 0
    before, after = table(out), table(copy)
    for navigator in before:
        assert float(after[navigator]["success (%)"]) == pytest.approx(float(before[navigator]["success (%)"]) + 100 / 3)
        assert after[navigator]["solved of solvable (%)"] == before[navigator]["solved of solvable (%)"]
        assert after[navigator]["time score"] == before[navigator]["time score"]
    text = (copy / "report.md").read_text(encoding="utf-8")
    assert "never counted against a navigator" in text


def test_the_report_draws_success_against_dynamic_traversability_in_the_palette(study):
    _, out = study
    markdown = (out / "report.md").read_text(encoding="utf-8")
    section = markdown.split("## Navigation against the oracle", 1)[1].split("\n## ", 1)[0]
    figure = section.split("](report_files/", 1)[1].split(")", 1)[0]
    svg = (out / "report_files" / figure.replace(".png", ".svg")).read_text(encoding="utf-8")
    assert "dynamic traversability" in svg and "success (%)" in svg
    assert palette.planner_colour(0) in svg and palette.planner_colour(1) in svg
    assert "velocity_obstacle" in svg and "follow" in svg
    # The figure's numbers come from the rows: one bin per solvable scene here, ordered by the metric.
    rows = load_runs(out)
    solvable = sorted({(r["dynamic_traversability"], r["scenario"]) for r in rows if r["oracle_verdict"] == "solvable"})
    centres, counts, shares = binned_success(rows)
    assert centres == [m for m, _ in solvable] and counts == [1, 1]
    for navigator, share in shares.items():
        assert share == [float(next(r["success"] for r in rows if r["scenario"] == scene
                                    and (r["navigator_label"] or "follow") == navigator)) for _, scene in solvable]
    html = (out / "report.html").read_text(encoding="utf-8")
    assert html.index("Navigation against the oracle") < html.index("data:image/svg+xml")


def test_an_oracle_that_cannot_decide_is_a_row_that_says_so(tmp_path):
    broken = tmp_path / "broken.toml"
    broken.write_text(generate("crossing", 1, GeneratorOptions(arena_m=6.0, obstacles=2)).replace(
        "time_limit_s", "time_limit_s = 'soon'\n#"), encoding="utf-8")
    row = Yardstick(tmp_path).annotate({"mode": "physics", "scenario_ref": str(broken), "world_seed": None,
                                        "success": False, "time_to_goal_s": None})
    assert row["oracle_verdict"] == "undecided" and "time_limit_s" in row["oracle_reason"]
    assert row.get("time_score") is None


def test_plan_only_rows_and_static_scenes_get_no_oracle_columns(tmp_path):
    yardstick = Yardstick(tmp_path)
    plan_row = {"mode": "plan", "scenario_ref": "dyn-crossing-1", "world_seed": 0}
    assert yardstick.annotate(dict(plan_row)) == plan_row and yardstick.computed == 0
    static = yardstick.annotate({"mode": "physics", "scenario_ref": "gwo-scenario-1", "world_seed": None,
                                 "success": True, "time_to_goal_s": 60.0})
    assert "oracle_verdict" not in static and yardstick.computed == 1
