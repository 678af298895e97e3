"""The two sensing models of moving obstacles, as plain data for the navigator.

Chosen per scenario by ``sensors.model``:

* ``rangefinder`` (default): the MuJoCo rangefinder rays.  A hit that lies on
  known static geometry (a static cylinder, a map box, an arena wall: the map
  the robot is given in advance) within ``STATIC_HIT_TOLERANCE_M`` is dropped;
  the rest are points of unknown obstacles, which a
  :class:`~controllers.tracking.HitTracker` turns into discs with velocities.
  Only what the rays saw.
* ``detector``: an idealised obstacle detector (the sensor Gong et al. (2022) assumes:
  "direction, step length, size and shape").  Computed here from the true state:
  each moving obstacle's centre, radius and velocity (finite difference over
  one control step of its scripted motion), reported once its surface is within
  ``sensors.range_m`` of the robot's rim.  Nothing beyond the range.

Both give :class:`~controllers.navigator.DetectedObstacle` tuples; the log and
``run --json`` name the model through the scenario.
"""

from __future__ import annotations

import numpy as np

from swarmnav.controllers.navigator import DetectedObstacle
from swarmnav.controllers.tracking import HitTracker
from swarmnav.models.scenario import Scenario
from swarmnav.models.world import Pose2D

STATIC_HIT_TOLERANCE_M = 0.02  # a hit this close to a known surface is the map's, not an unknown obstacle's


def hit_points(pose: Pose2D, ranges_m: np.ndarray, angles_rad: np.ndarray, offset_m: float
               ) -> tuple[np.ndarray, np.ndarray]:
    """World positions of the finite rangefinder hits (N, 2) and of the sensors that made them (N, 2)."""
    hit = np.isfinite(ranges_m)
    world = pose.heading_rad + np.asarray(angles_rad)[hit]
    direction = np.column_stack([np.cos(world), np.sin(world)])
    origins = np.array([pose.x_m, pose.y_m]) + offset_m * direction
    return origins + np.asarray(ranges_m)[hit][:, None] * direction, origins


def static_surfaces(scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """The known map's static discs (D, 3) as (x, y, radius) and boxes (B, 4), in metres."""
    discs = np.array([(ob.x_m, ob.y_m, ob.radius_m) for ob in scenario.obstacles if not ob.moving],
                     dtype=float).reshape(-1, 3)
    boxes = np.array([[bx.x_min_m, bx.y_min_m, bx.x_max_m, bx.y_max_m] for bx in scenario.boxes],
                     dtype=float).reshape(-1, 4)
    return discs, boxes


def known_surface_gap_m(points_m: np.ndarray, scenario: Scenario,
                        surfaces: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """(N,) distance from each point to the nearest known static surface (inf with none);
    ``surfaces``: :func:`static_surfaces` of the scenario, built once by a caller that asks every step."""
    pts = np.asarray(points_m, dtype=float).reshape(-1, 2)
    gap = np.full(len(pts), np.inf)
    d, b = static_surfaces(scenario) if surfaces is None else surfaces
    if len(d):
        gap = np.minimum(gap, np.min(np.abs(np.hypot(pts[:, None, 0] - d[:, 0], pts[:, None, 1] - d[:, 1])
                                            - d[:, 2]), axis=1))
    if len(b):
        dx = np.maximum(np.maximum(b[:, 0] - pts[:, None, 0], pts[:, None, 0] - b[:, 2]), 0.0)
        dy = np.maximum(np.maximum(b[:, 1] - pts[:, None, 1], pts[:, None, 1] - b[:, 3]), 0.0)
        gap = np.minimum(gap, np.min(np.hypot(dx, dy), axis=1))
    if scenario.walls:
        w, h = scenario.arena_width_m, scenario.arena_height_m
        walls = np.column_stack([pts[:, 0], w - pts[:, 0], pts[:, 1], h - pts[:, 1]])
        gap = np.minimum(gap, np.abs(walls).min(axis=1))
    return gap


class ObstacleSensing:
    """One run's sensing of moving obstacles: ``sense(step, pose, ranges) -> detections``.

    Args:
        scenario: gives the model, the range, the robot radius and the known map.
        track_m: (T, M, 2) positions of the moving obstacles at every control step (the runner's).
        radii_m: (M,) their radii.
        dt_s: the control period.
        angles_rad, offset_m: the rangefinders' beam directions and distance from the base centre.
    """

    def __init__(self, scenario: Scenario, track_m: np.ndarray, radii_m: np.ndarray, dt_s: float,
                 angles_rad: np.ndarray, offset_m: float):
        self.model = scenario.sensor_model
        self.range_m = scenario.sensor_range_m
        self.robot_radius_m = scenario.robot_radius_m
        self.scenario = scenario
        self.track_m = track_m
        self.radii_m = np.asarray(radii_m, dtype=float)
        self.dt_s = dt_s
        self.angles_rad = angles_rad
        self.offset_m = offset_m
        self.tracker = HitTracker()
        self.tracker.reach_m = scenario.sensor_range_m
        self.surfaces = static_surfaces(scenario)  # the known map, once (asked about every step)
        # Velocities by forward difference of the scripted track (backward at the last step).
        if track_m.shape[1] and len(track_m) > 1:
            diff = np.diff(track_m, axis=0) / dt_s
            self.velocity_m_s = np.concatenate([diff, diff[-1:]], axis=0)
        else:
            self.velocity_m_s = np.zeros_like(track_m)

    def sense(self, step: int, time_s: float, pose: Pose2D, ranges_m: np.ndarray) -> tuple[DetectedObstacle, ...]:
        if self.model == "detector":
            return self.detect(step, pose)
        # Every beam's direction and origin once; the hits are those of the finite ranges
        # (the same element-wise arithmetic as hit_points).
        ranges = np.asarray(ranges_m, dtype=float)
        world = pose.heading_rad + np.asarray(self.angles_rad)
        directions = np.column_stack([np.cos(world), np.sin(world)])
        beam_origins = np.array([pose.x_m, pose.y_m]) + self.offset_m * directions
        hit = np.isfinite(ranges)
        origins = beam_origins[hit]
        hits = origins + ranges[hit][:, None] * directions[hit]
        unknown = known_surface_gap_m(hits, self.scenario, self.surfaces) > STATIC_HIT_TOLERANCE_M \
            if len(hits) else np.zeros(0, dtype=bool)
        return self.tracker.update(time_s, hits[unknown], origins[unknown], (beam_origins, directions, ranges))

    def detect(self, step: int, pose: Pose2D) -> tuple[DetectedObstacle, ...]:
        """The ``detector`` model: the true moving obstacles whose surface is within range of the rim."""
        if not self.track_m.shape[1]:
            return ()
        centres = self.track_m[step]
        gap = np.hypot(centres[:, 0] - pose.x_m, centres[:, 1] - pose.y_m) - self.radii_m - self.robot_radius_m
        seen = np.flatnonzero(gap <= self.range_m)
        if not len(seen):
            return ()
        # One conversion to Python floats for all of them (the values float() gives one by one).
        xy, radii, velocity = centres[seen].tolist(), self.radii_m[seen].tolist(), self.velocity_m_s[step, seen].tolist()
        return tuple(DetectedObstacle(x, y, r, vx, vy, i)
                     for (x, y), r, (vx, vy), i in zip(xy, radii, velocity, seen.tolist()))

