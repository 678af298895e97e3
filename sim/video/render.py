"""Offscreen rendering of a run with EGL, and MP4 output (:mod:`swarmnav.video.file`).

The GL context is made when a :class:`SceneRenderer` is, by :func:`sim.gl_backend.new_renderer`
(EGL unless the user chose another backend), so rendering works on headless,
GPU-less servers through Mesa and importing this module loads no GL library.

What a frame shows: the scene from the ``top`` camera (the whole arena), the
robot's ``chase`` camera, or ``follow`` (straight down on the robot, about
:data:`FOLLOW_VIEW_M` of its surroundings in view, so the robot stays a readable
size in any arena); obstacles in the shared palette (:mod:`sim.palette`); a
visual-only ground past the floor's edge (decor boxes, not in the model: no
black background in the chase view, and logs and physics are untouched); a title
bar and the simulation time (:mod:`swarmnav.video.caption`).

Speed: shadows, reflections and multisampling are switched off, which takes a
640x480 frame from ~267 ms to ~20 ms on the reference machine, and the floor is
drawn without its checker texture but with a metre grid of lines (a third less
per frame in Mesa's software renderer).  The planned path
and the range beams are drawn as extra geoms in the scene (``mjv_initGeom`` /
``mjv_connector``); the beams start at the rangefinder sites of the model and
point along their z axes, so they are exactly what MuJoCo measured.

:class:`VideoRecorder` is a :class:`sim.recording.Recorder`: ``swarmnav run
--video`` plugs it into the runner, and ``swarmnav replay --video`` feeds it the
frames of a log, so both give the same pictures.  It compiles its own model from
the MJCF of the run and only *poses* it (robot free joint, mocap obstacles); it
never steps physics.
"""

from __future__ import annotations

import math  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from swarmnav.models.errors import ConfigError  # noqa: E402
from swarmnav.sim import palette  # noqa: E402
from swarmnav.video.caption import FrameCaption, run_title  # noqa: E402
from swarmnav.video.look import (  # noqa: E402
    FOLLOW_VIEW_M,
    follow_camera,
    ground_boxes,
    paint_obstacles,
    soften_lights,
)
from swarmnav.sim.defaults import MAX_FPS, MIN_FPS  # noqa: E402
from swarmnav.sim.gl_backend import new_renderer  # noqa: E402
from swarmnav.sim.recording import RunContext, StepFrame  # noqa: E402
from swarmnav.video.file import VideoWriter  # noqa: E402

CAMERAS = ("top", "chase", "follow")
GROUND_RGBA = np.array([0.78, 0.79, 0.8, 1.0], dtype=np.float32)
PATH_RGBA = np.array(palette.rgba(palette.PLANNED), dtype=np.float32)
DRIVEN_RGBA = np.array(palette.rgba(palette.DRIVEN, 0.9), dtype=np.float32)
BEAM_HIT_RGBA = np.array(palette.rgba(palette.COLLISION), dtype=np.float32)
BEAM_MISS_RGBA = np.array([1.0, 0.75, 0.2, 0.35], dtype=np.float32)
# Lines (widths in pixels) cost ~30 us each to draw, capsules ~200 us: the path,
# the trail and the beams are lines, and the trail keeps a point per TRAIL_STEP_M.
PATH_WIDTH_PX = 4.0
TRAIL_WIDTH_PX = 2.5
BEAM_WIDTH_PX = 2.0
TRAIL_STEP_M = 0.05
GRID_STEP_M = 1.0
GRID_Z_M = 0.001
GRID_WIDTH_PX = 1.0
GRID_RGBA = np.array([0.55, 0.57, 0.6, 1.0], dtype=np.float32)
MAX_TRAIL_POINTS = 400


def expected_frames(duration_s: float, fps: float) -> int:
    """Frames of a video of a run lasting ``duration_s``: one at t = 0, k/fps, ... <= duration."""
    return int(math.floor(duration_s * fps + 1e-9)) + 1


def check_video_size(width: int, height: int, fps: float) -> None:
    """H.264 in yuv420p needs even sizes; reject silly values early.

    Raises:
        ConfigError: on odd, too small or too large sizes, or a frame rate outside MIN_FPS..MAX_FPS.
    """
    for name, value in (("width", width), ("height", height)):
        if value < 16 or value > 4096 or value % 2:
            raise ConfigError(f"--{name}", f"must be an even number of pixels in 16..4096, got {value}")
    if not MIN_FPS <= fps <= MAX_FPS:  # NaN fails too
        raise ConfigError("--fps", f"must be from {MIN_FPS:g} to {MAX_FPS:g} frames per simulated second, got {fps:g}")


class ScenePoser:
    """Sets a run's recorded state on a model compiled from the run's MJCF.

    Args:
        model: the compiled scene.
        moving_ids: geom names of the moving obstacles, in ``StepFrame`` order.
    """

    def __init__(self, model: mujoco.MjModel, moving_ids: tuple[str, ...] = ()):
        self.model = model
        self.data = mujoco.MjData(model)
        free = np.flatnonzero(model.jnt_type == mujoco.mjtJoint.mjJNT_FREE)
        if free.size == 0:
            raise ValueError("the scene has no free joint for the robot")
        self._qpos_address = int(model.jnt_qposadr[free[0]])
        self._mocap = []
        for name in moving_ids:
            geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
            body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name) if geom < 0 else model.geom_bodyid[geom]
            mocap = int(model.body_mocapid[body]) if body >= 0 else -1
            if mocap < 0:
                raise ValueError(f"moving obstacle {name!r} is not a mocap body of the scene")
            self._mocap.append(mocap)
        # Rangefinders in sensor order: their sites are the beam origins.
        ranges = np.flatnonzero(model.sensor_type == mujoco.mjtSensor.mjSENS_RANGEFINDER)
        self.beam_sites = model.sensor_objid[ranges].astype(int)
        self.beam_cutoff_m = model.sensor_cutoff[ranges].astype(float)
        mujoco.mj_forward(model, self.data)

    def apply(self, position_m: np.ndarray, quaternion_wxyz: np.ndarray, moving_xy_m: np.ndarray | None) -> None:
        """Pose robot and moving obstacles, then update positions (no dynamics)."""
        a = self._qpos_address
        self.data.qpos[a : a + 3] = position_m
        self.data.qpos[a + 3 : a + 7] = quaternion_wxyz
        if moving_xy_m is not None and self._mocap:
            for mocap, xy in zip(self._mocap, np.asarray(moving_xy_m, dtype=float).reshape(-1, 2)):
                self.data.mocap_pos[mocap, :2] = xy
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_comPos(self.model, self.data)
        mujoco.mj_camlight(self.model, self.data)

    def beams(self, range_m: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Beam segments (K, 3) start, (K, 3) end and hit flags from sensor readings.

        ``range_m`` are distances from each site, ``inf`` where nothing is in range (the
        runner's convention; a miss is drawn at the sensor's cutoff length).
        """
        starts = self.data.site_xpos[self.beam_sites].copy()
        axes = self.data.site_xmat[self.beam_sites].reshape(-1, 3, 3)[:, :, 2]
        if range_m is None:
            range_m = np.full(len(starts), np.inf)
        ranges = np.asarray(range_m, dtype=float)[: len(starts)]
        hit = np.isfinite(ranges)
        cutoff = np.where(self.beam_cutoff_m > 0, self.beam_cutoff_m, 0.4)
        length = np.where(hit, ranges, cutoff)
        return starts, starts + axes * length[:, None], hit


_ZERO3 = np.zeros(3)
_EYE9 = np.eye(3).ravel()


def _add_line(scene: mujoco.MjvScene, start: np.ndarray, end: np.ndarray, width_px: float, rgba: np.ndarray) -> bool:
    """Append one line segment to the user part of the scene (False when it is full)."""
    if scene.ngeom >= scene.maxgeom:
        return False
    geom = scene.geoms[scene.ngeom]
    mujoco.mjv_initGeom(geom, mujoco.mjtGeom.mjGEOM_LINE, _ZERO3, _ZERO3, _EYE9, rgba)
    mujoco.mjv_connector(geom, mujoco.mjtGeom.mjGEOM_LINE, width_px, start, end)
    geom.category = mujoco.mjtCatBit.mjCAT_DECOR
    scene.ngeom += 1
    return True


def _add_polyline(scene: mujoco.MjvScene, points_xy: np.ndarray, z_m: float, width_px: float, rgba: np.ndarray) -> None:
    points = np.column_stack([np.asarray(points_xy, dtype=float)[:, :2], np.full(len(points_xy), z_m)])
    for a, b in zip(points[:-1], points[1:]):
        if not _add_line(scene, a, b, width_px, rgba):
            return


def untexture(model: mujoco.MjModel) -> None:
    """Draw every material without its texture (the floor becomes plain).

    Sampling the floor's texture is about a third of a 640x480 frame in Mesa's
    software renderer (llvmpipe): 40 -> 27 ms per frame on the reference machine
    under load.  Under the scene's lights a plain floor is near white; the metre
    grid of :func:`floor_grid` keeps the sense of scale and motion the checker gave.
    """
    model.mat_texid[:] = -1


def floor_grid(width_m: float, height_m: float, step_m: float = GRID_STEP_M) -> np.ndarray:
    """(L, 2, 3) line segments of a grid over the arena, just above the floor."""
    xs = np.arange(0.0, width_m + 1e-9, step_m)
    ys = np.arange(0.0, height_m + 1e-9, step_m)
    vertical = [((x, 0.0, GRID_Z_M), (x, height_m, GRID_Z_M)) for x in xs]
    horizontal = [((0.0, y, GRID_Z_M), (width_m, y, GRID_Z_M)) for y in ys]
    return np.array(vertical + horizontal, dtype=float).reshape(-1, 2, 3)


def _add_boxes(scene: mujoco.MjvScene, boxes: np.ndarray, rgba: np.ndarray) -> None:
    for centre, half in boxes:
        if scene.ngeom >= scene.maxgeom:
            return
        geom = scene.geoms[scene.ngeom]
        mujoco.mjv_initGeom(geom, mujoco.mjtGeom.mjGEOM_BOX, half, centre, _EYE9, rgba)
        geom.category = mujoco.mjtCatBit.mjCAT_DECOR
        scene.ngeom += 1


class SceneRenderer:
    """Offscreen frames of a posed scene, with the planned path and beams drawn in.

    Args:
        model: the compiled scene (its offscreen buffer is enlarged if needed).
        width, height: image size in pixels.
        camera: a camera name of the scene (``top`` or ``chase``).
        fast: no shadows, reflections, skybox, multisampling or textures
            (see :func:`untexture`).
        grid_m: with ``fast``, the (width, height) of the arena: a metre grid of
            lines is drawn on the floor in place of its texture.
    """

    def __init__(self, model: mujoco.MjModel, width: int = 640, height: int = 480, camera: str = "top",
                 fast: bool = True, grid_m: tuple[float, float] | None = None):
        self._follow: mujoco.MjvCamera | None = None
        if camera == "follow":
            self._follow = follow_camera(model)
        elif mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera) < 0:
            names = [model.camera(i).name for i in range(model.ncam)] + ["follow"]
            raise ConfigError("--camera", f"no camera {camera!r} in the scene (has {names})")
        paint_obstacles(model)
        soften_lights(model)
        # Every camera can look past the floor's edge (the top camera's 4:3 frame is wider than a square
        # arena): the ground strips around the floor fill what would be black bands.
        self._ground = ground_boxes(model)
        model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
        model.vis.global_.offheight = max(model.vis.global_.offheight, height)
        self._grid = np.zeros((0, 2, 3))
        if fast:
            model.vis.quality.offsamples = 0  # no multisampling
            model.vis.quality.shadowsize = 0
            untexture(model)
            if grid_m is not None:
                self._grid = floor_grid(*grid_m)
        self.camera = camera
        self.width, self.height = width, height
        self._renderer = new_renderer(model, height, width)  # the GL context is made here, not at import
        if fast:
            flags = self._renderer.scene.flags
            flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0
            flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0
            flags[mujoco.mjtRndFlag.mjRND_SKYBOX] = 0
        self._option = mujoco.MjvOption()
        self._option.sitegroup[:] = 0  # no site spheres; beams are drawn instead
        self._option.geomgroup[:4] = 1  # the robot's chassis is a collision geom (group 3)

    def render(
        self,
        data: mujoco.MjData,
        path_m: np.ndarray | None = None,
        beams: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
        trail_m: np.ndarray | None = None,
        follow_xy_m: np.ndarray | None = None,
    ) -> np.ndarray:
        """One (height, width, 3) uint8 RGB frame; ``follow_xy_m`` centres the follow camera."""
        if self._follow is not None:
            if follow_xy_m is not None:
                self._follow.lookat[:2] = follow_xy_m[:2]
            camera = self._follow
        else:
            camera = self.camera
        self._renderer.update_scene(data, camera=camera, scene_option=self._option)
        scene = self._renderer.scene
        _add_boxes(scene, self._ground, GROUND_RGBA)
        for start, end in self._grid:
            _add_line(scene, start, end, GRID_WIDTH_PX, GRID_RGBA)
        if beams is not None:
            for start, end, hit in zip(*beams):
                _add_line(scene, start, end, BEAM_WIDTH_PX, BEAM_HIT_RGBA if hit else BEAM_MISS_RGBA)
        if path_m is not None and len(path_m) > 1:
            _add_polyline(scene, path_m, 0.01, PATH_WIDTH_PX, PATH_RGBA)
        if trail_m is not None and len(trail_m) > 1:
            _add_polyline(scene, trail_m, 0.012, TRAIL_WIDTH_PX, DRIVEN_RGBA)
        return self._renderer.render()

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


class VideoRecorder:
    """A Recorder that renders a run to MP4 at a fixed frame rate of simulated time.

    Frame k shows the first control step at or after ``k / fps`` seconds, so a run
    of duration T gives :func:`expected_frames` (T, fps) frames.

    Args:
        path: the MP4 to write.
        camera, width, height, fps: view and video settings (``follow``: a top view
            centred on the robot, :data:`FOLLOW_VIEW_M` high).
        trail: also draw the driven trajectory so far.
        caption: draw the title bar (scenario, planner + navigator, seeds) and the
            simulation time on every frame (:class:`swarmnav.video.caption.FrameCaption`).
    """

    def __init__(
        self,
        path: str | Path,
        *,
        camera: str = "top",
        width: int = 640,
        height: int = 480,
        fps: float = 30.0,
        trail: bool = True,
        caption: bool = True,
    ):
        check_video_size(width, height, fps)
        if camera not in CAMERAS:
            raise ConfigError("--camera", f"must be one of {CAMERAS}, got {camera!r}")
        self.video_path = Path(path)
        self.camera, self.width, self.height, self.fps = camera, width, height, float(fps)
        self.trail = trail
        self.caption = caption
        self._caption: FrameCaption | None = None
        self._next_frame = 0
        self._path_m: np.ndarray | None = None
        self._trail: list[np.ndarray] = []
        self._renderer: SceneRenderer | None = None
        self._video: VideoWriter | None = None
        self.render_seconds = 0.0

    @property
    def frames(self) -> int:
        return 0 if self._video is None else self._video.frames

    def start(self, context: RunContext) -> None:
        model = mujoco.MjModel.from_xml_string(context.mjcf_xml)
        moving = tuple(o.entity_id for o in context.obstacles if o.moving)
        self._poser = ScenePoser(model, moving)
        self._renderer = SceneRenderer(model, self.width, self.height, self.camera,
                                       grid_m=tuple(context.arena_size_m))
        if self.caption:
            self._caption = FrameCaption(run_title(context.scenario_name, context.planner_name,
                                                   context.navigator_name, context.seed, context.world_seed),
                                         self.width, self.height)
        self._video = VideoWriter(self.video_path, self.width, self.height, self.fps)

    def path(self, time_s: float, waypoints_m: np.ndarray) -> None:
        self._path_m = np.asarray(waypoints_m, dtype=float).copy()

    def step(self, frame: StepFrame) -> None:
        if self.trail:
            point = np.array(frame.position_m[:2], dtype=float)
            if not self._trail or np.hypot(*(point - self._trail[-1])) >= TRAIL_STEP_M:
                self._trail.append(point)
                if len(self._trail) > MAX_TRAIL_POINTS:
                    self._trail = self._trail[::2]
        if frame.time_s + 1e-9 < self._next_frame / self.fps:
            return
        started = time.perf_counter()
        self._poser.apply(frame.position_m, frame.quaternion_wxyz, frame.moving_obstacles_m)
        image = self._renderer.render(
            self._poser.data,
            path_m=self._path_m,
            beams=self._poser.beams(frame.range_m),
            trail_m=np.array(self._trail + [frame.position_m[:2]]) if self.trail and self._trail else None,
            follow_xy_m=frame.position_m,
        )
        if self._caption is not None:
            self._caption.draw(image, frame.time_s)
        self.render_seconds += time.perf_counter() - started
        while self._next_frame / self.fps <= frame.time_s + 1e-9:
            self._video.add(image)
            self._next_frame += 1

    def event(self, time_s: float, kind: str, details: dict[str, Any]) -> None:
        pass

    def finish(self, summary: dict[str, Any]) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        if self._video is not None:
            self._video.close()
