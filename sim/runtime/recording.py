"""What the runner hands to a recorder (the MCAP log, a live view, a video).

The runner calls ``start`` once, ``step`` at every control step, ``event`` for
discrete happenings, ``path`` at the start and after any replan, and ``finish``
once (also after an exception, so what was written stays readable).  Every time
is simulation time in seconds from 0; no wall-clock time reaches a recorder.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np


@dataclass(frozen=True)
class ObstacleInfo:
    """One obstacle of the scene as the recorder sees it.

    Attributes:
        entity_id: stable id, e.g. ``"obstacle_3"`` (the MuJoCo geom name).
        shape: ``"cylinder"`` or ``"box"``.
        size_m: (radius, half-height) for cylinders, (half-x, half-y, half-z) for boxes.
        moving: True when the obstacle is a mocap body re-sent as it moves.
    """

    entity_id: str
    shape: str
    size_m: tuple[float, ...]
    position_m: tuple[float, float, float]
    moving: bool


@dataclass(frozen=True)
class RunContext:
    """Everything needed to describe, and re-simulate, a run."""

    scenario_name: str
    scenario_toml: str
    planner_name: str
    planner_params: dict[str, Any]
    seed: int
    mjcf_xml: str
    control_dt_s: float
    physics_dt_s: float
    sensor_angles_rad: np.ndarray  # (K,) beam directions in base_link, CCW from +x
    sensor_range_m: float
    sensor_offset_m: float  # distance of the rangefinder sites from base_link's origin (the rim)
    sensor_height_m: float  # height of the rangefinder sites above base_link's origin
    obstacles: tuple[ObstacleInfo, ...]
    versions: dict[str, str] = field(default_factory=dict)
    arena_size_m: tuple[float, float] = (10.0, 10.0)
    navigator_name: str = "follow"
    navigator_params: dict[str, Any] = field(default_factory=dict)
    world_seed: int = 0
    clearance_m: float | None = None  # the planning clearance the run used (None: the scenario file's)
    map_knowledge: str | None = None  # knowledge.map given over the file's (--map, a study axis); None: the file's
    pose_source: str | None = None  # knowledge.pose given over the file's (--pose, a study axis); None: the file's


@dataclass
class StepFrame:
    """State at one control step (arrays are fresh copies the recorder may keep).

    Attributes:
        time_s: simulation time.
        position_m: (3,) base position in the world.
        quaternion_wxyz: (4,) base orientation.
        heading_rad: yaw of the base.
        range_m: (K,) rangefinder distances; ``inf`` where nothing is in range.
        wheel_command_rad_s: (2,) commanded left, right wheel speeds.
        wheel_measured_rad_s: (2,) measured left, right wheel speeds.
        linear_m_s, angular_rad_s: the controller's (v, omega).
        waypoint_index: index of the active waypoint.
        moving_obstacles_m: (M, 2) positions of the moving obstacles, in ObstacleInfo order
            (only those with ``moving=True``).
        belief: what the navigator acted on (a :class:`~controllers.navigator.Belief`), or None.
        odometry: the pose the navigator saw (a :class:`~models.world.Pose2D`) with the odometry pose; else None.
    """

    time_s: float
    position_m: np.ndarray
    quaternion_wxyz: np.ndarray
    heading_rad: float
    range_m: np.ndarray
    wheel_command_rad_s: np.ndarray
    wheel_measured_rad_s: np.ndarray
    linear_m_s: float
    angular_rad_s: float
    waypoint_index: int
    moving_obstacles_m: np.ndarray
    belief: Any = None
    odometry: Any = None


class Recorder(Protocol):
    def start(self, context: RunContext) -> None: ...
    def path(self, time_s: float, waypoints_m: np.ndarray) -> None: ...
    def step(self, frame: StepFrame) -> None: ...
    def event(self, time_s: float, kind: str, details: dict[str, Any]) -> None: ...
    def finish(self, summary: dict[str, Any]) -> None: ...


class RecorderGroup:
    """Fans every call out to several recorders (log, video, live view), in order.

    ``finish`` reaches every recorder even when one of them raises.
    """

    def __init__(self, recorders: list[Recorder]):
        self.recorders = list(recorders)

    def start(self, context: RunContext) -> None:
        for r in self.recorders:
            r.start(context)

    def path(self, time_s: float, waypoints_m: np.ndarray) -> None:
        for r in self.recorders:
            r.path(time_s, waypoints_m)

    def step(self, frame: StepFrame) -> None:
        for r in self.recorders:
            r.step(frame)

    def event(self, time_s: float, kind: str, details: dict[str, Any]) -> None:
        for r in self.recorders:
            r.event(time_s, kind, details)

    def occupancy(self, time_s: float, grid: Any) -> None:
        """The sensed map (a :class:`models.occupancy.LogOddsGrid`) to the recorders that draw it (optional)."""
        for r in self.recorders:
            if hasattr(r, "occupancy"):
                r.occupancy(time_s, grid)

    def finish(self, summary: dict[str, Any]) -> None:
        error: BaseException | None = None
        for r in self.recorders:
            try:
                r.finish(summary)
            except BaseException as exc:  # keep closing the others
                error = error or exc
        if error is not None:
            raise error
