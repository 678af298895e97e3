"""``--log-format ros2``: a log that ROS 2 tools replay, checked by an independent reader (rosbags).

One run of gwo-scenario-2 (planner gwo, navigator replan) is logged with the ros2 profile; rosbags
decodes every message with ROS 2 Humble's own type definitions (not the file's), and swarmnav's
readers (log info, plot, replay --verify) read it back.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

rosbags = pytest.importorskip("rosbags")
from rosbags.highlevel import AnyReader  # noqa: E402
from rosbags.typesys import Stores, get_types_from_msg, get_typestore  # noqa: E402

from swarmnav.log.format import ROS2_CHANNELS  # noqa: E402
from swarmnav.log.ros2_types import FIELDS, msgdef, schema_name  # noqa: E402

HUMBLE = get_typestore(Stores.ROS2_HUMBLE)


@pytest.fixture(scope="module")
def ros2_run(tmp_path_factory):
    import swarmnav
    path = tmp_path_factory.mktemp("ros2") / "run.mcap"
    outcome = swarmnav.run("gwo-scenario-2", "gwo", navigator="replan", seed=0, log=path, log_format="ros2")
    return path, outcome


@pytest.fixture(scope="module")
def ros2_messages(ros2_run):
    return _decoded(ros2_run[0])


def _decoded(path: Path) -> dict[str, list]:
    """Every message of the file, decoded by rosbags with Humble's definitions, per topic."""
    out: dict[str, list] = {}
    with AnyReader([path], default_typestore=HUMBLE) as reader:
        assert all(c.msgtype == ROS2_CHANNELS[c.topic][1] for c in reader.connections)
        for c in reader.connections:  # each channel's offered QoS, as rosbags reads it: latched topics transient-local
            (qos,) = c.ext.offered_qos_profiles
            assert qos.durability.name == ("TRANSIENT_LOCAL" if c.topic in ("/tf_static", "/map") else "VOLATILE")
            assert qos.reliability.name == "RELIABLE"
        for connection, _, raw in reader.messages():
            out.setdefault(connection.topic, []).append(HUMBLE.deserialize_cdr(raw, connection.msgtype))
    return out


def test_every_definition_is_rosbags_humble_definition():
    for short in FIELDS:
        parsed = get_types_from_msg(msgdef(short), schema_name(short))
        for name, (_, fields) in parsed.items():
            assert fields == HUMBLE.fielddefs[name][1], name


def test_rosbags_decodes_every_message_as_the_standard_types(ros2_run, ros2_messages):
    path, outcome = ros2_run
    messages = ros2_messages
    steps = len(outcome.result.poses)  # one pose per control step
    for topic in ("/tf", "/odom", "/scan", "/cmd_vel", "/clock", "/joint_states", "/wheels/command"):
        assert len(messages[topic]) == steps, topic
    assert len(messages["/obstacles"]) == steps + 1  # and where they start, at t = 0
    assert len(messages["/tf_static"]) == 1 and len(messages["/scene"]) == 1
    assert len(messages["/plan"]) == 1 + outcome.result.summary()["replans"]
    kinds = [m.msg.split(" ")[0] for m in messages["/rosout"]]
    assert kinds.count("replan") == outcome.result.summary()["replans"] and kinds[-1] == "goal_reached"
    static = {(t.header.frame_id, t.child_frame_id) for t in messages["/tf_static"][0].transforms}
    assert static == {("world", "map"), ("map", "odom"), ("base_link", "base_scan")}
    assert {(t.header.frame_id, t.child_frame_id) for t in messages["/tf"][-1].transforms} == {("odom", "base_link")}
    scan = messages["/scan"][0]
    assert len(scan.ranges) == 12 and scan.ranges.dtype == np.float32 and scan.header.frame_id == "base_scan"
    assert math.isclose(scan.angle_min + 11 * scan.angle_increment, scan.angle_max, abs_tol=1e-5)
    from swarmnav.log.summary import read_summary
    obstacles = json.loads(read_summary(path).metadata["run"]["obstacles"])
    assert {len(m.markers) for m in messages["/obstacles"]} == {len(obstacles)}  # all of them, every step
    assert [m.ns for m in messages["/obstacles"][-1].markers] == [o["entity_id"] for o in obstacles]
    clock_s = [c.clock.sec + c.clock.nanosec * 1e-9 for c in messages["/clock"]]
    assert np.all(np.diff(clock_s) > 0)


def test_the_last_odometry_pose_is_the_runs_final_pose_at_the_goal(ros2_run, ros2_messages):
    path, outcome = ros2_run
    last = ros2_messages["/odom"][-1]
    x, y, heading = outcome.result.poses[-1]
    position, q = last.pose.pose.position, last.pose.pose.orientation
    assert (position.x, position.y) == (x, y)
    assert math.isclose(math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y ** 2 + q.z ** 2)), heading, abs_tol=1e-9)
    goal = outcome.episode.spec.scenario.goal
    assert outcome.reached and math.hypot(position.x - goal.x_m, position.y - goal.y_m) < 0.3
    assert last.header.frame_id == "odom" and last.child_frame_id == "base_link"


def test_log_info_plot_and_verify_read_the_ros2_log(ros2_run, tmp_path, capsys):
    from swarmnav.cli.main import main
    path, outcome = ros2_run
    assert main(["log", "info", str(path)]) == 0
    text = capsys.readouterr().out
    assert "nav_msgs/msg/Odometry" in text and "goal_reached" in text
    assert main(["plot", str(path), "-o", str(tmp_path / "p.png")]) == 0
    assert (tmp_path / "p.png").stat().st_size > 10_000
    assert main(["replay", str(path), "--verify"]) == 0
    assert "bitwise equal" in capsys.readouterr().out


def test_an_odometry_estimate_goes_to_odom_and_map_to_odom_carries_its_error(tmp_path):
    """With ``StepFrame.odometry`` (the drifting estimate a run with odometry hands over), /odom is the
    estimate and map -> odom -> base_link is still the true pose, which the reader recovers."""
    from swarmnav.log.reader import read_log
    from swarmnav.log.writer import McapRecorder
    from swarmnav.sim.recording import RunContext, StepFrame
    mjcf = '<mujoco><worldbody><body><geom name="chassis" size="0.2 0.05"/></body></worldbody></mujoco>'
    context = RunContext("s", "", "p", {}, 0, mjcf, 0.1, 0.01, np.linspace(-1, 1, 3), 1.0, 0.2, 0.1, ())
    recorder = McapRecorder(tmp_path / "odo.mcap", log_format="ros2")
    recorder.start(context)
    truth = [(1.0 + 0.1 * k, 2.0, 0.3 * k) for k in range(4)]
    for k, (x, y, yaw) in enumerate(truth):
        frame = StepFrame(0.1 * (k + 1), np.array([x, y, 0.05]), np.array([math.cos(yaw / 2), 0, 0, math.sin(yaw / 2)]),
                          yaw, np.array([0.5, np.inf, 0.7]), np.zeros(2), np.ones(2), 0.1, 0.0, 0, np.zeros((0, 2)))
        frame.odometry = SimpleNamespace(x_m=x + 0.05 * k, y_m=y - 0.02 * k, heading_rad=yaw + 0.01 * k)
        recorder.step(frame)
    recorder.finish({"outcome": "timeout"})
    messages = _decoded(tmp_path / "odo.mcap")
    assert messages["/odom"][-1].pose.pose.position.x == pytest.approx(truth[-1][0] + 0.15)
    assert {(t.header.frame_id, t.child_frame_id) for t in messages["/tf_static"][0].transforms} == {("world", "map"), ("base_link", "base_scan")}
    log = read_log(tmp_path / "odo.mcap")
    np.testing.assert_allclose(log.position_m[:, :2], [t[:2] for t in truth], atol=1e-12)
    np.testing.assert_allclose(log.heading_rad, [t[2] for t in truth], atol=1e-12)
    assert np.isnan(log.range_m[0, 1]) and log.range_m[0, 0] == pytest.approx(0.7)


def test_an_odometry_run_logs_the_estimate_on_odom_and_the_true_pose_through_map_to_odom(tmp_path):
    """knowledge.pose = "odometry": /odom is the dead-reckoned pose (it drifts), map -> odom -> base_link the truth."""
    from swarmnav.models.scenario import load_scenario
    from swarmnav.sim.episode import EpisodeSpec, run_episode
    from swarmnav.log.reader import read_log
    from swarmnav.log.writer import McapRecorder
    scenario = load_scenario("gwo-scenario-1").with_knowledge(pose_source="odometry")
    result = run_episode(EpisodeSpec(scenario), [McapRecorder(tmp_path / "odo.mcap", log_format="ros2")],
                         time_limit_s=4.0).result
    messages = _decoded(tmp_path / "odo.mcap")
    assert {(t.header.frame_id, t.child_frame_id) for t in messages["/tf"][-1].transforms} == \
        {("map", "odom"), ("odom", "base_link")}
    last = messages["/odom"][-1].pose.pose.position
    x, y, _ = result.poses[-1]
    drift_m = math.hypot(last.x - x, last.y - y)
    assert 0 < drift_m < 0.2  # the estimate is not the truth, and not far from it after 4 s
    log = read_log(tmp_path / "odo.mcap")
    np.testing.assert_allclose(log.position_m[:, :2], result.poses[:, :2], atol=1e-9)


def test_with_the_map_unknown_map_is_the_sensed_grid_as_nav_msgs_occupancy_grid(tmp_path):
    """The map a run builds (``knowledge = { map = "unknown" }``) goes to /map in both profiles: the same cells."""
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory
    from swarmnav.models.scenario import load_scenario
    from swarmnav.sim.episode import EpisodeSpec, run_episode
    from swarmnav.log.writer import McapRecorder
    scenario = load_scenario("gwo-scenario-1").with_knowledge("unknown")
    for log_format in ("ros2", "swarmnav"):
        run_episode(EpisodeSpec(scenario, navigator="replan"),
                    [McapRecorder(tmp_path / f"{log_format}.mcap", log_format=log_format)], time_limit_s=3.0)
    maps = _decoded(tmp_path / "ros2.mcap")["/map"]
    with (tmp_path / "swarmnav.mcap").open("rb") as stream:
        grids = [m for *_, m in make_reader(stream, decoder_factories=[DecoderFactory()])
                 .iter_decoded_messages(topics=["/map"])]
    assert len(maps) == len(grids) >= 2
    last, grid = maps[-1], grids[-1]
    assert last.header.frame_id == "map" and last.info.width == grid.column_count
    assert math.isclose(last.info.resolution, grid.cell_size.x, rel_tol=1e-6)
    assert last.data.tobytes() == grid.data  # the same cells: percent, -1 never seen
    assert (last.data == -1).any() and ((last.data >= 0) & (last.data < 50)).any() and last.data.max() <= 100


def test_bad_log_format_is_refused_by_run_study_and_env(capsys):
    from swarmnav.models.errors import ConfigError
    from swarmnav.cli.main import main
    from swarmnav.env.task import EnvOptions
    for argv in (["run", "gwo-scenario-2", "--log-format", "rosbag"], ["study", "x", "--logs", "--log-format", "bag"]):
        with pytest.raises(SystemExit) as exit_info:
            main(argv)
        assert exit_info.value.code == 2
        assert "invalid choice: 'bag" in capsys.readouterr().err.replace("rosbag", "bag")
    with pytest.raises(ConfigError, match="record_format"):
        EnvOptions(record_format="ros1")


def test_study_logs_and_the_env_recorder_write_the_ros2_profile_and_replay_renders_it(tmp_path):
    from swarmnav.cli.main import main
    from swarmnav.env.gym_adapter import NavigateEnv
    from swarmnav.log.summary import read_summary
    study = tmp_path / "logged.toml"
    study.write_text('name = "logged"\nscenarios = ["restaurant-table-2"]\nmode = "physics"\ntime_limit_s = 1.0\n'
                     'seeds = [0]\n[[planners]]\nname = "astar"\n')
    out = tmp_path / "out"
    assert main(["study", str(study), "--out", str(out), "--workers", "1", "--logs", "--log-format", "ros2",
                 "--json"]) == 0
    (log,) = (out / "logs").glob("*.mcap")
    assert read_summary(log).raw.profile == "ros2"
    assert set(_decoded(log)) >= {"/tf", "/odom", "/scan", "/plan", "/rosout"}
    import imageio.v3 as iio
    video = tmp_path / "study-run.mp4"  # replay --video reads a ros2 log (one simulated second, 4 frames)
    assert main(["replay", str(log), "--video", str(video), "--width", "160", "--height", "120", "--fps", "4"]) == 0
    frames = iio.imread(video)
    assert frames.shape[0] >= 4 and frames.shape[1:3] == (120, 160) and frames.std() > 0
    env = NavigateEnv("restaurant-table-5", time_limit_s=0.3, record_to=str(tmp_path / "ep{episode}.mcap"),
                      record_format="ros2")
    env.reset(seed=0)
    for _ in range(3):
        env.step(np.array([0.5, 0.2]))
    env.close()
    messages = _decoded(tmp_path / "ep0.mcap")
    assert len(messages["/odom"]) >= 3 and read_summary(tmp_path / "ep0.mcap").raw.profile == "ros2"


def test_a_cut_ros2_log_is_read_and_recovered_as_ros2(ros2_run, tmp_path):
    from swarmnav.cli.main import main
    from swarmnav.log.reader import read_log
    path, outcome = ros2_run
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    assert main(["log", "recover", str(cut), str(tmp_path / "recovered.mcap")]) == 0
    recovered = read_log(tmp_path / "recovered.mcap")
    assert recovered.raw.profile == "ros2" and recovered.complete
    kept = len(recovered.time_s)
    assert 0 < kept < len(outcome.result.poses)
    np.testing.assert_array_equal(recovered.position_m[:, :2], outcome.result.poses[:kept, :2])
