"""Run logs: MCAP contents, sim-time stamps, determinism, crash recovery, replay, plot.

Real runs, real MCAP files, real EGL rendering (MUJOCO_GL=egl).
"""

from __future__ import annotations

import json
import os

os.environ.setdefault("MUJOCO_GL", "egl")

import math  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from mcap.reader import make_reader  # noqa: E402
from mcap_protobuf.decoder import DecoderFactory  # noqa: E402

from swarmnav.models.scenario import load_scenario  # noqa: E402
from swarmnav.cli.main import main  # noqa: E402
from swarmnav.sim.episode import EpisodeSpec, run_episode  # noqa: E402
from swarmnav.log.format import TOPICS  # noqa: E402
from swarmnav.log.reader import read_log  # noqa: E402
from swarmnav.log.writer import McapRecorder  # noqa: E402
from swarmnav.log.records import read_records  # noqa: E402

REPO = Path(__file__).resolve().parent.parent
SCENARIO = "gwo-scenario-2"  # moving obstacles and collisions: every channel has traffic
PER_STEP = ("/tf", "/robot/pose", "/range/scan", "/wheels", "/controller")
# The foxglove.* names are those @foxglove/schemas defines (checked against Foxglove's schema reference:
# FrameTransform, PoseInFrame, PosesInFrame, SceneUpdate, LaserScan, Log); Foxglove recognises only these.
EXPECTED_SCHEMAS = {
    "/tf": "foxglove.FrameTransform",
    "/robot/pose": "foxglove.PoseInFrame",
    "/planner/path": "foxglove.PosesInFrame",
    "/obstacles": "foxglove.SceneUpdate",
    "/range/scan": "foxglove.LaserScan",
    "/wheels": "swarmnav.WheelSpeeds",
    "/controller": "swarmnav.ControllerState",
    "/events": "foxglove.Log",
    "/scene": "foxglove.SceneUpdate",
}


def record(path: Path, **run_options):
    return run_episode(EpisodeSpec(load_scenario(SCENARIO)), [McapRecorder(path)], **run_options)


@pytest.fixture(scope="module")
def full_run(tmp_path_factory):
    path = tmp_path_factory.mktemp("logs") / "full.mcap"
    episode = record(path)
    return path, episode


def messages_by_topic(path: Path) -> dict[str, list]:
    with path.open("rb") as stream:
        reader = make_reader(stream)
        out: dict[str, list] = {}
        for _, channel, message in reader.iter_messages(log_time_order=False):
            out.setdefault(channel.topic, []).append(message)
    return out


def test_log_reads_back_with_expected_channels_counts_and_schemas(full_run):
    path, episode = full_run
    with path.open("rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        schemas = {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values()}
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
        attachments = {a.name: a for a in reader.iter_attachments()}
    assert schemas == EXPECTED_SCHEMAS
    log = read_log(path)
    steps = episode.result.steps + 1
    for topic in PER_STEP:
        assert log.counts[topic] == steps, topic
    assert log.counts["/obstacles"] == steps + 1  # t = 0 at start, then every step (obstacles move)
    assert log.counts["/planner/path"] == 1
    kinds = [kind for _, kind, _ in log.events]
    assert kinds[-1] == episode.result.outcome
    assert kinds.count("collision_begin") == episode.result.collisions
    assert all({"geom_a", "geom_b"} <= set(d) for _, k, d in log.events if k.startswith("collision"))
    assert set(metadata) >= {"scenario", "planner", "run", "versions", "outcome"}
    assert metadata["scenario"]["toml"] == load_scenario(SCENARIO).source_text
    assert int(metadata["run"]["seed"]) == episode.spec.seed
    assert {"swarmnav", "mujoco", "python"} <= set(metadata["versions"])
    assert not any(key.startswith("wall_") for key in metadata["outcome"])
    assert attachments["scene.xml"].data.decode().startswith("<mujoco")
    assert np.array_equal(log.position_m[:, :2], episode.result.poses[:, :2])


def test_scan_and_obstacles_follow_foxglove_conventions(full_run):
    path, _ = full_run
    log = read_log(path)
    # Misses are NaN (not MuJoCo's -1); hits lie beyond the rim of the body.
    assert np.isnan(log.range_m).any()
    finite = log.range_m[np.isfinite(log.range_m)]
    assert finite.size and finite.min() > 0.15
    assert len(log.scan_angles_rad) == 12
    # Inclusive end; site positions are those of the logged MJCF, rounded to 6 digits.
    assert math.isclose(log.scan_angles_rad[-1] - log.scan_angles_rad[0], 2 * math.pi * 11 / 12, abs_tol=1e-6)
    factory = DecoderFactory()
    with path.open("rb") as stream:
        for schema, channel, message in make_reader(stream).iter_messages(topics=["/obstacles"]):
            update = factory.decoder_for(channel.message_encoding, schema)(message.data)
            break
    cylinders = [c for e in update.entities for c in e.cylinders]
    assert cylinders and all(c.bottom_scale == 1.0 and c.top_scale == 1.0 for c in cylinders)
    ids = [e.id for e in update.entities]
    assert len(ids) == len(set(ids)) == len(load_scenario(SCENARIO).obstacles)


def test_timestamps_are_simulation_time(full_run):
    path, episode = full_run
    topics = messages_by_topic(path)
    for topic, messages in topics.items():
        assert all(m.publish_time == m.log_time for m in messages), topic
    tf_ns = np.array([m.log_time for m in topics["/tf"]])
    dt_ns = round(episode.result.times_s[1] * 1e9)
    assert tf_ns[0] == 0
    assert np.array_equal(tf_ns, np.arange(len(tf_ns)) * dt_ns)
    # The stamp inside each message is the same sim time.
    factory = DecoderFactory()
    with path.open("rb") as stream:
        reader = make_reader(stream)
        for schema, channel, message in reader.iter_messages(topics=["/tf", "/range/scan"]):
            decoded = factory.decoder_for(channel.message_encoding, schema)(message.data)
            assert decoded.timestamp.seconds * 10**9 + decoded.timestamp.nanos == message.log_time


def test_same_seed_gives_identical_message_bytes(tmp_path):
    first, second = tmp_path / "a.mcap", tmp_path / "b.mcap"
    record(first, time_limit_s=25.0)
    record(second, time_limit_s=25.0)
    a, b = messages_by_topic(first), messages_by_topic(second)
    assert set(a) == set(b) == set(TOPICS)
    for topic in TOPICS:
        assert [m.data for m in a[topic]] == [m.data for m in b[topic]], topic
        assert [m.log_time for m in a[topic]] == [m.log_time for m in b[topic]], topic


CRASHING_RUN = """
import os, signal, sys
from swarmnav.models.scenario import load_scenario
from swarmnav.log.writer import McapRecorder
from swarmnav.sim.episode import EpisodeSpec, run_episode

class Crash(McapRecorder):
    def step(self, frame):
        super().step(frame)
        if frame.time_s >= 3.5:
            os.kill(os.getpid(), signal.SIGKILL)

run_episode(EpisodeSpec(load_scenario(sys.argv[2])), [Crash(sys.argv[1])])
"""


def test_sigkill_leaves_a_file_that_log_recover_completes(tmp_path, full_run, capsys):
    killed, recovered = tmp_path / "killed.mcap", tmp_path / "recovered.mcap"
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    process = subprocess.run([sys.executable, "-c", CRASHING_RUN, str(killed), SCENARIO],
                             cwd=REPO, env=env, capture_output=True, timeout=120)
    assert process.returncode == -9, process.stderr.decode()[-2000:]
    raw = read_records(killed)
    assert not raw.complete and raw.messages
    with killed.open("rb") as stream, pytest.raises(Exception):
        make_reader(stream).get_summary().statistics.message_count  # the default reader cannot

    assert main(["log", "recover", str(killed), str(recovered)]) == 0
    assert "recovered" in capsys.readouterr().out
    with recovered.open("rb") as stream:
        reader = make_reader(stream)
        statistics = reader.get_summary().statistics
        got = [(m.channel_id, m.log_time, m.data) for _, _, m in reader.iter_messages(log_time_order=False)]
    assert statistics.message_count == len(got) == len(raw.messages)
    # Flushes happen every simulated second: everything up to t = 3 s survives,
    # byte for byte the same as in the run that was not killed.
    last_flush_ns = 3 * 10**9
    assert max(t for _, t, _ in got) == last_flush_ns
    reference = messages_by_topic(full_run[0])
    recovered_topics = messages_by_topic(recovered)
    for topic, messages in recovered_topics.items():
        expected = [m.data for m in reference[topic] if m.log_time <= last_flush_ns]
        assert [m.data for m in messages] == expected, topic
    assert "recovery" in {m.name for m in make_reader(recovered.open("rb")).iter_metadata()}


def test_replay_video_has_expected_frames_and_is_not_blank(tmp_path, full_run):
    from swarmnav.video.render import expected_frames
    from video_files import read_video_frames, video_info

    path, _ = full_run
    video = tmp_path / "top.mp4"
    assert main(["replay", str(path), "--video", str(video), "--fps", "2",
                 "--width", "160", "--height", "120"]) == 0
    log = read_log(path)
    frames, _ = video_info(video)
    assert frames == expected_frames(log.duration_s, 2.0)
    images = read_video_frames(video, every=50)
    for image in images:
        assert image.shape == (120, 160, 3)
        assert image.std() > 10.0  # not a blank (uniform) frame
    assert not np.array_equal(images[0], images[-1])  # the robot moved


def test_chase_camera_renders(tmp_path, full_run):
    from video_files import read_video_frames

    video = tmp_path / "chase.mp4"
    assert main(["replay", str(full_run[0]), "--video", str(video), "--camera", "chase", "--fps", "0.5",
                 "--width", "128", "--height", "96"]) == 0
    assert all(image.std() > 10.0 for image in read_video_frames(video))


def test_replay_verify_passes_bitwise_on_a_fresh_log(full_run, capsys):
    assert main(["replay", str(full_run[0]), "--verify"]) == 0
    out = capsys.readouterr().out
    assert "bitwise equal" in out and "DIFFERENT" not in out


def test_plot_writes_an_image(tmp_path, full_run):
    out = tmp_path / "run.png"
    assert main(["plot", str(full_run[0]), "-o", str(out)]) == 0
    assert out.stat().st_size > 20_000
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plot_svg_names_everything_it_draws(tmp_path, full_run):
    """The legend names obstacles, plans, the driven trajectory and collisions; time has a colour bar."""
    path, episode = full_run
    out = tmp_path / "run.svg"
    assert main(["plot", str(path), "-o", str(out)]) == 0
    svg = out.read_text()
    for label in ("static obstacle", "moving obstacle", "planned path", "driven trajectory (time colour)",
                  "start", "goal", "simulation time [s]"):
        assert label in svg, label
    if episode.result.collisions:
        assert f"collision begins ({episode.result.collisions})" in svg


def test_plot_title_wraps_so_it_is_never_clipped(full_run):
    import dataclasses

    from swarmnav.log.plot import TITLE_CHARS, figure_title

    log = read_log(full_run[0])
    long_name = "a-scenario-with-a-very-long-name-" * 4
    metadata = {**log.metadata, "scenario": {**log.metadata["scenario"], "name": long_name}}
    title = figure_title(dataclasses.replace(log, metadata=metadata))
    assert "".join(title.split()).startswith("".join(long_name.split())[:40])
    assert len(title.splitlines()) >= 3 and all(len(line) <= TITLE_CHARS for line in title.splitlines())


def test_plot_marks_time_along_moving_tracks_and_the_trajectory():
    from swarmnav.log.plot import _mark_step_s, decimated

    assert [_mark_step_s(d) for d in (4.0, 72.4, 3000.0)] == [0.5, 10.0, 300.0]
    picked = decimated(1_000_000, 4000)
    assert len(picked) <= 4000 and picked[0] == 0 and picked[-1] == 999_999
    assert np.array_equal(decimated(10, 4000), np.arange(10))


def test_log_info_prints_channels_and_outcome(full_run, capsys):
    assert main(["log", "info", str(full_run[0])]) == 0
    out = capsys.readouterr().out
    assert SCENARIO in out and "goal_reached" in out
    for topic in TOPICS:
        assert topic in out
    navigator = full_run[1].spec.navigator  # the scenario's, as the run resolved it
    assert f"navigator:  {navigator} " in out
    assert main(["log", "info", str(full_run[0]), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["navigator"] == navigator


@pytest.mark.parametrize("command", [["log info"], ["replay", "--verify"], ["plot", "-o", "p.png"]])
def test_a_log_without_its_footer_is_read_with_one_warning_line(tmp_path, full_run, capsys, command):
    """log info, replay and plot read a cut log alike: what was recovered, a warning line, exit 0."""
    cut = tmp_path / "truncated.mcap"
    cut.write_bytes(full_run[0].read_bytes()[:40_000])
    argv = command[0].split() + [str(cut)] + [str(tmp_path / a) if a.endswith(".png") else a for a in command[1:]]
    assert main(argv) == 0
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"warning: {cut}: truncated") and "log recover" in lines[0]
    if command[0] == "log info":
        assert "messages" in captured.out and "none: the run did not finish" in captured.out
    if command[0] == "replay":
        assert "prefix bitwise equal" in captured.out


@pytest.mark.parametrize("kind", ["not_mcap", "empty"])
@pytest.mark.parametrize("command", [["log", "info"], ["replay"]])
def test_bad_log_gives_one_line_error_and_exit_2(tmp_path, full_run, capsys, kind, command):
    bad = tmp_path / f"{kind}.mcap"
    if kind == "not_mcap":
        bad.write_text("name = 'not a log'\n")
    else:
        bad.write_bytes(b"")
    argv = command + [str(bad)] + (["--video", str(tmp_path / "x.mp4")] if command == ["replay"] else [])
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert str(bad) in err
    assert not (tmp_path / "x.mp4").exists()


def test_live_view_serves_the_same_channels_on_loopback(tmp_path):
    """A Foxglove WebSocket client sees every channel, stamped with sim time,
    and a late subscriber still gets the path and the static obstacles."""
    import json
    import struct
    import threading
    import time

    from websockets.sync.client import connect  # a dependency of mujoco

    recorder = McapRecorder(tmp_path / "live.mcap", live=True, live_port=0, live_speed=4.0)
    runner = threading.Thread(target=run_episode, args=(EpisodeSpec(load_scenario("gwo-scenario-1")), [recorder]),
                              kwargs={"time_limit_s": 3.0})
    runner.start()
    try:
        deadline = time.monotonic() + 20
        while recorder.live_port_bound is None and time.monotonic() < deadline:
            time.sleep(0.01)
        assert recorder._server is not None
        with connect(f"ws://127.0.0.1:{recorder.live_port_bound}", subprotocols=["foxglove.sdk.v1"],
                     open_timeout=5) as client:
            channels: dict[str, int] = {}
            while len(channels) < len(TOPICS):
                message = json.loads(client.recv(timeout=5))
                if message["op"] == "advertise":
                    channels.update({c["topic"]: c["id"] for c in message["channels"]})
            assert set(channels) == set(TOPICS)
            wanted = {"/tf": 1, "/obstacles": 2, "/planner/path": 3}
            client.send(json.dumps({"op": "subscribe", "subscriptions": [
                {"id": sub, "channelId": channels[topic]} for topic, sub in wanted.items()]}))
            seen: dict[int, int] = {}
            while set(seen) != {1, 2, 3}:
                data = client.recv(timeout=5)
                if isinstance(data, bytes):
                    _, subscription, stamp_ns = struct.unpack("<BIQ", data[:13])
                    seen.setdefault(subscription, stamp_ns)
            assert all(stamp < 3 * 10**9 for stamp in seen.values())  # sim time, not the epoch
    finally:
        runner.join(timeout=30)
    assert read_log(tmp_path / "live.mcap").counts["/tf"] == 151


def test_render_benchmark_runs(capsys):
    assert main(["bench", "render", "--frames", "3", "--width", "64", "--height", "48", "--json"]) == 0
    figures = __import__("json").loads(capsys.readouterr().out)
    assert figures["frames"] == 3 and figures["frames_per_s"] > 0 and figures["mujoco_gl"] == "egl"


def test_bad_video_size_is_a_config_error(full_run, tmp_path, capsys):
    assert main(["replay", str(full_run[0]), "--video", str(tmp_path / "x.mp4"), "--width", "641"]) == 2
    assert "--width" in capsys.readouterr().err


def test_step_json_is_the_same_text_as_sorted_json_dumps():
    """The per-step JSON is formatted directly for speed; it must stay byte-identical to
    json.dumps(sort_keys=True), including edge values and non-finite ones."""
    import json

    from swarmnav.log.messages import controller_json, wheels_json

    rng = np.random.default_rng(7)
    edge = [0.0, -0.0, 1e-300, -1e300, 5e-324, 0.1, 1 / 3, math.pi, 12.5, math.nan, math.inf, -math.inf]
    samples = list(rng.normal(0, 20, (200, 4))) + [np.array(rng.choice(edge, 4)) for _ in range(200)]
    for command_l, command_r, measured_l, measured_r in samples:
        expected = json.dumps({"command_left_rad_s": float(command_l), "command_right_rad_s": float(command_r),
                               "measured_left_rad_s": float(measured_l), "measured_right_rad_s": float(measured_r)},
                              sort_keys=True)
        assert wheels_json(np.array([command_l, command_r]), (measured_l, measured_r)) == expected
        index = int(rng.integers(0, 1000))
        expected = json.dumps({"linear_m_s": float(command_l), "angular_rad_s": float(measured_r),
                               "waypoint_index": index}, sort_keys=True)
        assert controller_json(np.float64(command_l), measured_r, np.int64(index)) == expected


def _decoded(path: Path, topic: str) -> list:
    factory = DecoderFactory()
    with path.open("rb") as stream:
        return [factory.decoder_for(channel.message_encoding, schema)(message.data)
                for schema, channel, message in make_reader(stream).iter_messages(topics=[topic])]


def test_scene_has_the_arena_outline_and_the_robot_footprint(full_run):
    path, _ = full_run
    scenario = load_scenario(SCENARIO)
    (update,) = _decoded(path, "/scene")
    entities = {e.id: e for e in update.entities}
    assert set(entities) == {"arena", "robot_footprint"}
    arena, footprint = entities["arena"], entities["robot_footprint"]
    assert arena.frame_id == "world"
    corners = {(p.x, p.y) for p in arena.lines[0].points}
    assert corners == {(0.0, 0.0), (scenario.arena_width_m, 0.0), (0.0, scenario.arena_height_m),
                       (scenario.arena_width_m, scenario.arena_height_m)}
    # The footprint follows the robot through /tf: in base_link, frame-locked, the robot's radius.
    assert footprint.frame_id == "base_link" and footprint.frame_locked
    (disc,) = footprint.cylinders
    assert math.isclose(disc.size.x / 2, scenario.robot_radius_m, rel_tol=1e-6)
    assert disc.top_scale == disc.bottom_scale == 1.0 and disc.color.a > 0


def test_events_are_foxglove_log_messages_that_read_back(full_run):
    path, episode = full_run
    logs = _decoded(path, "/events")
    log = read_log(path)
    assert [m.message.split(" ", 1)[0] for m in logs] == [kind for _, kind, _ in log.events]
    assert logs[-1].message.startswith(episode.result.outcome)
    levels = {m.message.split(" ", 1)[0]: m.level for m in logs}
    assert levels.get("collision_begin", 3) == 3  # WARNING
    assert levels[episode.result.outcome] in (2, 3)  # INFO for goal_reached, WARNING for a timeout
    assert all(m.timestamp.seconds * 10**9 + m.timestamp.nanos > 0 for m in logs)
    collisions = [d for _, k, d in log.events if k == "collision_begin"]
    assert all(isinstance(d["geom_a"], str) for d in collisions)


def test_metadata_values_are_plain_strings_and_read_back_typed(full_run):
    path, episode = full_run
    with path.open("rb") as stream:
        outcome = {m.name: m.metadata for m in make_reader(stream).iter_metadata()}["outcome"]
    assert outcome["outcome"] == episode.result.outcome  # no JSON quotes for Foxglove to show
    assert float(outcome["sim_time_s"]) > 0
    log = read_log(path)
    assert log.outcome["outcome"] == episode.result.outcome
    assert log.outcome["collisions"] == episode.result.collisions
    assert isinstance(log.outcome["reached"], bool)


@pytest.mark.parametrize("value", ["goal_reached", "true", "12", "null", '"quoted"', "", "a b", 3, 2.5, None,
                                   True, [1, 2], {"k": "v"}])
def test_metadata_text_round_trips_every_value(value):
    from swarmnav.log.format import metadata_text, metadata_value

    text = metadata_text(value)
    assert metadata_value(text) == value and type(metadata_value(text)) is type(value)
    if isinstance(value, str) and value in ("goal_reached", "a b", ""):
        assert text == value


def test_events_of_older_logs_in_json_still_read():
    from mcap.records import Channel, Schema

    from swarmnav.log.format import LEGACY_EVENT_SCHEMA, dumps
    from swarmnav.log.reader import event_decoder
    from swarmnav.log.records import RawLog

    raw = RawLog(path=Path("old.mcap"), schemas={1: Schema(id=1, name="swarmnav.Event", encoding="jsonschema",
                                                          data=dumps(LEGACY_EVENT_SCHEMA).encode())})
    channel = Channel(id=1, topic="/events", message_encoding="json", schema_id=1, metadata={})
    decode = event_decoder(raw, channel)
    assert decode(dumps({"kind": "timeout", "details": {"x_m": 1.5}}).encode()) == ("timeout", {"x_m": 1.5})
