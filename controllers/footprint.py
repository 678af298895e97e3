"""A box chassis on a grid navigator's disc world (``dstar_replan``'s ``footprint = "box"``, ``cost_weight``,
``max_decel_m_s2``): what BARN's Jackal (a 0.508 x 0.430 m box, 2 m/s) needs where planning for its
circumscribed circle (0.333 m) closes BARN's 0.75 m passages.  Ours, after the costmap treatment of ROS'
navigation stacks (Nav2's inflation layer: lethal within the inscribed radius, a cost decaying beyond it):

* :func:`block_radius_m`: cells are blocked by the robot's inscribed circle (what the box surely covers);
* :func:`cell_penalty`: a penalty on free cells near blocked ones, so the planner keeps to the middle of a
  passage, where the box can also turn on the spot; :func:`no_costlier` keeps a shortcut of the cell path
  from running nearer the obstacles than the cells it replaces;
* :func:`braked`: the forward speed capped so that the robot can stop before the next sharp turn of its path
  and before the nearest mapped obstacle in the corridor its chassis sweeps straight ahead
  (:func:`free_ahead_m`), v <= sqrt(2 a d).

No MuJoCo here: plain arrays and the navigator's setup in, numbers out.
"""

from __future__ import annotations

import math

import numpy as np

from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.kinematics import wheel_speeds
from swarmnav.models.robots import robot_model


def chassis_extent_m(setup) -> tuple[float, float]:
    """(front, half width) of the chassis from the base origin: the box footprint's, else the robot radius."""
    radius = setup.problem.robot_radius_m
    if setup.scenario is None or robot_model(setup.scenario.robot_model).round_chassis:
        return radius, radius
    _, y0, x1, y1 = robot_model(setup.scenario.robot_model).footprint_m
    return x1, max(-y0, y1)


def block_radius_m(setup) -> float:
    """The radius cells are blocked by: the robot's inscribed circle (what its box chassis surely covers,
    :attr:`models.robots.RobotModel.inscribed_radius_m`), at most the robot radius; a round chassis (or no
    scenario) keeps the robot radius."""
    radius = setup.problem.robot_radius_m
    if setup.scenario is None:
        return radius
    model = robot_model(setup.scenario.robot_model)
    return radius if model.round_chassis else min(radius, model.inscribed_radius_m)


def cell_penalty(occupied: np.ndarray, cell_m: float, weight: float, reach_m: float) -> np.ndarray | None:
    """Each cell's penalty: ``weight`` x (1 - d / ``reach_m``)^2 within ``reach_m`` of a blocked cell (d from
    its centre to the nearest blocked cell's centre), else 0; None when ``weight`` is 0.  Rounded to 1e-3 so
    that a map change reaches only the cells whose penalty it changes."""
    if weight <= 0:
        return None
    if not occupied.any():
        return np.zeros(occupied.shape)
    from scipy.ndimage import distance_transform_edt
    d = distance_transform_edt(~occupied) * cell_m
    return np.round(weight * np.clip(1.0 - d / reach_m, 0.0, 1.0) ** 2, 3)


def no_costlier(penalty: np.ndarray | None, grid, a_m: np.ndarray, b_m: np.ndarray, cells) -> bool:
    """Whether the segment a -> b (sampled every half cell) meets no higher penalty than the highest of the
    cells it replaces (always with no penalty)."""
    if penalty is None:
        return True
    n = max(2, int(math.ceil(2.0 * float(np.hypot(*(b_m - a_m))) / grid.cell_m)) + 1)
    pts = a_m + np.linspace(0.0, 1.0, n)[:, None] * (b_m - a_m)
    rows = np.clip(((pts[:, 1] - grid.origin_m[1]) / grid.cell_m).astype(int), 0, penalty.shape[0] - 1)
    cols = np.clip(((pts[:, 0] - grid.origin_m[0]) / grid.cell_m).astype(int), 0, penalty.shape[1] - 1)
    along = penalty[tuple(np.array(cells).T)]
    return float(penalty[rows, cols].max()) <= float(along.max()) + 1e-9


def free_ahead_m(problem, pose, front_m: float, half_width_m: float) -> float:
    """How far the chassis (its front ``front_m`` ahead of the base, ``half_width_m`` to each side) can drive
    straight ahead before it meets a disc or box of ``problem`` (a box by its circumscribed disc)."""
    boxes = problem.box_array_m
    centres = np.vstack([problem.disc_centres_m.reshape(-1, 2), 0.5 * (boxes[:, :2] + boxes[:, 2:])])
    radii = np.concatenate([problem.disc_radii_m, 0.5 * np.hypot(boxes[:, 2] - boxes[:, 0], boxes[:, 3] - boxes[:, 1])])
    if not len(centres):
        return math.inf
    c, s = math.cos(pose.heading_rad), math.sin(pose.heading_rad)
    dx, dy = centres[:, 0] - pose.x_m, centres[:, 1] - pose.y_m
    lon, lat = dx * c + dy * s, -dx * s + dy * c
    ahead = (lon > 0) & (np.abs(lat) < half_width_m + radii)
    if not ahead.any():
        return math.inf
    return max(0.0, float(np.min(lon[ahead] - radii[ahead])) - front_m)


def braked(command: ControlCommand, pose, controller, waypoints: list[tuple[float, float]], decel_m_s2: float,
           ahead_m: float) -> ControlCommand:
    """``command`` with its forward speed capped to sqrt(2 ``decel_m_s2`` d), d the nearer of ``ahead_m`` and
    the distance to the active waypoint when the path turns there by at least the controller's turn-in-place
    angle (it stops to turn); the turn rate is kept.  Unchanged for a controller without a drive geometry."""
    geometry = getattr(controller, "geometry", None)
    i = command.waypoint_index
    if geometry is None or command.linear_m_s <= 0:
        return command
    stop_m = ahead_m
    if 0 < i < len(waypoints) - 1:
        (x0, y0), (x1, y1) = waypoints[i], waypoints[i + 1]
        turn = abs(math.remainder(math.atan2(y1 - y0, x1 - x0) - math.atan2(y0 - pose.y_m, x0 - pose.x_m), math.tau))
        if turn >= getattr(controller, "turn_in_place_rad", 0.0):
            stop_m = min(stop_m, math.hypot(x0 - pose.x_m, y0 - pose.y_m))
    cap = math.sqrt(2.0 * decel_m_s2 * stop_m)
    if command.linear_m_s <= cap:
        return command
    return ControlCommand(wheel_speeds(cap, command.angular_rad_s, geometry), cap, command.angular_rad_s, i)


def box_hits(problem, pose, headings_rad: np.ndarray, box_m: tuple[float, float, float, float],
             margin_m: float = 0.0) -> np.ndarray:
    """(H,) whether the chassis box ``box_m`` (x_min, y_min, x_max, y_max in the base frame) at the robot's
    position and each heading comes within ``margin_m`` of a disc of ``problem`` (its boxes by their
    circumscribed discs)."""
    boxes = problem.box_array_m
    centres = np.vstack([problem.disc_centres_m.reshape(-1, 2), 0.5 * (boxes[:, :2] + boxes[:, 2:])])
    radii = np.concatenate([problem.disc_radii_m, 0.5 * np.hypot(boxes[:, 2] - boxes[:, 0], boxes[:, 3] - boxes[:, 1])])
    x0, y0, x1, y1 = box_m
    reach = math.hypot(max(-x0, x1), max(-y0, y1))
    dx, dy = centres[:, 0] - pose.x_m, centres[:, 1] - pose.y_m
    near = np.hypot(dx, dy) < reach + radii + margin_m
    if not near.any():
        return np.zeros(len(headings_rad), dtype=bool)
    dx, dy, r = dx[near], dy[near], radii[near]
    c, s = np.cos(headings_rad)[:, None], np.sin(headings_rad)[:, None]
    lon, lat = dx * c + dy * s, -dx * s + dy * c  # (H, N) in each heading's base frame
    gap = np.hypot(np.maximum(np.maximum(x0 - lon, lon - x1), 0.0), np.maximum(np.maximum(y0 - lat, lat - y1), 0.0))
    return np.any(gap < r + margin_m, axis=1)


def turn_blocked(problem, pose, sign: float, box_m, sweep_rad: float = 0.35, step_rad: float = 0.05) -> bool:
    """Whether turning on the spot by ``sweep_rad`` in the direction ``sign`` (+1 counter-clockwise) brings the
    chassis box onto an obstacle of ``problem`` (headings sampled every ``step_rad``)."""
    headings = pose.heading_rad + sign * np.arange(1, int(math.ceil(sweep_rad / step_rad)) + 1) * step_rad
    return bool(box_hits(problem, pose, headings, box_m).any())


def chassis_box_m(setup) -> tuple[float, float, float, float] | None:
    """The chassis' box footprint (x_min, y_min, x_max, y_max, base frame), None for a round chassis."""
    if setup.scenario is None or robot_model(setup.scenario.robot_model).round_chassis:
        return None
    return robot_model(setup.scenario.robot_model).footprint_m


def guarded_turn(command: ControlCommand, pose, controller, problem, box_m, latched: float,
                 back_m_s: float = 0.2) -> tuple[ControlCommand, float]:
    """A turn on the spot (no forward speed) checked against the chassis box: (the command, the turn
    direction to keep).  The command's way (or the ``latched`` one) if it does not bring the box onto an
    obstacle (:func:`turn_blocked`); else backing straight off at ``back_m_s`` when the corridor behind is free
    for 5 cm (a corner that would hit turns clear once the robot has moved away); else the other way round
    if that is clear (kept until the controller drives forward again); else the command as it is."""
    geometry = getattr(controller, "geometry", None)
    if geometry is None or box_m is None or command.linear_m_s > 1e-9 or command.angular_rad_s == 0.0:
        return command, 0.0
    sign = latched or math.copysign(1.0, command.angular_rad_s)
    i = command.waypoint_index
    if turn_blocked(problem, pose, sign, box_m):
        x0, y0, _, y1 = box_m
        behind = type(pose)(pose.x_m, pose.y_m, pose.heading_rad + math.pi)
        if free_ahead_m(problem, behind, -x0, max(-y0, y1)) > 0.05:
            return ControlCommand(wheel_speeds(-back_m_s, 0.0, geometry), -back_m_s, 0.0, i), latched
        if turn_blocked(problem, pose, -sign, box_m):
            return command, latched
        sign = -sign
    elif not latched:
        return command, 0.0
    omega = sign * abs(command.angular_rad_s)
    return ControlCommand(wheel_speeds(0.0, omega, geometry), 0.0, omega, i), sign


def covering_discs(setup) -> tuple[np.ndarray, float]:
    """((n, 2) disc centres in the base frame, their radius): discs along the chassis box's long axis that
    together cover it (n = ceil(half length / half width), each the circle about its 1/n of the box), the
    collision model of the local navigators' ``footprint = "box"`` (two discs of 0.25 m for the Jackal's
    0.508 x 0.430 m box, where its circumscribed circle is 0.333 m); one disc of the robot radius at the
    origin for a round chassis (or no scenario)."""
    box = chassis_box_m(setup)
    if box is None:
        return np.zeros((1, 2)), float(setup.problem.robot_radius_m)
    x0, y0, x1, y1 = box
    half_x, half_y = 0.5 * (x1 - x0), 0.5 * (y1 - y0)
    long_half, short_half = max(half_x, half_y), min(half_x, half_y)
    n = max(1, int(math.ceil(long_half / short_half - 1e-9)))
    along = -long_half + (2.0 * np.arange(n) + 1.0) * long_half / n
    centre = np.array([0.5 * (x0 + x1), 0.5 * (y0 + y1)])
    offsets = np.column_stack([along, np.zeros(n)]) if half_x >= half_y else np.column_stack([np.zeros(n), along])
    return centre + offsets, float(math.hypot(long_half / n, short_half))
