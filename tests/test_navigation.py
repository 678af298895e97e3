"""Online navigators among moving obstacles, in physics; the safety filter; the generator; bad input."""

import math

import numpy as np
import pytest

from swarmnav.controllers.controller import ControlCommand, Twist
from swarmnav.controllers.goal import GoalChecker
from swarmnav.controllers.kinematics import DriveGeometry, WheelSpeeds
from swarmnav.controllers.navigator import DetectedObstacle, NavigationSetup, Observation
from swarmnav.controllers.navigators import make_navigator
from swarmnav.controllers.point_to_point import PointToPointController
from swarmnav.controllers.safety_filter import SafetyFilter
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.scenario_generator import GeneratorOptions, generate
from swarmnav.models.world import Pose2D
from swarmnav.cli.main import main
from swarmnav.sim.episode import EpisodeSpec, plan_episode, run_episode, static_problem

ONLINE = ("replan", "dstar_replan", "dwa", "velocity_obstacle")


def short_case(kind: str, sensor_model: str = "rangefinder", **options) -> str:
    """A 5 m arena with one obstacle at half the robot's speed (a 2.5 m drive)."""
    base = dict(obstacles=1, arena_m=5.0, speed_ratio=0.5, sensor_model=sensor_model, range_m=1.0)
    base.update(options)
    return generate(kind, 7, GeneratorOptions(**base))


@pytest.mark.parametrize("kind, sensor_model", [("head_on", "detector"), ("crossing", "rangefinder")])
def test_follow_collides_in_the_short_cases(kind, sensor_model):
    """The cases are hard enough: the plan made at t = 0, followed blindly, is run into."""
    result = run_episode(EpisodeSpec(parse_scenario(short_case(kind, sensor_model)), navigator="follow")).result
    assert result.collisions > 0


@pytest.mark.parametrize("navigator", ONLINE)
@pytest.mark.parametrize("kind, sensor_model", [("head_on", "detector"), ("crossing", "rangefinder")])
def test_online_navigators_reach_the_goal_without_collision(navigator, kind, sensor_model):
    result = run_episode(EpisodeSpec(parse_scenario(short_case(kind, sensor_model)), navigator=navigator)).result
    summary = result.summary()
    assert result.success and result.collisions == 0, summary
    assert summary["time_to_goal_s"] == pytest.approx(result.sim_time_s)
    assert 0.0 < summary["spl"] <= 1.0


def test_dstar_replan_marks_a_sensed_sweep_on_its_cells_and_clears_it_when_the_obstacle_leaves():
    scenario = parse_scenario(short_case("crossing"))
    episode = plan_episode(EpisodeSpec(scenario, navigator="dstar_replan"))
    goal = scenario.goal
    setup = NavigationSetup(episode.path, episode.problem, None, np.random.default_rng(0),
                            PointToPointController(GEOMETRY, max_speed_m_s=0.2), GoalChecker(goal.x_m, goal.y_m, 0.1),
                            0.02, 0.2, known_problem=static_problem(scenario))
    nav = make_navigator("dstar_replan")
    nav.reset(setup)
    start = scenario.start

    def observe(t, detections):
        return Observation(t, Pose2D(start.x_m, start.y_m, 0.0), Twist(0.0, 0.0), np.full(12, np.inf),
                           np.zeros(12), 0.155, detections)

    first = nav.step(observe(0.0, ()))
    assert first.new_path is not None and not first.events  # the initial D* Lite path is not a replan
    straight = first.new_path.waypoints
    assert len(straight) == 2  # nothing in the way on this map
    # A disc on the start-goal line ahead, still: its cells are blocked and the path bends around it.
    ahead = DetectedObstacle(start.x_m + 1.0, start.y_m, 0.3, 0.0, 0.0, 0)
    step = nav.step(observe(1.0, (ahead,)))
    assert nav.current.sum() > nav.static.sum()
    assert step.new_path is not None and [kind for kind, _ in step.events] == ["replan"]
    assert len(step.new_path.waypoints) > 2
    # It leaves: every marked cell is freed again, the cells are the known map's.
    nav.step(observe(2.0, ()))
    assert np.array_equal(nav.current, nav.static)


def test_replan_replans_and_reports_it_in_the_metrics():
    result = run_episode(EpisodeSpec(parse_scenario(short_case("crossing")), navigator="replan")).result
    assert result.replans >= 1 and result.replan_wall_s > 0.0


GEOMETRY = DriveGeometry(wheel_radius_m=0.05, track_m=0.3, max_wheel_speed_rad_s=20.0)


def test_safety_filter_slows_for_a_far_obstacle_and_stops_for_a_near_one():
    filt = SafetyFilter(GEOMETRY, robot_radius_m=0.15, time_before_collision_s=2.0)
    forward = ControlCommand(WheelSpeeds(4.0, 4.0), 0.2, 0.0, 1)
    pose = Pose2D(0.0, 0.0, 0.0)
    still_far = DetectedObstacle(1.2, 0.0, 0.3, 0.0, 0.0, 0)  # 0.72 m gap: 3.6 s at 0.2 m/s
    out, triggered = filt.apply(pose, forward, (still_far,))
    assert out.linear_m_s == pytest.approx(0.2) and not triggered
    closer = DetectedObstacle(0.8, 0.0, 0.3, 0.0, 0.0, 0)     # 0.32 m gap with the margin: 1.6 s at 0.2 m/s
    out, triggered = filt.apply(pose, forward, (closer,))
    assert 0.0 < out.linear_m_s < 0.2 and triggered and filt.triggers == 1
    charging = DetectedObstacle(0.8, 0.0, 0.3, -0.3, 0.0, 0)  # drives at the robot: no forward speed is safe
    out, triggered = filt.apply(pose, forward, (charging,))
    assert out.linear_m_s == 0.0 and not triggered and filt.triggers == 1  # still the same trigger


def test_safety_filter_stops_the_robot_before_an_obstacle_that_drives_straight_at_it():
    text = short_case("head_on", "detector", speed_ratio=0.8, range_m=1.5, navigator="replan")
    scenario = parse_scenario(text)
    # No replanning within reach (lookahead shorter than anything), no evasion: the filter alone acts.
    params = {"lookahead_m": 1e-3, "safety_filter": True, "time_before_collision_s": 3.0, "evade": False}
    result = run_episode(EpisodeSpec(scenario, navigator_params=params), time_limit_s=20.0).result
    assert result.safety_triggers >= 1 and result.collisions >= 1  # obstacles do not yield
    step = int(round(result.first_collision_s / (result.times_s[1] - result.times_s[0])))
    wheels = result.wheel_command_rad_s[max(step - 5, 0):step + 1]
    assert np.allclose(wheels.sum(axis=1), 0.0)  # zero forward speed before and at contact
    moved = np.hypot(*(result.poses[step, :2] - result.poses[step - 25, :2]))
    assert moved < 0.01  # stood still for the half second before contact


@pytest.mark.parametrize("navigator", ["replan", "dstar_replan"])
def test_same_scenario_seeds_and_navigator_give_the_same_trajectory_and_log_bytes(tmp_path, navigator):
    from swarmnav.log.writer import McapRecorder
    scenario = parse_scenario(short_case("crossing"))
    logs, poses = [], []
    for k in range(2):
        path = tmp_path / f"run{k}.mcap"
        result = run_episode(EpisodeSpec(scenario, navigator=navigator), [McapRecorder(path, overwrite=True)],
                             time_limit_s=12.0).result
        logs.append(path.read_bytes())
        poses.append(result.poses)
    assert np.array_equal(poses[0], poses[1])
    assert logs[0] == logs[1]


def test_generator_is_a_function_of_kind_seed_and_options():
    a = generate("crowd", 3, GeneratorOptions(obstacles=4))
    assert a == generate("crowd", 3, GeneratorOptions(obstacles=4))
    assert a != generate("crowd", 4, GeneratorOptions(obstacles=4))
    scenario = parse_scenario(a)
    assert sum(ob.moving for ob in scenario.obstacles) == 4
    assert "swarmnav scenarios generate crowd --seed 3" in scenario.description


@pytest.mark.parametrize("argv, field", [
    (["run", "dyn-crossing-1", "--navigator", "nope", "--no-log"], "navigator.name"),
    (["run", "dyn-crossing-1", "--navigator", "replan", "--navigator-set", "horizon_s=-1", "--no-log"],
     "navigator.params.horizon_s"),
    (["run", "dyn-crossing-1", "--navigator", "dwa", "--navigator-set", "alpha=fast", "--no-log"],
     "navigator.params.alpha"),
    (["run", "dyn-crossing-1", "--navigator", "dstar_replan", "--navigator-set", "cell_m=-0.1", "--no-log"],
     "navigator.params.cell_m"),
    (["scenarios", "generate", "head_on", "--seed", "1", "--obstacles", "40"], "--obstacles"),
    (["scenarios", "generate", "sideways", "--seed", "1"], "KIND"),
    (["scenarios", "generate", "crossing", "--seed", "1", "--time-limit-s", "30.051"], "--time-limit-s"),
    (["scenarios", "generate", "crossing", "--seed", "1", "--time-limit-s", "nan"], "--time-limit-s"),
])
def test_bad_navigation_input_exits_2_with_one_line_naming_the_field(argv, field, capsys):
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.strip().splitlines()) == 1 and field in err, err


def test_a_generated_time_limit_is_written_as_given_and_the_file_loads(capsys):
    assert main(["scenarios", "generate", "crossing", "--seed", "1", "--time-limit-s", "123.46"]) == 0
    text = capsys.readouterr().out
    assert parse_scenario(text).time_limit_s == 123.46
    # Seven significant digits: written with `:g` it became 12345.7, not a whole number of 0.02 s periods.
    assert main(["scenarios", "generate", "crossing", "--seed", "1", "--time-limit-s", "12345.68"]) == 0
    assert parse_scenario(capsys.readouterr().out).time_limit_s == 12345.68


def test_an_unknown_sensing_model_in_a_scenario_exits_2_naming_it(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(short_case("crossing").replace('model = "rangefinder"', 'model = "sonar"'))
    assert main(["run", str(path), "--no-log"]) == 2
    err = capsys.readouterr().err
    assert "sensors.model" in err and len(err.strip().splitlines()) == 1
    with pytest.raises(ConfigError):
        parse_scenario(path.read_text())


def test_time_in_danger_counts_control_steps_below_danger_m():
    scenario = parse_scenario(short_case("crossing"))
    result = run_episode(EpisodeSpec(scenario, navigator="follow")).result
    assert result.collisions > 0 and result.time_in_danger_s > 0.0
    assert not result.success and result.spl == 0.0
    assert math.isclose(result.time_in_danger_s / (result.times_s[1] - result.times_s[0]),
                        round(result.time_in_danger_s / (result.times_s[1] - result.times_s[0])))


def navigator_messages(path):
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory
    with open(path, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        return {topic: [(m.log_time, d) for _, _, m, d in reader.iter_decoded_messages(topics=[topic])]
                for topic in ("/navigator", "/obstacles")}


def test_navigator_channel_draws_what_the_detector_reported_beside_the_true_obstacles(tmp_path):
    """With the exact ``detector`` model the believed centres are the true ones at every logged step;
    the update after the last sensed step only deletes; ``follow`` (which ignores sensing) writes none."""
    from swarmnav.log.writer import McapRecorder
    scenario = parse_scenario(short_case("head_on", "detector"))
    logs = {}
    for nav in ("dwa", "follow"):
        logs[nav] = tmp_path / f"{nav}.mcap"
        run_episode(EpisodeSpec(scenario, navigator=nav), [McapRecorder(logs[nav])], time_limit_s=15.0)
    assert navigator_messages(logs["follow"])["/navigator"] == []
    messages = navigator_messages(logs["dwa"])
    belief, truth = messages["/navigator"], dict(messages["/obstacles"])
    drawn = [(t, u) for t, u in belief if u.entities]
    assert len(drawn) > 50
    for t, update in drawn:
        assert [d.type for d in update.deletions] == [1]  # ALL: the drawing is exactly this step's belief
        (entity,) = update.entities
        (true,) = [e for e in truth[t].entities if e.id == "obstacle_00"]  # the one (moving) obstacle
        sensed, true_pos = entity.cylinders[0].pose.position, true.cylinders[0].pose.position
        assert (sensed.x, sensed.y) == pytest.approx((true_pos.x, true_pos.y), abs=1e-9)
        assert entity.arrows and entity.lines  # the obstacle drives at the robot: velocity and sweep drawn
    cleared = [u for _, u in belief if not u.entities]
    assert len(cleared) <= 1 and all(u.deletions for u in cleared)


@pytest.mark.parametrize("navigator", ["replan", "dwa"])
def test_replay_verify_reproduces_a_navigator_run_bit_for_bit(tmp_path, navigator, capsys):
    from swarmnav.log.writer import McapRecorder
    log = tmp_path / f"{navigator}.mcap"
    run_episode(EpisodeSpec(parse_scenario(short_case("crossing")), navigator=navigator), [McapRecorder(log)])
    assert navigator_messages(log)["/navigator"]  # the run sensed the obstacle and logged its belief
    assert main(["replay", str(log), "--verify"]) == 0
    assert "verify: bitwise equal" in capsys.readouterr().out
