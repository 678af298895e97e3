"""``swarmnav bench render``: offscreen EGL frames per second at 640x480.

Times pose + overlay (path and 12 beams) + render + read-back on a scenario's
compiled scene; MP4 encoding runs in ffmpeg's own process and is not included.
``--compare-defaults`` also times the same frames with MuJoCo's own default
quality settings, read from MuJoCo itself rather than written down here.
"""

from __future__ import annotations

import argparse
import math
import os
import time

# Imported at the top on purpose: swarmnav.video.render sets MUJOCO_GL=egl, which must happen before
# anything imports mujoco, and the CLI imports this module before the runner's.
from swarmnav.benchmarks.figures import print_figures
from swarmnav.sim.defaults import BENCH_RENDER_QUICK_FRAMES
from swarmnav.video.caption import FrameCaption, run_title
from swarmnav.video.render import ScenePoser, SceneRenderer, check_video_size

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

TARGET_FRAMES_PER_S = 60.0

# An MJCF with one light and one material and nothing set: MuJoCo fills in its defaults.
_DEFAULTS_MJCF = '<mujoco><asset><material name="m"/></asset><worldbody><light/></worldbody></mujoco>'


def mujoco_default_quality(model: mujoco.MjModel) -> None:
    """Undo a scene's render-speed settings: multisampling, shadow map size, shadow-casting
    lights and material reflectance take the values MuJoCo gives an MJCF that sets none."""
    reference = mujoco.MjModel.from_xml_string(_DEFAULTS_MJCF)
    model.vis.quality.offsamples = reference.vis.quality.offsamples
    model.vis.quality.shadowsize = reference.vis.quality.shadowsize
    model.light_castshadow[:] = reference.light_castshadow[0]
    model.mat_reflectance[:] = reference.mat_reflectance[0]


def benchmark_render(
    mjcf_xml: str, *, width: int = 640, height: int = 480, frames: int = 120, camera: str = "top",
    fast: bool = True, grid_m: tuple[float, float] | None = None,
) -> dict[str, float]:
    """Rendered frames per second (pose + overlay + render + caption, no encoding) for a scene.

    The robot drives a circle so the chase camera moves too.  ``fast=False``
    renders with MuJoCo's own defaults instead (:func:`mujoco_default_quality`
    and the renderer's default flags) for comparison.
    """
    model = mujoco.MjModel.from_xml_string(mjcf_xml)
    if not fast:
        mujoco_default_quality(model)
    poser = ScenePoser(model)
    renderer = SceneRenderer(model, width, height, camera, fast=fast, grid_m=grid_m)
    caption = FrameCaption(run_title("bench", "planner", "navigator", 0, 0), width, height)
    path = np.array([[1.0, 1.0], [3.0, 2.0], [5.0, 5.0], [8.0, 9.0]])
    try:
        renderer.render(poser.data)  # warm-up: context, textures
        started = time.perf_counter()
        for k in range(frames):
            angle = 2 * math.pi * k / max(frames, 1)
            position = np.array([5 + 2 * math.cos(angle), 5 + 2 * math.sin(angle), 0.0])
            poser.apply(
                position,
                np.array([math.cos(angle / 2 + math.pi / 4), 0, 0, math.sin(angle / 2 + math.pi / 4)]),
                None,
            )
            caption.draw(renderer.render(poser.data, path_m=path, beams=poser.beams(None), follow_xy_m=position),
                         k / 30.0)
        elapsed = time.perf_counter() - started
    finally:
        renderer.close()
    return {
        "width": width,
        "height": height,
        "camera": camera,
        "frames": frames,
        "seconds": elapsed,
        "frames_per_s": frames / elapsed,
        "ms_per_frame": 1e3 * elapsed / frames,
        "mujoco_gl": os.environ.get("MUJOCO_GL", ""),
    }


def run(args: argparse.Namespace) -> int:
    from swarmnav.models.errors import ConfigError
    from swarmnav.models.scenario import load_scenario
    from swarmnav.sim.scene import compile_scene

    check_video_size(args.width, args.height, 30.0)
    if args.frames < 1:
        raise ConfigError("--frames", f"must be at least 1, got {args.frames}")
    frames = min(args.frames, BENCH_RENDER_QUICK_FRAMES) if args.quick else args.frames
    scenario = load_scenario(args.scenario)
    scene = compile_scene(scenario)
    grid_m = (scenario.arena_width_m, scenario.arena_height_m)  # as VideoRecorder draws it
    figures = {"scenario": args.scenario,
               **benchmark_render(scene.xml, width=args.width, height=args.height,
                                  frames=frames, camera=args.camera, grid_m=grid_m),
               "target_frames_per_s": TARGET_FRAMES_PER_S}
    figures["meets_target"] = figures["frames_per_s"] >= TARGET_FRAMES_PER_S
    if args.compare_defaults:
        slow = benchmark_render(scene.xml, width=args.width, height=args.height,
                                frames=max(frames // 10, 5), camera=args.camera, fast=False)
        figures["defaults_frames_per_s"] = slow["frames_per_s"]
        figures["defaults_ms_per_frame"] = slow["ms_per_frame"]
        figures["speedup"] = figures["frames_per_s"] / slow["frames_per_s"]
    print_figures(figures, args.json)
    return 0
