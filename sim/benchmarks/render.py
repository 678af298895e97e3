"""``swarmnav bench render``: offscreen EGL frames per second (target >= 30 at 640x480).

Times pose + overlay (path and 12 beams) + render + read-back on a scenario's
compiled scene; MP4 encoding runs in ffmpeg's own process and is not included.
"""

from __future__ import annotations

import argparse
import json

from swarmnav.sim.render import benchmark_render

TARGET_FRAMES_PER_S = 30.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--scenario", default="dense-field-30")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--frames", type=int, default=150)
    parser.add_argument("--camera", choices=("top", "chase"), default="top")
    parser.add_argument("--compare-defaults", action="store_true",
                        help="also time MuJoCo's default quality (multisampling, shadows, reflections)")
    parser.add_argument("--json", action="store_true")


def run(args: argparse.Namespace) -> int:
    from swarmnav.models.scenario import load_scenario
    from swarmnav.sim.scene import compile_scene

    scene = compile_scene(load_scenario(args.scenario))
    figures = {"scenario": args.scenario,
               **benchmark_render(scene.xml, width=args.width, height=args.height,
                                  frames=args.frames, camera=args.camera),
               "target_frames_per_s": TARGET_FRAMES_PER_S}
    figures["meets_target"] = figures["frames_per_s"] >= TARGET_FRAMES_PER_S
    if args.compare_defaults:
        slow = benchmark_render(scene.xml, width=args.width, height=args.height,
                                frames=max(args.frames // 10, 5), camera=args.camera, fast=False)
        figures["defaults_frames_per_s"] = slow["frames_per_s"]
        figures["defaults_ms_per_frame"] = slow["ms_per_frame"]
        figures["speedup"] = figures["frames_per_s"] / slow["frames_per_s"]
    if args.json:
        print(json.dumps(figures))
    else:
        for key, value in figures.items():
            print(f"{key:<22} {value:.4g}" if isinstance(value, float) else f"{key:<22} {value}")
    return 0
