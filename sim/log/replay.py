"""``swarmnav replay LOG``: a logged run to video, or re-simulated and checked.

``--video out.mp4`` rebuilds the scene from the MJCF attached to the log, poses
the robot (free joint) and the moving obstacles (mocap bodies) from the log frame
by frame, and renders offscreen (see :mod:`swarmnav.video.render`) through the same
:class:`swarmnav.video.render.VideoRecorder` that ``swarmnav run --video`` uses.

``--verify`` re-simulates from what the log holds (scenario TOML, planner name and
parameters, seed, and the attached MJCF, not today's model files) and compares
every logged pose and range scan with the re-simulated one (the comparison and
its verdict are :mod:`swarmnav.log.verify_report`).  On the same machine and versions we
expect bitwise equality; otherwise the largest deviation is reported and where it
first appeared.  A log that ends early (killed, interrupted, recovered, or a file
without its footer, read as far as it goes with a warning line) passes when every
step it holds is equal: "prefix bitwise equal, the log ends at t = ...".

Both stream the log (:func:`swarmnav.log.reader.read_log`): memory is the arrays of
numbers the comparison or the frames need, not the log's messages.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Iterator

import numpy as np

from swarmnav.models.errors import ConfigError
from swarmnav.sim.defaults import DEFAULT_FPS
from swarmnav.log.format import ranges_from_scan
from swarmnav.log.reader import RunLog, read_log, truncation_advice
from swarmnav.log.records import LogError
from swarmnav.log.scene_guard import compile_log_scene
from swarmnav.models.contained_files import loads_json
from swarmnav.sim.recording import ObstacleInfo, RunContext, StepFrame
from swarmnav.log.verify_report import TrajectoryCapture, VerifyReport, compare_with_log


EXIT_DIFFERENT = 4  # replay --verify: the re-simulation differs from the log

def _params(log: RunLog, record: str) -> dict:
    """A component's ``params`` metadata: a JSON table (anything else is one LogError naming it)."""
    text = log.metadata.get(record, {}).get("params", "{}")
    try:
        value = loads_json(text, str(log.raw.path), f"{record}.params")
    except ConfigError as exc:
        raise LogError(log.raw.path, f"metadata {record}.params: {exc.problem}") from None
    if not isinstance(value, dict):
        raise LogError(log.raw.path, f"metadata {record}.params: expected a JSON table, got {text[:60]!r}")
    return value


def context_from_log(log: RunLog) -> RunContext:
    """The :class:`RunContext` a log was written with (as far as a renderer needs it); its scene is checked
    and compiled once here (:func:`swarmnav.log.scene_guard.compile_log_scene`), so a scene from elsewhere that
    reaches beyond itself is refused before anything renders or re-simulates."""
    compile_log_scene(log.mjcf_xml, str(log.raw.path))
    planner = log.metadata.get("planner", {})
    navigator = log.metadata.get("navigator", {})
    return RunContext(
        scenario_name=log.scenario_name,
        scenario_toml=log.metadata.get("scenario", {}).get("toml", ""),
        planner_name=planner.get("name", ""),
        planner_params=_params(log, "planner"),
        seed=int(log.run_value("seed", 0)),
        mjcf_xml=log.mjcf_xml,
        control_dt_s=float(log.run_value("control_dt_s", 0.02)),
        physics_dt_s=float(log.run_value("physics_dt_s", 0.002)),
        sensor_angles_rad=np.asarray(log.run_value("sensor_angles_rad", []), dtype=float),
        sensor_range_m=float(log.run_value("sensor_range_m", 0.0)),
        sensor_offset_m=float(log.run_value("sensor_offset_m", 0.0)),
        sensor_height_m=float(log.run_value("sensor_height_m", 0.0)),
        obstacles=tuple(
            ObstacleInfo(o["entity_id"], o["shape"], tuple(o["size_m"]), tuple(o["position_m"]), o["moving"])
            for o in log.obstacles
        ),
        versions=dict(log.metadata.get("versions", {})),
        arena_size_m=tuple(log.run_value("arena_size_m", [10.0, 10.0])),
        navigator_name=navigator.get("name", "follow"),
        navigator_params=_params(log, "navigator"),
        world_seed=int(log.run_value("world_seed", log.run_value("seed", 0))),
        clearance_m=log.run_value("clearance_m", None),
        map_knowledge=log.run_value("map_knowledge", None),
        pose_source=log.run_value("pose_source", None),
    )


def frames_from_log(log: RunLog) -> Iterator[StepFrame]:
    """One StepFrame per logged control step (``/tf`` times), other channels aligned by time, made as
    they are consumed (a long log is never a list of frames)."""
    times = log.time_s
    count = len(times)

    def align(channel_times: np.ndarray) -> np.ndarray:
        if len(channel_times) == 0:
            return np.full(count, -1)
        index = np.searchsorted(channel_times, times, side="right") - 1
        return np.clip(index, 0, len(channel_times) - 1)

    scan_index = align(log.scan_time_s)
    ranges = ranges_from_scan(log.range_m, float(log.run_value("sensor_offset_m", 0.0))) if len(log.range_m) else None
    wheel_index = align(log.wheel_time_s)
    control_index = align(log.controller_time_s)
    moving = [o["entity_id"] for o in log.obstacles if o["moving"]]
    tracks = []
    for name in moving:
        track_t, track_xy = log.obstacle_tracks.get(name, (np.zeros(0), np.zeros((0, 2))))
        tracks.append((align(track_t), track_xy))

    for k in range(count):
        range_m = np.full(len(log.scan_angles_rad), np.inf)
        if ranges is not None and scan_index[k] >= 0:
            range_m = ranges[scan_index[k]]
        moving_xy = np.array([xy[i[k]] if len(xy) else (np.nan, np.nan) for i, xy in tracks]).reshape(-1, 2)
        w, c = wheel_index[k], control_index[k]
        yield StepFrame(
            time_s=float(times[k]),
            position_m=log.position_m[k],
            quaternion_wxyz=log.quaternion_wxyz[k],
            heading_rad=float(log.heading_rad[k]),
            range_m=range_m,
            wheel_command_rad_s=log.wheel_command_rad_s[w] if w >= 0 else np.zeros(2),
            wheel_measured_rad_s=log.wheel_measured_rad_s[w] if w >= 0 else np.zeros(2),
            linear_m_s=float(log.linear_m_s[c]) if c >= 0 else 0.0,
            angular_rad_s=float(log.angular_rad_s[c]) if c >= 0 else 0.0,
            waypoint_index=int(log.waypoint_index[c]) if c >= 0 else 0,
            moving_obstacles_m=moving_xy,
        )


def render_log(log: RunLog, video_path: str | Path, *, camera: str = "top", width: int = 640,
               height: int = 480, fps: float = DEFAULT_FPS, trail: bool = True) -> dict[str, float]:
    """Render a log to MP4; returns frame count, video and render seconds."""
    from swarmnav.video.render import VideoRecorder  # EGL only when a video is asked for

    recorder = VideoRecorder(video_path, camera=camera, width=width, height=height, fps=fps, trail=trail)
    recorder.start(context_from_log(log))
    paths = iter(log.paths)
    pending = next(paths, None)
    try:
        for frame in frames_from_log(log):
            while pending is not None and pending[0] <= frame.time_s + 1e-12:
                recorder.path(*pending)
                pending = next(paths, None)
            recorder.step(frame)
    finally:
        recorder.finish({})
    return {"frames": recorder.frames, "video_s": recorder.frames / fps, "render_s": recorder.render_seconds}


def code_for_verify(context: RunContext, named: dict, trust_code: bool, source: str) -> dict:
    """The navigator parameters to re-simulate with: the log's, with the code parameters named on the command
    line in place of the logged ones.

    A log is data: a parameter of its planner or navigator that names code (the
    ``policy`` navigator's ``policy``) is re-run only when the user names it on the
    command line (``--navigator-set policy=module:function``), or with
    ``--trust-code``.  Nothing is imported here; only declarations are read.

    Raises:
        ConfigError: a logged code parameter that is neither named nor trusted, or a ``--navigator-set``
            key that is not a code parameter of the logged navigator.
    """
    from swarmnav.controllers.navigators import NAVIGATORS
    from swarmnav.models.parameters import TRUST_OPTION, code_parameters, refuse_code
    from swarmnav.planners.registry import PLANNERS

    cls = NAVIGATORS.get(context.navigator_name)
    code_keys = code_parameters(cls) if cls is not None else ()
    for key in named:
        if key not in code_keys:
            raise ConfigError("--navigator-set", f"{key!r}: replay --verify takes only the parameters of the log's "
                              f"navigator {context.navigator_name!r} that name code "
                              f"({', '.join(code_keys) or 'it has none'}); the rest come from the log")
    if not trust_code:
        refuse_code(PLANNERS, "planner", context.planner_name, context.planner_params, source)
        for key in code_keys:
            if key in context.navigator_params and key not in named:
                raise ConfigError(f"navigator.params.{key}",
                                  f"the log was recorded with {key}={context.navigator_params[key]!r}, which names "
                                  f"code; replay --verify re-simulates it only when you name it: --navigator-set "
                                  f"{key}=MODULE:FUNCTION (or {TRUST_OPTION})", source)
    return {**context.navigator_params, **named}


def verify_log(log: RunLog, named: dict | None = None, trust_code: bool = False) -> VerifyReport:
    """Re-simulate a logged run from the log alone and compare poses step by step.

    Args:
        named: code parameters of the navigator named on the command line (see :func:`code_for_verify`).
        trust_code: run the code the log names.
    """
    import mujoco

    from swarmnav.models.scenario import parse_scenario
    from swarmnav.sim.episode import EpisodeSpec, plan_episode, run_episode
    from swarmnav.sim.scene import index_scene

    context = context_from_log(log)
    source = str(log.raw.path)
    if len(log.time_s) == 0:
        raise LogError(source, "holds no step to replay")
    navigator_params = code_for_verify(context, named or {}, trust_code, source)
    scenario = parse_scenario(context.scenario_toml, f"{source}[scenario]", trust_code=trust_code)
    scenario = scenario.with_knowledge(context.map_knowledge, context.pose_source)  # --map / --pose, as run
    spec = EpisodeSpec(scenario, context.planner_name, context.planner_params, context.navigator_name,
                       navigator_params, context.seed, context.world_seed, context.clearance_m)
    model = compile_log_scene(context.mjcf_xml, source)
    # Reproduce how the logged run stopped: a timeout at T means the limit was T.
    kinds = [kind for _, kind, _ in log.events]
    options = {}
    if "timeout" in kinds and len(log.time_s):
        options["time_limit_s"] = float(log.time_s[-1])
    if "stopped_on_collision" in kinds:
        options["stop_on_collision"] = True
    capture = TrajectoryCapture()
    episode = run_episode(plan_episode(spec, scene=index_scene(model, context.mjcf_xml)), [capture], **options)
    path, result = episode.path, episode.result
    return compare_with_log(log, capture, np.asarray(path.waypoints, dtype=float)[:, :2], result.outcome)


def run(args: argparse.Namespace) -> int:
    """Exit 0 on success (a log that ends early passes when its steps are equal), 4 when
    --verify finds a difference, 2 on bad input."""
    if not args.video and not args.verify:
        raise ConfigError("replay", "nothing to do: give --video OUT.mp4 and/or --verify")
    if (args.navigator_set or args.trust_code) and not args.verify:
        raise ConfigError("--navigator-set" if args.navigator_set else "--trust-code", "needs --verify")
    if args.video:
        from swarmnav.video.render import check_video_size
        check_video_size(args.width, args.height, args.fps)
    log = read_log(args.log, allow_truncated=True)  # as plot and log info: what was recovered, with a warning
    if not log.complete:
        print(f"warning: {args.log}: {truncation_advice(log.raw)}", file=sys.stderr)
    results: dict = {"log": str(args.log), "complete": log.complete}
    status = 0
    if args.video:
        info = render_log(log, args.video, camera=args.camera, width=args.width, height=args.height,
                          fps=args.fps, trail=not args.no_trail)
        results["video"] = {"path": str(args.video), **info}
        if not args.json:
            print(f"video: {args.video}: {info['frames']} frames, {info['video_s']:.1f} s at {args.fps:g} fps "
                  f"({info['frames'] / max(info['render_s'], 1e-9):.0f} frames/s rendered)")
    if args.verify:
        from swarmnav.sim.options import parse_settings
        named = parse_settings(args.navigator_set, "--navigator-set")
        report = verify_log(log, named, args.trust_code)
        results["verify"] = {**report.as_dict(), "named_on_command_line": named}
        if not args.json:
            for key, value in named.items():
                logged = context_from_log(log).navigator_params.get(key)
                print(f"re-simulated with {key}={value!r} as named on the command line (the log recorded "
                      f"{logged!r})")
            print("\n".join(report.lines()))
        status = 0 if report.passed else EXIT_DIFFERENT
    if args.json:
        print(json.dumps(results, sort_keys=True, default=str))
    sys.stdout.flush()
    return status
