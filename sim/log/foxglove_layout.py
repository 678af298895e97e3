"""``swarmnav foxglove-layout [-o FILE]``: the Foxglove layout for a run log.

The layout (``sim/log/foxglove_layout.json``, shipped in the package) has a 3D panel
looking down on the scene (``/scene``'s arena and footprint, ``/obstacles``, the
planned path, the range scan, what the navigator acted on), a plot of the wheel
speeds, a plot of the range readings (their lower envelope is the clearance the
rangefinders saw) and the Log panel on ``/events``.  :func:`build_layout` builds it
with the foxglove SDK's layout types (``foxglove.layouts``); the shipped file is
that output, which a test checks, so the two never drift.  Open a log in Foxglove,
then import the file from the layout menu.
"""

from __future__ import annotations

import argparse
import json
import sys
from importlib import resources
from pathlib import Path

from swarmnav.sim import palette
from swarmnav.sim.log.format import EVENTS_TOPIC, MAP_TOPIC, NAVIGATOR_TOPIC, ODOM_TOPIC, SCENE_TOPIC, WORLD_FRAME

LAYOUT_FILE = "foxglove_layout.json"
WHEEL_SERIES = (("command_left_rad_s", "left commanded", "dashed", palette.PLANNERS[0]),
                ("measured_left_rad_s", "left measured", "solid", palette.PLANNERS[0]),
                ("command_right_rad_s", "right commanded", "dashed", palette.PLANNERS[1]),
                ("measured_right_rad_s", "right measured", "solid", palette.PLANNERS[1]))


def build_layout() -> str:
    """The layout as the JSON text Foxglove imports (from the SDK's layout types)."""
    import foxglove.layouts as fl

    topics = {topic: fl.BaseRendererSceneUpdateTopicSettings(visible=True)
              for topic in (SCENE_TOPIC, "/obstacles", NAVIGATOR_TOPIC)}
    topics["/planner/path"] = fl.BaseRendererPosesTopicSettings(visible=True, type="line", line_width=0.04,
                                                               gradient=(palette.PLANNED, palette.PLANNED))
    topics["/range/scan"] = fl.BaseRendererLaserScanTopicSettings(visible=True)
    # The sensed map (only in logs with the map unknown): occupancy percent, grey from free to occupied.
    topics[MAP_TOPIC] = fl.BaseRendererGridTopicSettings(visible=True, color_mode="gradient", color_field="occupancy",
                                                         gradient=("#ffffff20", "#000000c0"), min_value=0.0,
                                                         max_value=100.0, draw_behind=True)
    topics[ODOM_TOPIC] = fl.BaseRendererPoseTopicSettings(visible=True)  # the odometry pose (only with it)
    scene = fl.ThreeDeePanel(title="scene (top view)", config=fl.ThreeDeeConfig(
        fixed_frame=WORLD_FRAME, follow_tf=WORLD_FRAME, follow_mode="follow-none", topics=topics,
        camera_state=fl.ThreeDeeCameraState(perspective=False, distance=16.0, target_offset=(5.0, 5.0, 0.0))))
    wheels = fl.PlotPanel(title="wheel speeds [rad/s]", config=fl.PlotConfig(
        y_axis_label="rad/s", paths=[fl.PlotSeries(value=f"/wheels.{field}", label=label, line_style=style,
                                                   color=colour)
                                     for field, label, style, colour in WHEEL_SERIES]))
    ranges = fl.PlotPanel(title="range readings [m] (lower envelope: clearance seen)", config=fl.PlotConfig(
        y_axis_label="m from the robot's centre", min_y_value=0.0,
        paths=[fl.PlotSeries(value="/range/scan.ranges[:]", label="range readings", show_line=False,
                             color=palette.COLLISION)]))
    events = fl.LogPanel(title="events", config=fl.LogConfig(topic_to_render=EVENTS_TOPIC))
    layout = fl.Layout(content=fl.SplitContainer(direction="row", items=[
        fl.SplitItem(proportion=3, content=scene),
        fl.SplitItem(proportion=2, content=fl.SplitContainer(direction="column", items=[
            fl.SplitItem(content=wheels), fl.SplitItem(content=ranges), fl.SplitItem(content=events)]))]))
    return json.dumps(json.loads(layout.to_json()), indent=2, sort_keys=True) + "\n"


def shipped_layout() -> str:
    """The layout file of the installed package."""
    return resources.files("swarmnav.sim.log").joinpath(LAYOUT_FILE).read_text()


def run(args: argparse.Namespace) -> int:
    text = shipped_layout()
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
