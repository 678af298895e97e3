"""CrowdNav's scenes (``scenarios generate crowdnav_circle|crowdnav_square``) and the crowd metrics of a run."""

from __future__ import annotations

import json
import os

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from swarmnav.models.crowd_agents import AgentMotion  # noqa: E402
from swarmnav.models.scenario import parse_scenario  # noqa: E402
from swarmnav.models.scenario_generator import GeneratorOptions, generate  # noqa: E402
from swarmnav.cli.main import main  # noqa: E402
from swarmnav.sim.crowd_stepping import crowd_metrics  # noqa: E402

CENTRE = np.array([6.0, 6.0])


def humans(text: str) -> list:
    return [ob for ob in parse_scenario(text, "<test>").obstacles if isinstance(ob.motion, AgentMotion)]


@pytest.mark.parametrize("seed", [0, 7, 123])
def test_circle_crossing_puts_humans_on_the_circle_heading_to_the_opposite_point(seed):
    text = generate("crowdnav_circle", seed, GeneratorOptions())
    assert text == generate("crowdnav_circle", seed, GeneratorOptions())
    people = humans(text)
    assert len(people) == 5
    start = np.array([(ob.x_m, ob.y_m) for ob in people]) - CENTRE
    goal = np.array([ob.motion.spec.goals_m[0] for ob in people]) - CENTRE
    radius = np.hypot(start[:, 0], start[:, 1])
    assert np.all(np.abs(radius - 4.0) <= 0.5 * np.sqrt(2) + 1e-9)  # jitter of at most 0.5 m per axis
    assert np.allclose(goal, -start, atol=1e-3)
    # clear of each other (and of the robot's start and goal) by the radii and the discomfort distance
    everyone = np.vstack([start, [[0.0, -4.0], [0.0, 4.0]]])
    gap = np.hypot(*(everyone[:, None] - everyone[None]).transpose(2, 0, 1))
    assert gap[np.triu_indices(len(everyone), 1)].min() >= 0.8 - 1e-3
    assert all(ob.radius_m == 0.3 and ob.motion.spec.v_pref_m_s == 1.0 and not ob.motion.spec.sees_robot
               for ob in people)
    assert len({generate("crowdnav_circle", s, GeneratorOptions()) for s in (seed, seed + 1)}) == 2


def test_square_crossing_walks_from_one_side_to_the_other_and_options_apply():
    for seed in range(20):
        text = generate("crowdnav_square", seed, GeneratorOptions(humans=7, robot_visible=True))
        people = humans(text)
        assert len(people) == 7 and all(ob.motion.spec.sees_robot for ob in people)
        for ob in people:
            x0, gx = ob.x_m - 6.0, ob.motion.spec.goals_m[0][0] - 6.0
            assert x0 * gx <= 0 and abs(x0) <= 5 and abs(gx) <= 5
    scenario = parse_scenario(generate("crowdnav_square", 3, GeneratorOptions(robot_visible=True)), "<t>")
    assert "--robot-visible" in scenario.description
    assert (scenario.robot_radius_m, scenario.max_speed_m_s, scenario.time_limit_s) == (0.3, 1.0, 25.0)
    assert (scenario.start.x_m, scenario.start.y_m, scenario.goal.x_m, scenario.goal.y_m) == (6, 2, 6, 10)


def test_generated_scene_runs_and_its_json_carries_the_crowd_metrics(tmp_path, capsys):
    path = tmp_path / "c.toml"
    assert main(["scenarios", "generate", "crowdnav_circle", "--seed", "4", "--out", str(path)]) == 0
    code = main(["run", str(path), "--navigator", "velocity_obstacle", "--no-log", "--json"])
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert code in (0, 5)
    assert 0.0 <= out["discomfort_frequency"] <= 1.0
    assert out["min_separation_m"] < 10 and out["path_irregularity_rad_m"] >= 0.0


def test_a_scene_without_agents_keeps_its_json_keys(tmp_path, capsys):
    assert main(["run", "dyn-head-on-1", "--no-log", "--json", "--navigator", "follow"]) in (0, 5)
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert "discomfort_frequency" not in out


def test_crowd_metrics_count_steps_within_the_discomfort_distance():
    steps = 11
    poses = np.zeros((steps, 3))
    poses[:, 1] = np.linspace(0.0, 10.0, steps)  # straight along y: no turning
    track = np.zeros((steps, 1, 2))
    track[:, 0, 1] = poses[:, 1]
    track[:, 0, 0] = 2.0  # a human walking beside the robot 2 m to the side ...
    track[4:7, 0, 0] = 0.3 + 0.3 + 0.1  # ... then 0.1 m from the rim for 3 of the 10 steps after the start
    metrics = crowd_metrics(poses, track, np.array([0.3]), 0.3, 10.0)
    assert metrics["discomfort_frequency"] == pytest.approx(0.3)
    assert metrics["min_separation_m"] == pytest.approx(0.1)
    assert metrics["path_irregularity_rad_m"] == 0.0
    poses[5:, 2] = np.pi / 2  # one quarter turn over 10 m
    assert crowd_metrics(poses, track, np.array([0.3]), 0.3, 10.0)["path_irregularity_rad_m"] == \
        pytest.approx(np.pi / 20)


@pytest.mark.parametrize("argv, message", [
    (["--humans", "0"], "--humans: must be in [1, 20]"),
    (["--humans", "21"], "--humans: must be in [1, 20]"),
])
def test_bad_generator_options_are_one_line_and_exit_2(argv, message, capsys):
    assert main(["scenarios", "generate", "crowdnav_circle", "--seed", "1"] + argv) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1


def test_the_crowdnav_suite_reads_each_setting_apart_and_the_visible_one_without_a_yardstick(tmp_path):
    from swarmnav.controllers.oracle_search import NoClairvoyantYardstick, search
    from swarmnav.models.suites import load_suite
    from swarmnav.benchmarks.navigation import benchmark_navigation
    suite = load_suite("crowdnav")
    assert [len([s for s in suite.scenes if s.group == g]) for g in ("circle-invisible", "circle-visible")] == \
        [500, 500]
    visible = parse_scenario(next(s for s in suite.scenes if s.group == "circle-visible").text(), "<t>")
    with pytest.raises(NoClairvoyantYardstick):
        search(visible)
    rows = benchmark_navigation(navigators=["follow"], suite="crowdnav", per_group=1, out_dir=str(tmp_path),
                                speed=False)
    by = {(r["navigator"], r["robot_visible"]): r for r in rows if r["scenario"] is None}
    assert set(by) == {("follow", False), ("oracle", False), ("follow", True)}  # no oracle where it cannot be one
    assert by[("oracle", False)]["oracle_solvable_runs"] == 1 and by[("oracle", False)]["yardstick"] == "oracle"
    assert by[("follow", True)]["oracle_solvable_runs"] == 0 and by[("follow", True)]["solved_share"] is None
    assert by[("follow", True)]["yardstick"].startswith("none")
    for r in by.values():
        assert r["runs"] == 1 and 0.0 <= r["discomfort_frequency"] <= 1.0
    # the blind follower meets the humans closer than the oracle does
    assert by[("follow", False)]["discomfort_frequency"] > by[("oracle", False)]["discomfort_frequency"]
    # The report counts the oracle's refused run on the visible scene nowhere: "no yardstick" instead.
    from swarmnav.study.report import write_report
    text = write_report(tmp_path, tmp_path / "report.html").read_text(encoding="utf-8")
    assert "No yardstick: 1 runs of the clairvoyant oracle" in text
    assert "3 runs, " in text and "4 runs, " not in text
