"""Generated suites (models/suites), the new generator kinds and bench navigation against the oracle."""

import pytest

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.scenario_generator import GeneratorOptions, generate
from swarmnav.models.suites import load_suite, stratified_sample
from swarmnav.benchmarks.navigation import ORACLE, benchmark_navigation


def test_dyn300_has_300_distinct_scenes_each_with_a_shipped_verdict_in_order_of_difficulty():
    suite = load_suite("dyn300")
    names = [s.name for s in suite.scenes]
    assert len(names) == 300 == len(set(names))
    assert set(names) == set(suite.verdicts)
    ranks = [suite.verdicts[n]["difficulty_rank"] for n in names]
    assert ranks == sorted(ranks)
    sample = stratified_sample(suite)
    assert len(sample) == 2 * len({s.group for s in suite.scenes})


def test_every_group_generates_scenarios_that_load_with_the_sensing_asked_for():
    suite = load_suite("dyn300", sensor_model="rangefinder")
    for scene in stratified_sample(suite, per_group=1):
        scenario = parse_scenario(scene.text(), scene.name)
        assert scenario.name == scene.name and scenario.world_seed == scene.seed
        assert scenario.sensor_model == "rangefinder" and scenario.sensor_range_m == 1.0


def test_a_bad_suite_file_names_the_field(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('name = "bad"\n[[groups]]\nkind = "crossing"\nseeds = [3, 1]\n')
    with pytest.raises(ConfigError, match=r"groups\[0\]\.seeds"):
        load_suite(str(path))
    path.write_text('name = "bad"\n[[groups]]\nkind = "crossing"\nseeds = [0, 1]\noptions = { speed = 1 }\n')
    with pytest.raises(ConfigError, match=r"groups\[0\]\.options\.speed"):
        load_suite(str(path))


@pytest.mark.parametrize("kind", ["fast_crossing", "dense_crowd", "door_patrol", "corridor", "mixed"])
def test_new_kinds_are_pure_functions_of_their_options_and_load(kind):
    options = GeneratorOptions(speed_ratio=1.5 if kind == "fast_crossing" else 0.6,
                               obstacles=10 if kind == "dense_crowd" else 3)
    text = generate(kind, 4, options)
    assert text == generate(kind, 4, options)
    scenario = parse_scenario(text)
    walls = [ob for ob in scenario.obstacles if not ob.moving]
    assert (len(walls) > 0) == (kind in ("door_patrol", "corridor"))


def test_fast_crossers_must_outrun_the_robot():
    with pytest.raises(ConfigError, match="--speed-ratio"):
        generate("fast_crossing", 0, GeneratorOptions(speed_ratio=0.9))


def test_bench_rows_read_each_run_against_the_oracle_verdict(tmp_path):
    path = tmp_path / "short.toml"
    path.write_text(generate("crossing", 5, GeneratorOptions(obstacles=2, arena_m=5.0, sensor_model="detector")))
    rows = benchmark_navigation(1, ["follow", "velocity_obstacle"], [str(path)], out_dir=str(tmp_path / "out"))
    by_name = {r["navigator"]: r for r in rows}
    assert set(by_name) == {"follow", "velocity_obstacle", ORACLE}
    oracle = by_name[ORACLE]
    assert oracle["oracle_solvable_runs"] == 1 and oracle["success_on_solvable"] == 1.0
    for name in ("follow", "velocity_obstacle"):
        row = by_name[name]
        assert row["solved_share"] == row["success_rate"]      # the one run is oracle-solvable
        assert (row["time_score"] > 0) == (row["success_rate"] > 0) and row["time_score"] <= 1.0
        assert row["realtime_factor_cpu"] > 0                   # simulated over the runs' own CPU time
    search = oracle["oracle_search"]                            # the speed lines' figures: timed, not asserted
    assert search["scenes"] == 1 and search["max_s"] == search["median_s"] > 0 and search["max_cpu_s"] > 0
    from swarmnav.benchmarks.navigation_speed import speed_lines
    lines = speed_lines(rows, search, None)
    assert lines[0].startswith("oracle search: median") and "1 scenes" in lines[0]
    assert any(line.startswith("real-time factor: follow") for line in lines)
    assert lines[-1].startswith("oracle physics success on its solvable scenes: 1.000 of 1")


def test_the_mppi_speed_line_times_an_optimisation_at_every_control_step():
    from swarmnav.benchmarks.navigation_speed import mppi_step_cost
    cost = mppi_step_cost(("dyn-crossing-3",), sim_s=1.0)
    assert (cost["samples"], cost["horizon_steps"]) == (1000, 30)
    assert cost["steps"] == 50 or cost["steps"] == 51            # 1 s at 50 Hz, every step timed
    assert cost["cpu_us_per_step"] > 0 and set(cost["cpu_us_per_step_by_scene"]) == {"dyn-crossing-3"}


def test_arms_are_rows_under_their_own_labels_and_extend_a_kept_benchmark(tmp_path):
    """``--arm``: a navigator under its own label with its own parameters is one more row; the same navigator
    with the same (default) parameters under another label drives the same runs; a later run into the same
    folder with one more arm runs only that arm's cells (the study resumes)."""
    import pyarrow.parquet as pq
    from swarmnav.benchmarks.navigation import parse_arm
    path = tmp_path / "short.toml"
    path.write_text(generate("crossing", 5, GeneratorOptions(obstacles=2, arena_m=5.0, sensor_model="detector")))
    out = tmp_path / "out"
    first = benchmark_navigation(1, ["follow"], [str(path)], out_dir=str(out), speed=False,
                                 arms=[parse_arm("follow-again:follow")])
    assert pq.read_table(out / "runs.parquet").num_rows == 3
    rows = benchmark_navigation(1, ["follow"], [str(path)], out_dir=str(out), speed=False,
                                arms=[parse_arm("follow-again:follow"),
                                      parse_arm("vo-wide:velocity_obstacle:time_horizon_s=3.0")])
    assert pq.read_table(out / "runs.parquet").num_rows == 4     # only the new arm's run was added
    by_label = {r["navigator"]: r for r in rows}
    assert list(by_label) == ["follow", "follow-again", "vo-wide", ORACLE]
    assert by_label["follow-again"]["mean_spl"] == by_label["follow"]["mean_spl"]
    assert by_label["follow-again"]["success_rate"] == by_label["follow"]["success_rate"]
    assert by_label["vo-wide"]["arm_of"] == "velocity_obstacle"
    assert by_label["vo-wide"]["arm_params"] == {"time_horizon_s": 3.0}
    assert {r["navigator"]: r["runs"] for r in first} == {"follow": 1, "follow-again": 1, ORACLE: 1}


def test_arms_with_no_navigator_named_run_alone_beside_the_oracle(tmp_path):
    """``--arm`` without ``--navigator``: only the arms (and the yardstick) run, not every default navigator."""
    import pyarrow.parquet as pq
    from swarmnav.benchmarks.navigation import parse_arm
    path = tmp_path / "short.toml"
    path.write_text(generate("crossing", 5, GeneratorOptions(obstacles=2, arena_m=5.0, sensor_model="detector")))
    out = tmp_path / "out"
    rows = benchmark_navigation(1, None, [str(path)], out_dir=str(out), speed=False,
                                arms=[parse_arm("follow-again:follow")])
    assert [r["navigator"] for r in rows] == ["follow-again", ORACLE]
    assert pq.read_table(out / "runs.parquet").num_rows == 2


@pytest.mark.parametrize("arm, message", [
    ("vo", "expected LABEL:NAVIGATOR"),
    ("a:nope", "unknown navigator 'nope'"),
    ("a:oracle", "the yardstick"),
    ("follow:follow", "label 'follow' is already a row"),
    ("a:velocity_obstacle:bogus=1", "--arm a: navigator.params.bogus: unknown parameter"),
    ("a:velocity_obstacle:margin_m=[1,2]", "--arm a: navigator.params.margin_m: expected a number"),
])
def test_bad_arms_are_one_line_and_exit_2(arm, message, capsys):
    from swarmnav.cli.main import main
    assert main(["bench", "navigation", "--quick", "--navigator", "follow", "--arm", arm]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1


def test_a_seed_offset_gives_held_out_scenes_of_the_same_groups():
    from swarmnav.models.suites import load_suite
    suite, held_out = load_suite("dyn300"), load_suite("dyn300", seed_offset=1000)
    assert len(held_out.scenes) == len(suite.scenes) and held_out.verdicts == {}
    assert not {s.name for s in suite.scenes} & {s.name for s in held_out.scenes}
    own = {(s.group, s.seed): s for s in suite.scenes}
    for scene in held_out.scenes:
        twin = own[(scene.group, scene.seed - 1000)]
        assert scene.kind == twin.kind and scene.name == f"d300-{scene.group}-{scene.seed}"
        assert {k: v for k, v in vars(scene.options).items() if k != "name"} == \
            {k: v for k, v in vars(twin.options).items() if k != "name"}
    assert held_out.scenes[0].text() != own[(held_out.scenes[0].group, held_out.scenes[0].seed - 1000)].text()
    with pytest.raises(ConfigError, match="--seed-offset"):
        load_suite("dyn300", seed_offset=-1)


def test_a_seed_offset_without_a_generated_suite_is_one_line_and_exit_2(capsys):
    from swarmnav.cli.main import main
    assert main(["bench", "navigation", "--quick", "--seed-offset", "5"]) == 2
    err = capsys.readouterr().err.strip()
    assert "--seed-offset" in err and len(err.splitlines()) == 1


def test_an_arms_settings_split_at_keys_only():
    from swarmnav.benchmarks.navigation import parse_arm
    arm = parse_arm("drive:immas_stepwise:evade=true, lookahead_cells=6,predict_s=1")
    assert arm.params == {"evade": True, "lookahead_cells": 6, "predict_s": 1}
    assert parse_arm("plain:follow:").params == {}


def test_bench_navigation_map_and_pose_reach_every_run_and_row(tmp_path, capsys):
    import json

    from swarmnav.cli.main import main
    path = tmp_path / "short.toml"
    text = generate("crossing", 5, GeneratorOptions(obstacles=2, arena_m=5.0))
    path.write_text(text.replace("time_limit_s = 65", "time_limit_s = 4"))
    argv = ["bench", "navigation", "--scenario", str(path), "--seeds", "1", "--navigator", "replan", "--map",
            "unknown", "--pose", "odometry", "--json", "--out", str(tmp_path / "out")]
    assert main(argv) == 0
    rows = json.loads(capsys.readouterr().out)
    assert {r["navigator"] for r in rows} == {"replan", ORACLE}
    assert {(r["map_knowledge"], r["pose_source"]) for r in rows} == {("unknown", "odometry")}
    import pandas as pd
    runs = pd.read_parquet(tmp_path / "out" / "runs.parquet")
    assert set(runs.map_knowledge) == {"unknown"} and set(runs.pose_source) == {"odometry"} and len(runs) == 2


def test_a_group_slice_is_each_groups_contiguous_seeds_so_a_validation_range_is_exact():
    # CrowdNav's validation cases 500-749 in both settings: --seed-offset 500 --per-group 0:250
    suite = load_suite("crowdnav", seed_offset=500)
    scenes = stratified_sample(suite, (0, 250))
    by_group = {g: [s.seed for s in scenes if s.group == g] for g in ("circle-invisible", "circle-visible")}
    assert by_group["circle-invisible"] == by_group["circle-visible"] == list(range(500, 750))
    assert [s.seed for s in stratified_sample(suite, (490, 600)) if s.group == "circle-visible"] == list(range(990, 1000))
    # the spread sample it does not replace: every other case of 500-999
    spread = [s.seed for s in stratified_sample(suite, 250) if s.group == "circle-invisible"]
    assert spread[:3] == [501, 503, 505] and len(spread) == 250


@pytest.mark.parametrize("value", ["5:5", "7:3", "-1:4", "0:99999999999", "a:b", ":3", "600:700"])
def test_a_bad_group_slice_is_one_line_exit_2(capsys, value):
    from swarmnav.cli.main import main
    try:
        code = main(["bench", "navigation", "--suite", "crowdnav", "--per-group", value])
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "--per-group" in err, err
