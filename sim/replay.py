"""``swarmnav replay LOG``: a logged run to video, or re-simulated and checked.

``--video out.mp4`` rebuilds the scene from the MJCF attached to the log, poses
the robot (free joint) and the moving obstacles (mocap bodies) from the log frame
by frame, and renders offscreen (see :mod:`sim.render`) through the same
:class:`sim.render.VideoRecorder` that ``swarmnav run --video`` uses.

``--verify`` re-simulates from what the log holds (scenario TOML, planner name and
parameters, seed, and the attached MJCF, not today's model files) and compares
every logged pose with the re-simulated one.  On the same machine and versions
we expect bitwise equality; otherwise the largest deviation is reported and where
it first appeared.  The range scans are compared too and reported, but are not
part of the verdict: the attached MJCF is ``MjSpec.to_xml()`` text, which keeps 6
significant digits, so sites (and with them the rangefinder readings) may move by
micrometres unless the runner itself runs the model compiled from that text.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from swarmnav.models.errors import ConfigError
from swarmnav.sim.log_reader import LogError, RunLog, read_log
from swarmnav.sim.recording import ObstacleInfo, RunContext, StepFrame

DEFAULT_FPS = 30.0


def context_from_log(log: RunLog) -> RunContext:
    """The :class:`RunContext` a log was written with (as far as a renderer needs it)."""
    if not log.mjcf_xml:
        raise LogError(log.raw.path, "the log has no MJCF attachment (scene.xml)")
    planner = log.metadata.get("planner", {})
    navigator = log.metadata.get("navigator", {})
    return RunContext(
        scenario_name=log.scenario_name,
        scenario_toml=log.metadata.get("scenario", {}).get("toml", ""),
        planner_name=planner.get("name", ""),
        planner_params=json.loads(planner.get("params", "{}")),
        seed=int(log.metadata.get("run", {}).get("seed", 0)),
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
        navigator_params=json.loads(navigator.get("params", "{}")),
        world_seed=int(log.metadata.get("run", {}).get("seed" if "world_seed" not in log.metadata.get("run", {})
                                                       else "world_seed", 0)),
    )


def frames_from_log(log: RunLog) -> list[StepFrame]:
    """One StepFrame per logged control step (``/tf`` times), other channels aligned by time."""
    times = log.time_s
    count = len(times)

    def align(channel_times: np.ndarray) -> np.ndarray:
        if len(channel_times) == 0:
            return np.full(count, -1)
        index = np.searchsorted(channel_times, times, side="right") - 1
        return np.clip(index, 0, len(channel_times) - 1)

    offset_m = float(log.run_value("sensor_offset_m", 0.0))
    scan_index = align(log.scan_time_s)
    ranges = log.range_m - offset_m if len(log.range_m) else None   # back to distances from the sites
    wheel_index = align(log.wheel_time_s)
    control_index = align(log.controller_time_s)
    moving = [o["entity_id"] for o in log.obstacles if o["moving"]]
    tracks = []
    for name in moving:
        track_t, track_xy = log.obstacle_tracks.get(name, (np.zeros(0), np.zeros((0, 2))))
        tracks.append((align(track_t), track_xy))

    frames = []
    for k in range(count):
        range_m = np.full(len(log.scan_angles_rad), np.inf)
        if ranges is not None and scan_index[k] >= 0:
            row = ranges[scan_index[k]]
            range_m = np.where(np.isfinite(row), row, np.inf)
        moving_xy = np.array([xy[i[k]] if len(xy) else (np.nan, np.nan) for i, xy in tracks]).reshape(-1, 2)
        w, c = wheel_index[k], control_index[k]
        frames.append(StepFrame(
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
        ))
    return frames


def render_log(log: RunLog, video_path: str | Path, *, camera: str = "top", width: int = 640,
               height: int = 480, fps: float = DEFAULT_FPS, trail: bool = True) -> dict[str, float]:
    """Render a log to MP4; returns frame count, video and render seconds."""
    from swarmnav.sim.render import VideoRecorder  # EGL only when a video is asked for

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


@dataclass
class VerifyReport:
    """How a re-simulation compares with a log."""

    logged_steps: int
    simulated_steps: int
    compared_steps: int
    max_position_error_m: float
    max_quaternion_error: float
    worst_time_s: float | None
    first_difference_s: float | None
    bitwise_equal: bool
    path_bitwise_equal: bool
    path_max_error_m: float
    ranges_bitwise_equal: bool
    max_range_error_m: float
    outcome_logged: str
    outcome_simulated: str

    @property
    def passed(self) -> bool:
        return self.bitwise_equal and self.path_bitwise_equal

    def lines(self) -> list[str]:
        verdict = "bitwise equal" if self.passed else "DIFFERENT"
        lines = [
            f"verify: {verdict}: {self.compared_steps} poses compared "
            f"(logged {self.logged_steps}, re-simulated {self.simulated_steps})",
            f"  max position deviation:   {self.max_position_error_m:.3e} m"
            + (f" at t={self.worst_time_s:.3f} s" if self.worst_time_s is not None else ""),
            f"  max quaternion deviation: {self.max_quaternion_error:.3e}",
            f"  planned path: {'bitwise equal' if self.path_bitwise_equal else 'differs'} "
            f"(max {self.path_max_error_m:.3e} m)",
            f"  range scans (not part of the verdict): "
            f"{'bitwise equal' if self.ranges_bitwise_equal else 'differ'} "
            f"(max {self.max_range_error_m:.3e} m)",
            f"  outcome: logged {self.outcome_logged}, re-simulated {self.outcome_simulated}",
        ]
        if self.first_difference_s is not None:
            lines.append(f"  first difference at t={self.first_difference_s:.3f} s")
        return lines

    def as_dict(self) -> dict:
        out = dict(self.__dict__)
        out["passed"] = self.passed
        return out


class TrajectoryCapture:
    """A Recorder that keeps the time and base pose of every step in memory."""

    def __init__(self) -> None:
        self.times_s: list[float] = []
        self.positions_m: list[np.ndarray] = []
        self.quaternions_wxyz: list[np.ndarray] = []
        self.ranges_m: list[np.ndarray] = []

    def start(self, context: RunContext) -> None:
        pass

    def path(self, time_s: float, waypoints_m: np.ndarray) -> None:
        pass

    def step(self, frame: StepFrame) -> None:
        self.times_s.append(frame.time_s)
        self.positions_m.append(np.array(frame.position_m, dtype=float))
        self.quaternions_wxyz.append(np.array(frame.quaternion_wxyz, dtype=float))
        self.ranges_m.append(np.array(frame.range_m, dtype=float))

    def event(self, time_s: float, kind: str, details: dict) -> None:
        pass

    def finish(self, summary: dict) -> None:
        pass

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(T,) times, (T, 3) positions, (T, 4) quaternions."""
        return (np.array(self.times_s, dtype=float),
                np.array(self.positions_m, dtype=float).reshape(-1, 3),
                np.array(self.quaternions_wxyz, dtype=float).reshape(-1, 4))


def verify_log(log: RunLog) -> VerifyReport:
    """Re-simulate a logged run from the log alone and compare poses step by step."""
    import mujoco

    from swarmnav.models.scenario import parse_scenario
    from swarmnav.sim.episode import EpisodeSpec, run_episode
    from swarmnav.sim.scene import index_scene

    context = context_from_log(log)
    scenario = parse_scenario(context.scenario_toml, f"{log.raw.path}[scenario]")
    spec = EpisodeSpec(scenario, context.planner_name, context.planner_params, context.navigator_name,
                       context.navigator_params, context.seed, context.world_seed)
    model = mujoco.MjModel.from_xml_string(context.mjcf_xml)
    # Reproduce how the logged run stopped: a timeout at T means the limit was T.
    kinds = [kind for _, kind, _ in log.events]
    options = {}
    if "timeout" in kinds and len(log.time_s):
        options["time_limit_s"] = float(log.time_s[-1])
    if "stopped_on_collision" in kinds:
        options["stop_on_collision"] = True
    capture = TrajectoryCapture()
    episode = run_episode(spec, [capture], scene=index_scene(model, context.mjcf_xml), **options)
    path, result = episode.path, episode.result
    sim_t, sim_p, sim_q = capture.arrays()

    n = min(len(sim_t), len(log.time_s))
    dp = np.linalg.norm(sim_p[:n] - log.position_m[:n], axis=1)
    # q and -q are the same rotation.
    dq = np.minimum(np.linalg.norm(sim_q[:n] - log.quaternion_wxyz[:n], axis=1),
                    np.linalg.norm(sim_q[:n] + log.quaternion_wxyz[:n], axis=1))
    same = (np.all(sim_p[:n] == log.position_m[:n], axis=1)
            & np.all(sim_q[:n] == log.quaternion_wxyz[:n], axis=1)
            & (np.round(sim_t[:n] * 1e9) == np.round(log.time_s[:n] * 1e9)))
    differing = np.flatnonzero(~same)
    logged_path = log.paths[0][1] if log.paths else np.zeros((0, 2))
    replanned = np.asarray(path.waypoints, dtype=float)[:, :2]
    path_equal = logged_path.shape == replanned.shape and np.array_equal(logged_path, replanned)
    path_error = (float(np.max(np.linalg.norm(logged_path - replanned, axis=1)))
                  if logged_path.shape == replanned.shape and len(replanned) else math.inf)
    # Ranges as the writer logged them (reading + rim offset, NaN for misses).
    offset_m = float(log.run_value("sensor_offset_m", 0.0))
    sim_r = np.array(capture.ranges_m, dtype=float).reshape(len(sim_t), -1)
    sim_r = np.where(np.isfinite(sim_r) & (sim_r >= 0.0), sim_r + offset_m, np.nan)
    m = min(len(sim_r), len(log.range_m))
    ranges_equal = (sim_r.shape == log.range_m.shape
                    and np.array_equal(sim_r, log.range_m, equal_nan=True))
    range_diff = np.abs(sim_r[:m] - log.range_m[:m])
    both_nan = np.isnan(sim_r[:m]) & np.isnan(log.range_m[:m])
    range_diff = np.where(both_nan, 0.0, np.where(np.isnan(range_diff), np.inf, range_diff))
    worst = int(np.argmax(dp)) if n and dp.max() > 0 else None
    from swarmnav.sim.log_reader import outcome_text
    return VerifyReport(
        logged_steps=len(log.time_s), simulated_steps=len(sim_t), compared_steps=n,
        max_position_error_m=float(dp.max()) if n else 0.0,
        max_quaternion_error=float(dq.max()) if n else 0.0,
        worst_time_s=float(log.time_s[worst]) if worst is not None else None,
        first_difference_s=float(log.time_s[differing[0]]) if len(differing) else None,
        bitwise_equal=len(differing) == 0 and len(sim_t) == len(log.time_s),
        path_bitwise_equal=bool(path_equal), path_max_error_m=path_error,
        ranges_bitwise_equal=bool(ranges_equal), max_range_error_m=float(range_diff.max()) if m else 0.0,
        outcome_logged=outcome_text(log), outcome_simulated=result.outcome,
    )


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("log", help="an .mcap run log")
    parser.add_argument("--video", metavar="OUT.mp4", help="render the run to an MP4 (offscreen EGL)")
    parser.add_argument("--camera", choices=("top", "chase"), default="top")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--fps", type=float, default=DEFAULT_FPS, help="frames per simulated second")
    parser.add_argument("--no-trail", action="store_true", help="do not draw the driven trajectory")
    parser.add_argument("--verify", action="store_true",
                        help="re-simulate from the log and compare every pose (exit 1 if they differ)")
    parser.add_argument("--json", action="store_true", help="print the results as JSON")


def run(args: argparse.Namespace) -> int:
    """Exit 0 on success, 1 when --verify finds a difference, 2 on bad input."""
    if not args.video and not args.verify:
        raise ConfigError("replay", "nothing to do: give --video OUT.mp4 and/or --verify")
    if args.video:
        from swarmnav.sim.render import check_video_size
        check_video_size(args.width, args.height, args.fps)
    log = read_log(args.log)
    results: dict = {"log": str(args.log)}
    status = 0
    if args.video:
        info = render_log(log, args.video, camera=args.camera, width=args.width, height=args.height,
                          fps=args.fps, trail=not args.no_trail)
        results["video"] = {"path": str(args.video), **info}
        if not args.json:
            print(f"video: {args.video}: {info['frames']} frames, {info['video_s']:.1f} s at {args.fps:g} fps "
                  f"({info['frames'] / max(info['render_s'], 1e-9):.0f} frames/s rendered)")
    if args.verify:
        report = verify_log(log)
        results["verify"] = report.as_dict()
        if not args.json:
            print("\n".join(report.lines()))
        status = 0 if report.passed else 1
    if args.json:
        print(json.dumps(results, sort_keys=True, default=str))
    sys.stdout.flush()
    return status
