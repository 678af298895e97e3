"""The shipped Foxglove layout: valid JSON, the SDK's own output, on topics a real log has."""

from __future__ import annotations

import json
import os

os.environ.setdefault("MUJOCO_GL", "egl")

from mcap.reader import make_reader  # noqa: E402

from swarmnav.models.scenario import load_scenario  # noqa: E402
from swarmnav.cli.main import main  # noqa: E402
from swarmnav.sim.episode import EpisodeSpec, run_episode  # noqa: E402
from swarmnav.log.foxglove_layout import build_layout, shipped_layout  # noqa: E402
from swarmnav.log.reader import read_log  # noqa: E402
from swarmnav.log.writer import McapRecorder  # noqa: E402


def _panels(node):
    if node.get("type") == "panel":
        yield node
    for item in node.get("items", []):
        yield from _panels(item["content"])


def _topics(panel) -> set[str]:
    config = panel["config"]
    found = set(config.get("topics", {}))
    found |= {series["value"].split(".", 1)[0] for series in config.get("paths", [])}
    if "topicToRender" in config:
        found.add(config["topicToRender"])
    return found


def test_shipped_layout_is_the_sdk_build():
    assert shipped_layout() == build_layout()


def test_layout_panels_read_topics_a_log_has(tmp_path):
    layout = json.loads(shipped_layout())
    panels = list(_panels(layout["content"]))
    assert {p["panelType"] for p in panels} == {"ThreeDee", "Plot", "Log"}
    path = tmp_path / "run.mcap"
    run_episode(EpisodeSpec(load_scenario("gwo-scenario-2")), [McapRecorder(path)])
    log = read_log(path)
    used = set().union(*(_topics(p) for p in panels))
    # /navigator appears only in logs of navigators that sense, /map with the map unknown, /odom with the
    # odometry pose; every other topic is in every log.
    assert used - {"/navigator", "/map", "/odom"} <= set(log.counts), used - set(log.counts)
    assert {"/scene", "/obstacles", "/wheels", "/events", "/range/scan"} <= used
    wheels = next(p for p in panels if any(s["value"].startswith("/wheels.") for s in p["config"].get("paths", [])))
    fields = {s["value"].split(".", 1)[1] for s in wheels["config"]["paths"]}
    with path.open("rb") as stream:
        _, _, message = next(make_reader(stream).iter_messages(topics=["/wheels"]))
    assert fields == set(json.loads(message.data))  # every plotted field is in the messages, and all of them


def test_foxglove_layout_command_writes_the_file(tmp_path, capsys):
    out = tmp_path / "layouts" / "swarmnav.json"
    assert main(["foxglove-layout", "-o", str(out)]) == 0
    assert json.loads(out.read_text()) == json.loads(shipped_layout())
    assert main(["foxglove-layout", "-o", str(tmp_path)]) == 2
    assert "-o" in capsys.readouterr().err


def test_ros2_layout_is_the_sdk_build_on_topics_a_ros2_log_has(tmp_path, capsys):
    assert shipped_layout("ros2") == build_layout("ros2")
    panels = list(_panels(json.loads(shipped_layout("ros2"))["content"]))
    path = tmp_path / "run.mcap"
    run_episode(EpisodeSpec(load_scenario("gwo-scenario-2")), [McapRecorder(path, log_format="ros2")],
                time_limit_s=2.0)
    log = read_log(path)
    used = set().union(*(_topics(p) for p in panels))
    # /navigator and /map are in logs of sensing navigators and of runs with the map unknown only.
    assert used - {"/navigator", "/map"} <= set(log.counts), used - set(log.counts)
    assert {"/scene", "/obstacles", "/plan", "/scan", "/joint_states", "/wheels/command", "/rosout"} <= used
    scene = next(p for p in panels if p["panelType"] == "ThreeDee")
    with path.open("rb") as stream:
        _, _, static = next(make_reader(stream).iter_messages(topics=["/tf_static"]))
    assert scene["config"]["fixedFrame"].encode() in static.data  # the layout's frame is in the log's tree
    assert main(["foxglove-layout", "--log-format", "ros2"]) == 0
    assert json.loads(capsys.readouterr().out) == json.loads(shipped_layout("ros2"))
