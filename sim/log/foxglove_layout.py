"""``swarmnav foxglove-layout [--log-format ros2] [-o FILE]``: the Foxglove layout for a run log.

The layout (``sim/log/foxglove_layout.json``, shipped in the package) has a 3D panel
looking down on the scene (``/scene``'s arena and footprint, ``/obstacles``, the
planned path, the range scan, what the navigator acted on), a plot of the wheel
speeds, a plot of the range readings (their lower envelope is the clearance the
rangefinders saw) and the Log panel on ``/events``.  :func:`build_layout` builds it
with the foxglove SDK's layout types (``foxglove.layouts``); the shipped file is
that output, which a test checks, so the two never drift.  Open a log in Foxglove,
then import the file from the layout menu.  Logs of profile ``ros2`` have a layout of their
own (``foxglove_layout_ros2.json``): the same panels on the ROS 2 topics (``/plan``,
``/scan``, ``/joint_states`` and ``/wheels/command``, ``/rosout``), in the ``world`` frame,
which a ``ros2`` log's ``/tf_static`` places at ``map``.
"""

from __future__ import annotations

import argparse
import json
import sys
from importlib import resources
from pathlib import Path

from swarmnav.sim import palette
from swarmnav.log.format import (
    EVENTS_TOPIC,
    MAP_TOPIC,
    NAVIGATOR_TOPIC,
    ODOM_TOPIC,
    ROS2_EVENTS_TOPIC,
    ROS2_PROFILE,
    SCENE_TOPIC,
    WORLD_FRAME,
)

LAYOUT_FILES = {"swarmnav": "foxglove_layout.json", ROS2_PROFILE: "foxglove_layout_ros2.json"}
LAYOUT_FILE = LAYOUT_FILES["swarmnav"]
WHEEL_SERIES = (("command_left_rad_s", "left commanded", "dashed", palette.PLANNERS[0]),
                ("measured_left_rad_s", "left measured", "solid", palette.PLANNERS[0]),
                ("command_right_rad_s", "right commanded", "dashed", palette.PLANNERS[1]),
                ("measured_right_rad_s", "right measured", "solid", palette.PLANNERS[1]))


def build_layout(log_format: str = "swarmnav") -> str:
    """The layout of a log of ``log_format`` as the JSON text Foxglove imports (from the SDK's layout types)."""
    import foxglove.layouts as fl

    ros2 = log_format == ROS2_PROFILE
    path_topic, scan_topic = ("/plan", "/scan") if ros2 else ("/planner/path", "/range/scan")
    markers = fl.BaseRendererRosMarkerTopicSettings if ros2 else fl.BaseRendererSceneUpdateTopicSettings
    topics = {topic: markers(visible=True) for topic in (SCENE_TOPIC, "/obstacles", NAVIGATOR_TOPIC)}
    topics[path_topic] = fl.BaseRendererPosesTopicSettings(visible=True, type="line", line_width=0.04,
                                                           gradient=(palette.PLANNED, palette.PLANNED))
    topics[scan_topic] = fl.BaseRendererLaserScanTopicSettings(visible=True)
    if ros2:
        # The sensed map (only in logs with the map unknown), drawn as Foxglove draws a ROS map.
        topics[MAP_TOPIC] = fl.BaseRendererRosOccupancyGridTopicSettings(visible=True, color_mode="map",
                                                                        draw_behind=True, alpha=0.6)
        wheel_series = [(f"{topic}.velocity[{side}]", f"{name} {label}", style, palette.PLANNERS[side])
                        for side, name in enumerate(("left", "right"))
                        for topic, label, style in (("/wheels/command", "commanded", "dashed"),
                                                    ("/joint_states", "measured", "solid"))]
    else:
        wheel_series = [(f"/wheels.{field}", label, style, colour) for field, label, style, colour in WHEEL_SERIES]
        # The sensed map (only in logs with the map unknown): occupancy percent, from clear to dark grey; and
        # the odometry pose (only with knowledge.pose = "odometry").
        topics[MAP_TOPIC] = fl.BaseRendererGridTopicSettings(
            visible=True, color_mode="gradient", color_field="occupancy", gradient=("#ffffff20", "#000000c0"),
            min_value=0.0, max_value=100.0, draw_behind=True)
        topics[ODOM_TOPIC] = fl.BaseRendererPoseTopicSettings(visible=True)
    scene = fl.ThreeDeePanel(title="scene (top view)", config=fl.ThreeDeeConfig(
        fixed_frame=WORLD_FRAME, follow_tf=WORLD_FRAME, follow_mode="follow-none", topics=topics,
        camera_state=fl.ThreeDeeCameraState(perspective=False, distance=16.0, target_offset=(5.0, 5.0, 0.0))))
    wheels = fl.PlotPanel(title="wheel speeds [rad/s]", config=fl.PlotConfig(
        y_axis_label="rad/s", paths=[fl.PlotSeries(value=value, label=label, line_style=style, color=colour)
                                     for value, label, style, colour in wheel_series]))
    ranges = fl.PlotPanel(title="range readings [m] (lower envelope: clearance seen)", config=fl.PlotConfig(
        y_axis_label="m from the robot's centre", min_y_value=0.0,
        paths=[fl.PlotSeries(value=f"{scan_topic}.ranges[:]", label="range readings", show_line=False,
                             color=palette.COLLISION)]))
    events = fl.LogPanel(title="events", config=fl.LogConfig(topic_to_render=ROS2_EVENTS_TOPIC if ros2 else EVENTS_TOPIC))
    layout = fl.Layout(content=fl.SplitContainer(direction="row", items=[
        fl.SplitItem(proportion=3, content=scene),
        fl.SplitItem(proportion=2, content=fl.SplitContainer(direction="column", items=[
            fl.SplitItem(content=wheels), fl.SplitItem(content=ranges), fl.SplitItem(content=events)]))]))
    return json.dumps(json.loads(layout.to_json()), indent=2, sort_keys=True) + "\n"


def shipped_layout(log_format: str = "swarmnav") -> str:
    """The layout file of the installed package for logs of ``log_format``."""
    return resources.files("swarmnav.log").joinpath(LAYOUT_FILES[log_format]).read_text()


def run(args: argparse.Namespace) -> int:
    text = shipped_layout(getattr(args, "log_format", "swarmnav"))
    if args.out is None:
        sys.stdout.write(text)
        return 0
    out = Path(args.out)
    if out.is_dir():
        from swarmnav.models.errors import ConfigError
        raise ConfigError("-o", "is a directory; give a file name such as swarmnav-layout.json", str(out))
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text)
    except OSError as error:
        raise type(error)(error.errno, error.strerror, str(out)) from None
    print(out)
    return 0
