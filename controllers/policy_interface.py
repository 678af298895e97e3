"""What a learned policy sees and what it answers: one convention for the environment and the ``policy`` navigator.

The environment (``swarmnav.env``) and the ``policy`` navigator both lay
out their observations with :func:`observation_layout` and fill them with
:class:`PolicyObserver`, and both turn actions into wheel commands with
:func:`action_command`, so a policy trained in the environment runs unchanged
through ``swarmnav run``.

Observation: a dict of float32 arrays, every entry bounded (the bounds are the
environment's specs, :class:`ObservationLayout`).  Values that physics or an
estimator can push past a bound are clipped to it; each entry says which.

* ``ranges`` (K,): rangefinder distances divided by their reach, in [0, 1];
  1 = nothing in range.  Beam k points at 2 pi k / K rad from the heading,
  counter-clockwise (k = 0 straight ahead, k = K/4 to the left), from the rim of
  the robot (:meth:`ObservationLayout.range_angles_rad`; the environment's
  ``metadata["range_angles_rad"]``).  Present with both sensing models: the robot's rays are
  in the scene either way and are how it sees the static map.
* ``goal`` (2,): distance to the goal (m, in [0, D] with D the arena's diagonal;
  clipped there, which only matters off the arena of a scenario without walls)
  and its bearing in the robot frame (rad, in [-pi, pi], CCW from the heading).
* ``velocity`` (2,): the measured forward speed (m/s) and turn rate (rad/s),
  bounded by what the wheels' limit gives on flat ground: |v| <= r w_max and
  |omega| <= 2 r w_max / track (r the wheel radius, w_max the wheels' limit).
  Clipped there (a pushing obstacle or a skid can exceed them for a step).
* ``obstacles`` (N, 5) and ``obstacle_mask`` (N,): with the ``detector`` sensing
  model, and with ``rangefinder`` when the tracker's estimates are asked for
  (``tracked_obstacles``).  Row i: the sensed obstacle's centre in the robot
  frame (m; x forward, y left), its velocity in the world rotated into the
  robot's axes (m/s; the obstacle's own motion, not relative to the robot's),
  and its radius (m); rows sorted by surface gap to the robot, nearest first,
  ties by track id.  ``obstacle_mask`` is 1 for a row holding an obstacle and 0
  for padding (all-zero rows).  N defaults to the scenario's number of moving
  obstacles (at least 1): the ``detector`` reports only those, so none is ever
  dropped; with a smaller N the nearest N are kept.  Bounds: centre components
  within +-(sensor range + robot radius + largest moving radius), which holds
  every detection exactly; velocity components within +-(fastest moving
  obstacle's speed: ``speed_m_s``, or ``step_m / period_s`` for a random walk);
  radius within [0, largest moving radius].  The tracker's estimates are
  clipped to these bounds.
* ``path`` (P, 2), only when asked for: the next P waypoints of a planned path
  in the robot frame (m), components within +-D (clipped).  "Next" counts
  from the waypoint after the nearest one, never going back along the path;
  when fewer than P are left the last (the goal) repeats.

Flat order (:data:`FLAT_ORDER`, :func:`flatten_observation`): one vector, the
entries present in this order, each flattened row by row: ``ranges``, ``goal``,
``velocity``, ``path``, ``obstacles``, ``obstacle_mask``.  The environment's
``flatten=True`` and the ``policy`` navigator's ``flatten`` give it (not
Gymnasium's ``FlattenObservation``, which sorts the keys alphabetically).

Float32 because that is what learning libraries expect and store; the physics,
the poses, the wheel commands and the reward stay float64 (the reward's
distances are computed in float64, not read back from the float32 observation).

Action (2,), in one of two modes:

* ``"twist"`` (the default): a normalised (v, omega) in [-1, 1]^2, scaled by the
  robot's speed limit and by :func:`max_turn_rate_rad_s`, then turned into wheel
  speeds by the inverse kinematics with curvature-keeping saturation
  (:func:`kinematics.wheel_speeds`);
* ``"wheels"``: left and right wheel speeds in rad/s, clipped to the wheels' limit
  (not normalised: Gymnasium's checker warns about it, which is why it is not the default).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.kinematics import DriveGeometry, WheelSpeeds, body_twist, wheel_speeds
from swarmnav.controllers.navigator import DetectedObstacle, Observation
from swarmnav.models.scenario import Scenario
from swarmnav.models.world import wrap_angle_rad

ACTION_MODES = ("twist", "wheels")
OBSERVATION_DTYPE = np.float32
OBSTACLE_COLUMNS = ("x_m", "y_m", "vx_m_s", "vy_m_s", "radius_m")
FLAT_ORDER = ("ranges", "goal", "velocity", "path", "obstacles", "obstacle_mask")


def flatten_observation(observation: dict[str, np.ndarray]) -> np.ndarray:
    """The observation dict as one float32 vector in :data:`FLAT_ORDER` (see the module docstring)."""
    return np.concatenate([np.ravel(observation[key]) for key in FLAT_ORDER if key in observation]
                          ).astype(OBSERVATION_DTYPE, copy=False)


def max_turn_rate_rad_s(geometry: DriveGeometry, max_speed_m_s: float) -> float:
    """The turn rate that omega = 1 means: both wheels at the speed limit in opposite directions (2 v_max / track)."""
    return 2.0 * max_speed_m_s / geometry.track_m


def action_bounds(mode: str, geometry: DriveGeometry) -> tuple[float, float]:
    """(lower, upper) of each action component in ``mode``."""
    if mode == "twist":
        return -1.0, 1.0
    return -geometry.max_wheel_speed_rad_s, geometry.max_wheel_speed_rad_s


def action_command(action: np.ndarray, mode: str, geometry: DriveGeometry, max_speed_m_s: float,
                   waypoint_index: int = 0) -> ControlCommand:
    """A (2,) action in ``mode`` -> the wheel command (out-of-range values are clipped; taken in float64)."""
    a0, a1 = np.asarray(action, dtype=float).reshape(2).tolist()
    if mode == "twist":
        v = min(max(a0, -1.0), 1.0) * max_speed_m_s
        omega = min(max(a1, -1.0), 1.0) * max_turn_rate_rad_s(geometry, max_speed_m_s)
        return ControlCommand(wheel_speeds(v, omega, geometry), v, omega, waypoint_index)
    limit = geometry.max_wheel_speed_rad_s
    wheels = WheelSpeeds(min(max(a0, -limit), limit), min(max(a1, -limit), limit))
    v, omega = body_twist(wheels, geometry)
    return ControlCommand(wheels, v, omega, waypoint_index)


class ActionError(ValueError):
    """A policy's action that is not 2 finite real numbers (the environment raises it; the navigator reports it
    as a ConfigError of its ``policy`` parameter)."""


def checked_action(action) -> np.ndarray:
    """The action as a (2,) float64 array, or :class:`ActionError` saying what is wrong with it.

    Accepted: any array-like of shape (2,) (or (1, 2), one environment's row) of real numbers, floating or
    integer, all finite.  Rejected: other shapes, booleans, complex numbers, strings and objects, NaN and inf.
    """
    if type(action) is np.ndarray and action.shape == (2,) and action.dtype.kind == "f":  # the usual action, fast
        array = action.astype(np.float64)
        a0, a1 = array.tolist()
        if math.isfinite(a0) and math.isfinite(a1):
            return array
        raise ActionError(f"action {array.tolist()} is not finite")
    try:
        array = np.asarray(action)
    except Exception as exc:  # ragged lists and the like
        raise ActionError(f"action {action!r} is not an array: {exc}") from None
    if array.dtype == bool or not (np.issubdtype(array.dtype, np.floating) or np.issubdtype(array.dtype, np.integer)):
        raise ActionError(f"action of dtype {array.dtype}; expected real numbers (float32 as the action space)")
    if array.shape not in ((2,), (1, 2)):
        raise ActionError(f"action of shape {array.shape}; expected (2,)")
    array = array.reshape(2).astype(np.float64)
    if not np.all(np.isfinite(array)):
        raise ActionError(f"action {array.tolist()} is not finite")
    return array


def normalised_action(action: np.ndarray, mode: str, geometry: DriveGeometry) -> np.ndarray:
    """The action as the reward's effort and smoothness terms see it: each component clipped and scaled to [-1, 1]."""
    low, high = action_bounds(mode, geometry)
    return np.clip(np.asarray(action, dtype=np.float64), low, high) / high


def motion_speed_bound_m_s(motion) -> float:
    """The fastest a scripted obstacle motion moves (m/s): its speed, or a random walk's step per period."""
    if hasattr(motion, "speed_m_s"):
        return abs(float(motion.speed_m_s))
    return float(motion.step_m) / float(motion.period_s)


@dataclass(frozen=True)
class ObservationLayout:
    """Which entries the observation has, their sizes and their bounds (see the module docstring).

    Attributes:
        range_count: K, the rangefinders.
        path_waypoints: P (0: no ``path``).
        obstacle_slots: N (0: no ``obstacles`` / ``obstacle_mask``).
        goal_distance_max_m: D, the arena's diagonal (also bounds ``path``).
        speed_max_m_s, turn_rate_max_rad_s: the ``velocity`` bounds from the wheels' limit.
        obstacle_offset_max_m, obstacle_speed_max_m_s, obstacle_radius_max_m: the ``obstacles`` bounds.
    """

    range_count: int
    path_waypoints: int
    obstacle_slots: int
    goal_distance_max_m: float
    speed_max_m_s: float
    turn_rate_max_rad_s: float
    obstacle_offset_max_m: float = 0.0
    obstacle_speed_max_m_s: float = 0.0
    obstacle_radius_max_m: float = 0.0

    def range_angles_rad(self) -> np.ndarray:
        """(K,) the direction of each ``ranges`` beam, rad CCW from the heading: 2 pi k / K."""
        return 2.0 * math.pi * np.arange(self.range_count) / self.range_count

    def flat_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) of the flat observation, float32 (:func:`flatten_observation`'s order)."""
        parts = [(np.broadcast_to(low, shape), np.broadcast_to(high, shape)) for shape, low, high in self.bounds().values()]
        ordered = dict(zip(self.bounds(), parts))
        low = flatten_observation({key: value[0] for key, value in ordered.items()})
        high = flatten_observation({key: value[1] for key, value in ordered.items()})
        return low, high

    def bounds(self) -> dict[str, tuple[tuple[int, ...], np.ndarray, np.ndarray]]:
        """Per entry: (shape, lower, upper), the bounds broadcastable to the shape (float64)."""
        pi = math.pi
        out = {"ranges": ((self.range_count,), np.array(0.0), np.array(1.0)),
               "goal": ((2,), np.array([0.0, -pi]), np.array([self.goal_distance_max_m, pi])),
               "velocity": ((2,), -np.array([self.speed_max_m_s, self.turn_rate_max_rad_s]),
                            np.array([self.speed_max_m_s, self.turn_rate_max_rad_s]))}
        if self.path_waypoints:
            d = self.goal_distance_max_m
            out["path"] = ((self.path_waypoints, 2), np.array(-d), np.array(d))
        if self.obstacle_slots:
            p, v, r = self.obstacle_offset_max_m, self.obstacle_speed_max_m_s, self.obstacle_radius_max_m
            out["obstacles"] = ((self.obstacle_slots, len(OBSTACLE_COLUMNS)), np.array([-p, -p, -v, -v, 0.0]),
                                np.array([p, p, v, v, r]))
            out["obstacle_mask"] = ((self.obstacle_slots,), np.array(0.0), np.array(1.0))
        return out


def observation_layout(scenario: Scenario, geometry: DriveGeometry, path_waypoints: int = 0,
                       obstacle_slots: int | None = None, tracked_obstacles: bool = False) -> ObservationLayout:
    """The layout of a scenario's observations.

    Args:
        path_waypoints: P > 0 adds ``path``.
        obstacle_slots: N for ``obstacles`` (None: the scenario's moving obstacles, at least 1).
        tracked_obstacles: with the ``rangefinder`` model, also give the tracker's estimates as ``obstacles``
            (the ``detector`` model always gives them).
    """
    moving = [ob for ob in scenario.obstacles if ob.moving]
    wants_obstacles = scenario.sensor_model == "detector" or tracked_obstacles
    slots = 0
    if wants_obstacles:
        slots = max(1, len(moving)) if obstacle_slots is None else int(obstacle_slots)
    radius_max_m = max((ob.radius_m for ob in moving), default=0.0)
    top_speed_m_s = geometry.wheel_radius_m * geometry.max_wheel_speed_rad_s
    return ObservationLayout(
        range_count=scenario.sensor_count, path_waypoints=int(path_waypoints), obstacle_slots=slots,
        goal_distance_max_m=math.hypot(scenario.arena_width_m, scenario.arena_height_m),
        speed_max_m_s=top_speed_m_s, turn_rate_max_rad_s=2.0 * top_speed_m_s / geometry.track_m,
        obstacle_offset_max_m=scenario.sensor_range_m + scenario.robot_radius_m + radius_max_m,
        obstacle_speed_max_m_s=max((motion_speed_bound_m_s(ob.motion) for ob in moving), default=0.0),
        obstacle_radius_max_m=radius_max_m)


class PolicyObserver:
    """Turns an :class:`Observation` into the policy's observation dict (see the module docstring).

    Args:
        layout: the entries and bounds (:func:`observation_layout`).
        goal_xy_m: the goal position.
        path_m: (M, 2) waypoints of a planned path (needed when ``layout.path_waypoints`` > 0).
    """

    def __init__(self, layout: ObservationLayout, goal_xy_m: tuple[float, float], path_m: np.ndarray | None = None):
        self.layout = layout
        self.goal_xy_m = (float(goal_xy_m[0]), float(goal_xy_m[1]))
        if layout.path_waypoints and path_m is None:
            raise ValueError("the layout has a path entry but no path was given")
        self.path_m = None if not layout.path_waypoints else np.asarray(path_m, dtype=float).reshape(-1, 2)
        self._bounds = layout.bounds()
        self.cursor = 0  # index of the nearest waypoint so far (never decreases)

    def reset(self) -> None:
        self.cursor = 0

    def __call__(self, observation: Observation) -> dict[str, np.ndarray]:
        pose = observation.pose
        ranges = np.asarray(observation.ranges_m, dtype=float) / observation.range_cutoff_m
        x, y, heading = pose.x_m, pose.y_m, pose.heading_rad
        out = {"ranges": ranges,  # inf / cutoff = inf -> clipped to 1
               "goal": np.array(self.goal_in_robot_frame(x, y, heading)),
               "velocity": np.array([observation.twist.linear_m_s, observation.twist.angular_rad_s])}
        if self.path_m is not None:
            out["path"] = self.next_waypoints(x, y, heading)
        if self.layout.obstacle_slots:
            out["obstacles"], out["obstacle_mask"] = self.obstacle_rows(observation.detections, x, y, heading)
        bounds = self._bounds
        return {key: np.minimum(np.maximum(value, bounds[key][1]), bounds[key][2]).astype(OBSERVATION_DTYPE)
                for key, value in out.items()}

    def goal_distance_m(self, x_m: float, y_m: float) -> float:
        """The straight-line distance to the goal, in float64 and unclipped (the reward's)."""
        return math.hypot(self.goal_xy_m[0] - x_m, self.goal_xy_m[1] - y_m)

    def goal_in_robot_frame(self, x_m: float, y_m: float, heading_rad: float) -> tuple[float, float]:
        dx, dy = self.goal_xy_m[0] - x_m, self.goal_xy_m[1] - y_m
        return math.hypot(dx, dy), float(wrap_angle_rad(math.atan2(dy, dx) - heading_rad))

    def next_waypoints(self, x_m: float, y_m: float, heading_rad: float) -> np.ndarray:
        path = self.path_m
        ahead = path[self.cursor:]
        self.cursor += int(np.argmin(np.hypot(ahead[:, 0] - x_m, ahead[:, 1] - y_m)))
        index = np.minimum(np.arange(self.cursor + 1, self.cursor + 1 + self.layout.path_waypoints), len(path) - 1)
        return _to_robot_frame(path[index] - (x_m, y_m), heading_rad)

    def obstacle_rows(self, detections: tuple[DetectedObstacle, ...], x_m: float, y_m: float, heading_rad: float
                      ) -> tuple[np.ndarray, np.ndarray]:
        """(N, 5) rows [x, y, vx, vy, radius] in the robot frame, nearest first, zero-padded; (N,) mask."""
        slots = self.layout.obstacle_slots
        rows, mask = np.zeros((slots, len(OBSTACLE_COLUMNS))), np.zeros(slots)
        if not detections:
            return rows, mask
        d = np.array([(o.x_m, o.y_m, o.vx_m_s, o.vy_m_s, o.radius_m, o.track_id) for o in detections], dtype=float)
        gap = np.hypot(d[:, 0] - x_m, d[:, 1] - y_m) - d[:, 4]
        keep = np.lexsort((d[:, 5], gap))[:slots]
        n = len(keep)
        rows[:n, 0:2] = _to_robot_frame(d[keep, 0:2] - (x_m, y_m), heading_rad)
        rows[:n, 2:4] = _to_robot_frame(d[keep, 2:4], heading_rad)
        rows[:n, 4] = d[keep, 4]
        mask[:n] = 1.0
        return rows, mask


def _to_robot_frame(vectors: np.ndarray, heading_rad: float) -> np.ndarray:
    """(M, 2) world-frame vectors rotated into the robot's axes (x forward, y left)."""
    c, s = math.cos(heading_rad), math.sin(heading_rad)
    return np.stack([c * vectors[:, 0] + s * vectors[:, 1], -s * vectors[:, 0] + c * vectors[:, 1]], axis=1)
