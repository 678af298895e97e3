"""The global path as guidance for local navigators: a carrot point a lookahead ahead (no MuJoCo).

``dwa`` and ``velocity_obstacle`` do not follow the path exactly: they steer
toward a point ``lookahead_m`` further along it than the robot's projection,
and nearer obstacles bend their choice.  Progress along the path only moves
forward (the projection is searched from the last one onward), so a detour
does not send the carrot back.
"""

from __future__ import annotations

import bisect
import math

import numpy as np

from swarmnav.controllers.navigator import NavigationSetup
from swarmnav.controllers.prediction import LocalObstacles
from swarmnav.models.geometry import segment_box_distances, segment_disc_distances
from swarmnav.models.world import Pose2D

SIGHT_SLACK_M = 1e-6  # PathCarrot._visible: discs this much beyond a segment's reach are still measured
SIGHT_SHRINK_M = 1e-6  # PathCarrot.sight_shrink: the lowered radius is this much below the robot's clearance


def local_setup(setup: NavigationSetup, margin_m: float, lookahead_m: float, carrot_in_sight: bool = False,
                centred=None, radius_m: float | None = None, speed_cap_m_s: float = 0.0):
    """What the local navigators (``dwa``, ``velocity_obstacle``, ``mppi``) build alike at reset, from a
    :class:`~controllers.navigator.NavigationSetup`: (drive geometry, top speed in m/s, the radius kept from
    obstacle centres beyond theirs (``radius_m``, default the robot radius, + ``margin_m``), the known static
    obstacles, the path's carrot, the goal as an (x, y) array).  ``carrot_in_sight``: the carrot is kept
    where the robot can drive to it straight past the known map (:class:`PathCarrot`).  ``centred`` (their
    ``footprint = "box"``, :func:`controllers.guided.box_guidance`): with the map unknown the guidance path is
    that :class:`~controllers.centred_path.CentredPlanner`'s (:class:`~controllers.guided.GuidedCarrot`), and
    the sight test is for a disc of its ``block_m``.
    ``speed_cap_m_s`` > 0: the top speed returned is at most that (their ``speed_cap_m_s`` option)."""
    known = setup.map_problem
    geometry = setup.controller.geometry
    radius_m = known.robot_radius_m if radius_m is None else radius_m
    if setup.world_map is None:
        carrot = PathCarrot(setup.path.waypoints, lookahead_m)
        local = LocalObstacles(known.disc_centres_m, known.disc_radii_m, known.box_array_m)
    else:  # the map unknown: the sensed map's obstacles, and the path replanned on it (controllers.guided)
        carrot, local = setup.world_map.local_guidance(setup, lookahead_m)
        if centred is not None:
            carrot.centred = centred  # GuidedCarrot plans its guidance with it from now on
    if carrot_in_sight:
        sight_m = known.robot_radius_m if centred is None else centred.block_m
        carrot.keep_in_sight(known.disc_centres_m, known.disc_radii_m, known.box_array_m, sight_m)
    top_m_s = min(setup.max_speed_m_s, speed_cap_m_s) if speed_cap_m_s > 0 else setup.max_speed_m_s
    return (geometry, top_m_s, radius_m + margin_m, local,
            carrot, np.array([setup.goal.x_m, setup.goal.y_m]))


class PathCarrot:
    """Projects the robot on a polyline and returns the point ``lookahead_m`` ahead of it.

    The polyline is kept as plain Python lists: the window searched each step holds
    a handful of segments, for which a loop costs a few microseconds where NumPy's
    per-call overhead cost a hundred or more.
    """

    # Whether the sight test's radius is lowered to the robot's clearance now while the robot stands within it
    # of a disc (:meth:`_first_visible`; set by ``dwa``'s ``sight_inside = "shrink"``; a class default, so that
    # a replanned path (:meth:`~controllers.guided.GuidedCarrot._restart`) keeps the instance's choice).
    sight_shrink: bool = False

    def __init__(self, waypoints: np.ndarray, lookahead_m: float):
        pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
        if len(pts) == 1:
            pts = np.vstack([pts, pts])
        self.points = pts.tolist()
        self.seg = np.diff(pts, axis=0).tolist()
        self.seg_len = [math.hypot(dx, dy) for dx, dy in self.seg]
        self.cum = [0.0]
        for length in self.seg_len:
            self.cum.append(self.cum[-1] + length)
        self.lookahead_m = lookahead_m
        self.progress_m = 0.0
        self.sight: tuple[np.ndarray, np.ndarray, np.ndarray, float] | None = None

    def keep_in_sight(self, disc_centres_m: np.ndarray, disc_radii_m: np.ndarray, boxes_m: np.ndarray,
                      radius_m: float, samples: int = 8) -> None:
        """From now on the carrot is the farthest of ``samples`` points between the robot's projection and
        the lookahead point that the robot (a disc of ``radius_m``) can reach in a straight line past the
        given discs and boxes (the known map); with none, the projection itself.

        Why (ours, measured on dyn300's door scenes): a robot pushed off its path beside a wall by a moving
        obstacle had its carrot on the far side of the wall; ``velocity_obstacle`` and ``mppi``, pulled
        straight at it, stood still against the wall until the time limit (a local minimum).  A carrot the
        robot can see leads it back to the path, through the door.
        """
        centres = np.asarray(disc_centres_m, dtype=float).reshape(-1, 2)
        boxes = np.asarray(boxes_m, dtype=float).reshape(-1, 4)
        if len(centres) or len(boxes):
            self.sight = (centres, np.asarray(disc_radii_m, dtype=float).reshape(-1), boxes, float(radius_m))
            self.sight_samples = samples

    @property
    def length_m(self) -> float:
        return self.cum[-1]

    def _segment(self, s_m: float) -> int:
        """Index of the segment holding arc length ``s_m`` (clamped to the polyline)."""
        return min(max(bisect.bisect_right(self.cum, s_m) - 1, 0), len(self.seg) - 1)

    def point_at(self, s_m: float) -> np.ndarray:
        s = min(max(s_m, 0.0), self.length_m)
        i = self._segment(s)
        frac = (s - self.cum[i]) / self.seg_len[i] if self.seg_len[i] > 0 else 0.0
        (ax, ay), (dx, dy) = self.points[i], self.seg[i]
        return np.array([ax + frac * dx, ay + frac * dy])

    def update(self, pose: Pose2D, window_m: float = 2.0) -> np.ndarray:
        """Advance the progress to the robot's projection (within ``window_m`` ahead) and return the carrot."""
        lo = self._segment(self.progress_m)
        hi = max(min(bisect.bisect_right(self.cum, self.progress_m + window_m), len(self.seg)), lo + 1)
        px, py = pose.x_m, pose.y_m
        best_d2, best_s = math.inf, self.progress_m
        for i in range(lo, hi):
            (ax, ay), (dx, dy), length = self.points[i], self.seg[i], self.seg_len[i]
            t = ((px - ax) * dx + (py - ay) * dy) / max(length * length, 1e-12)
            t = min(max(t, 0.0), 1.0)
            ex, ey = ax + t * dx - px, ay + t * dy - py
            d2 = ex * ex + ey * ey
            if d2 < best_d2:  # the first nearest, as argmin
                best_d2, best_s = d2, self.cum[i] + t * length
        self.progress_m = max(self.progress_m, best_s)
        if self.sight is None:
            return self.point_at(self.progress_m + self.lookahead_m)
        ahead = np.array([self.point_at(s) for s in np.linspace(self.progress_m + self.lookahead_m, self.progress_m,
                                                                  self.sight_samples + 1)])
        first = self._first_visible(np.array([px, py]), ahead)
        return ahead[first] if first is not None else ahead[-1]

    def _first_visible(self, origin: np.ndarray, points: np.ndarray) -> int | None:
        """The first of ``points`` :meth:`_visible` finds visible (None: none is), the points tested one at a
        time in order, each against the discs within its own reach, up to the first visible one (usually the
        farthest).  Why (speed): :meth:`_visible` measured every point though only the first visible one is
        used; a segment's distances do not depend on the other segments measured with it."""
        centres, radii, boxes, radius = self.sight
        lengths = np.hypot(points[:, 0] - origin[0], points[:, 1] - origin[1])
        if len(centres):
            gap = np.hypot(centres[:, 0] - origin[0], centres[:, 1] - origin[1]) - radii
            if self.sight_shrink and len(gap):  # the robot stands within the radius of a disc: no nearer than now
                radius = max(0.0, min(radius, float(gap.min()) - SIGHT_SHRINK_M))
            near = np.flatnonzero(gap <= float(lengths.max()) + radius + SIGHT_SLACK_M)
            centres, radii, gap = centres[near], radii[near], gap[near]
        for k in range(len(points)):
            segment = (origin[None, :], points[k:k + 1])
            if len(centres):
                mine = gap <= float(lengths[k]) + radius + SIGHT_SLACK_M
                if mine.any() and not bool(np.all(segment_disc_distances(*segment, centres[mine])
                                                  >= radii[mine][None, :] + radius)):
                    continue
            if len(boxes) and not bool(np.all(segment_box_distances(*segment, boxes) >= radius)):
                continue
            return k
        return None

    def _visible(self, origin: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(P,) whether a disc of the sight radius drives straight from ``origin`` to each point untouched."""
        centres, radii, boxes, radius = self.sight
        starts = np.repeat(origin[None, :], len(points), axis=0)
        ok = np.ones(len(points), dtype=bool)
        if len(centres):
            # Only the discs that could be within the radius of a segment: one farther from the origin than the
            # longest segment plus both radii (and SIGHT_SLACK_M) passes every test (a segment's distance is at
            # least that from its start less its length).  Why (speed): on a sensed map every cell was measured
            # against every segment, ~10 % of a BARN run's CPU; the answer is the same.
            longest_m = float(np.hypot(points[:, 0] - origin[0], points[:, 1] - origin[1]).max())
            near = np.hypot(centres[:, 0] - origin[0], centres[:, 1] - origin[1]) - radii \
                <= longest_m + radius + SIGHT_SLACK_M
            if near.any():
                ok &= np.all(segment_disc_distances(starts, points, centres[near]) >= radii[near][None, :] + radius,
                             axis=1)
        if len(boxes):
            ok &= np.all(segment_box_distances(starts, points, boxes) >= radius, axis=1)
        return ok

    def remaining_m(self, pose: Pose2D) -> float:
        """Straight distance from the robot to the path's end."""
        end = self.points[-1]
        return math.hypot(end[0] - pose.x_m, end[1] - pose.y_m)
