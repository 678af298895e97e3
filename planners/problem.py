"""The planning seam: what a planner is given and what it returns.

Nothing here knows MuJoCo or scenario files.  ``models.scenario`` builds a
:class:`Problem` from a scenario; ``sim`` executes a :class:`Path`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np

from planners.geometry import polyline_clearance_m, polyline_length_m, segment_box_distances


@dataclass(frozen=True)
class Pose2D:
    """A planar pose: position in metres, heading in radians (CCW from +x)."""

    x_m: float
    y_m: float
    heading_rad: float = 0.0

    @property
    def xy(self) -> np.ndarray:
        return np.array([self.x_m, self.y_m], dtype=float)


@dataclass(frozen=True)
class Disc:
    """A circular obstacle footprint (not inflated)."""

    x_m: float
    y_m: float
    radius_m: float


@dataclass(frozen=True)
class Box:
    """An axis-aligned rectangular obstacle footprint (not inflated)."""

    x_min_m: float
    y_min_m: float
    x_max_m: float
    y_max_m: float


@dataclass(frozen=True)
class Rect:
    """Axis-aligned bounds of the workspace, in metres."""

    x_min_m: float
    y_min_m: float
    x_max_m: float
    y_max_m: float

    @property
    def width_m(self) -> float:
        return self.x_max_m - self.x_min_m

    @property
    def height_m(self) -> float:
        return self.y_max_m - self.y_min_m

    def contains(self, x_m: float, y_m: float, margin_m: float = 0.0) -> bool:
        return (self.x_min_m + margin_m <= x_m <= self.x_max_m - margin_m
                and self.y_min_m + margin_m <= y_m <= self.y_max_m - margin_m)


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """A boolean occupancy grid over a :class:`Rect`.

    ``occupied[row, col]`` covers x in ``[x_min + col*cell_m, x_min + (col+1)*cell_m)``
    and y in ``[y_min + row*cell_m, ...)``: rows grow with y, columns with x.
    """

    occupied: np.ndarray  # (rows, cols) bool
    cell_m: float
    origin_m: tuple[float, float]  # world (x, y) of the corner of cell (0, 0)

    @property
    def shape(self) -> tuple[int, int]:
        return self.occupied.shape  # type: ignore[return-value]

    def cell_of(self, x_m: float, y_m: float) -> tuple[int, int]:
        """(row, col) of the cell containing a world point, clamped to the grid."""
        rows, cols = self.occupied.shape
        col = int(math.floor((x_m - self.origin_m[0]) / self.cell_m))
        row = int(math.floor((y_m - self.origin_m[1]) / self.cell_m))
        return min(max(row, 0), rows - 1), min(max(col, 0), cols - 1)

    def centres_m(self, cells: np.ndarray) -> np.ndarray:
        """World (x, y) centres of an (N, 2) array of (row, col) cells."""
        cells = np.asarray(cells, dtype=float).reshape(-1, 2)
        x = self.origin_m[0] + (cells[:, 1] + 0.5) * self.cell_m
        y = self.origin_m[1] + (cells[:, 0] + 0.5) * self.cell_m
        return np.column_stack([x, y])


def rasterise(bounds: Rect, discs: tuple[Disc, ...], boxes: tuple[Box, ...],
              inflation_m: float, cell_m: float) -> OccupancyGrid:
    """Occupancy grid whose blocked cells have centres within ``inflation_m`` of an obstacle.

    A further margin of ``cell_m / sqrt(2)`` is added so that the straight move
    between the centres of two free 8-neighbours never enters an inflated
    obstacle (with endpoints at least R + h/sqrt(2) from a centre, the midpoint
    of a move of length h*sqrt(2) stays at least R away).
    """
    if cell_m <= 0:
        raise ValueError("cell_m must be positive")
    cols = max(1, int(math.ceil(bounds.width_m / cell_m - 1e-9)))
    rows = max(1, int(math.ceil(bounds.height_m / cell_m - 1e-9)))
    xs = bounds.x_min_m + (np.arange(cols) + 0.5) * cell_m
    ys = bounds.y_min_m + (np.arange(rows) + 0.5) * cell_m
    gx, gy = np.meshgrid(xs, ys)  # (rows, cols)
    reach = inflation_m + cell_m / math.sqrt(2.0)
    occupied = np.zeros((rows, cols), dtype=bool)
    for disc in discs:
        occupied |= (gx - disc.x_m) ** 2 + (gy - disc.y_m) ** 2 < (disc.radius_m + reach) ** 2
    for box in boxes:
        dx = np.maximum(np.maximum(box.x_min_m - gx, gx - box.x_max_m), 0.0)
        dy = np.maximum(np.maximum(box.y_min_m - gy, gy - box.y_max_m), 0.0)
        occupied |= dx * dx + dy * dy < reach * reach
    return OccupancyGrid(occupied=occupied, cell_m=float(cell_m),
                         origin_m=(bounds.x_min_m, bounds.y_min_m))


@dataclass(frozen=True, eq=False)
class Problem:
    """A 2-D planning query.

    Attributes:
        start, goal: poses in metres / radians.
        bounds: the workspace; paths must stay inside it.
        obstacles: disc footprints, *not* inflated.
        robot_radius_m: radius of the robot's footprint.
        clearance_m: extra safety margin a planner keeps beyond the robot radius.
        boxes: axis-aligned box footprints (from grid maps), not inflated.
        cell_m: resolution of :attr:`grid`.
    """

    start: Pose2D
    goal: Pose2D
    bounds: Rect
    obstacles: tuple[Disc, ...]
    robot_radius_m: float
    clearance_m: float = 0.0
    boxes: tuple[Box, ...] = ()
    cell_m: float = 0.05
    grid_override: OccupancyGrid | None = field(default=None, repr=False)

    @property
    def inflation_m(self) -> float:
        """Distance a path keeps from every obstacle footprint."""
        return self.robot_radius_m + self.clearance_m

    @cached_property
    def disc_centres_m(self) -> np.ndarray:
        """(C, 2) disc centres."""
        return np.array([[d.x_m, d.y_m] for d in self.obstacles], dtype=float).reshape(-1, 2)

    @cached_property
    def disc_radii_m(self) -> np.ndarray:
        """(C,) disc radii, not inflated."""
        return np.array([d.radius_m for d in self.obstacles], dtype=float)

    @cached_property
    def inflated_radii_m(self) -> np.ndarray:
        """(C,) disc radii grown by :attr:`inflation_m`."""
        return self.disc_radii_m + self.inflation_m

    @cached_property
    def grid(self) -> OccupancyGrid:
        """Occupancy grid of the inflated obstacles at :attr:`cell_m`."""
        if self.grid_override is not None:
            return self.grid_override
        return rasterise(self.bounds, self.obstacles, self.boxes, self.inflation_m, self.cell_m)

    def nearest_obstacle(self, x_m: float, y_m: float) -> tuple[str, int, float]:
        """The obstacle nearest a point: ("disc" or "box", its index, signed gap to its inflated footprint).

        ("", -1, inf) with no obstacle.  A point inside a box scores ``-inflation_m``.
        """
        best = ("", -1, float("inf"))
        if self.obstacles:
            d = np.hypot(self.disc_centres_m[:, 0] - x_m, self.disc_centres_m[:, 1] - y_m) - self.inflated_radii_m
            i = int(np.argmin(d))
            best = ("disc", i, float(d[i]))
        if self.boxes:
            p = np.array([[x_m, y_m]])
            d = segment_box_distances(p, p, self.box_array_m)[0] - self.inflation_m
            i = int(np.argmin(d))
            if d[i] < best[2]:
                best = ("box", i, float(d[i]))
        return best

    def point_clearance_m(self, x_m: float, y_m: float) -> float:
        """Signed gap from a point to the nearest inflated disc or box (inf with none)."""
        return self.nearest_obstacle(x_m, y_m)[2]

    @cached_property
    def box_array_m(self) -> np.ndarray:
        """(B, 4) box footprints as rows of (x_min, y_min, x_max, y_max), not inflated."""
        return np.array([[b.x_min_m, b.y_min_m, b.x_max_m, b.y_max_m] for b in self.boxes],
                        dtype=float).reshape(-1, 4)

    def path_clearance_m(self, waypoints: np.ndarray) -> float:
        """Exact smallest gap between a polyline and the inflated discs and boxes.

        Discs by segment-disc distance, boxes by segment-box distance; a segment
        crossing a box scores ``-inflation_m``.
        """
        gap = polyline_clearance_m(waypoints, self.disc_centres_m, self.inflated_radii_m)
        if self.boxes:
            pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
            if pts.shape[0] == 1:
                pts = np.vstack([pts, pts])
            dist = segment_box_distances(pts[:-1], pts[1:], self.box_array_m)
            gap = min(gap, float(np.min(dist)) - self.inflation_m)
        return gap

    def is_collision_free(self, waypoints: np.ndarray, tolerance_m: float = 1e-6) -> bool:
        """Exact check: inside the bounds and clear of every inflated disc."""
        pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
        b = self.bounds
        if np.any(pts[:, 0] < b.x_min_m - tolerance_m) or np.any(pts[:, 0] > b.x_max_m + tolerance_m):
            return False
        if np.any(pts[:, 1] < b.y_min_m - tolerance_m) or np.any(pts[:, 1] > b.y_max_m + tolerance_m):
            return False
        return self.path_clearance_m(pts) >= -tolerance_m


@dataclass(frozen=True, eq=False)
class PlanStats:
    """What a planner measured about its own run."""

    length_m: float
    plan_time_s: float
    iterations: int = 0
    evaluations: int = 0
    cost_history: tuple[float, ...] = ()
    extra: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class Path:
    """Planner output: waypoints (N, 2) in metres from start to goal, and stats."""

    waypoints: np.ndarray
    stats: PlanStats

    @classmethod
    def from_waypoints(cls, waypoints: np.ndarray, plan_time_s: float, **stats: Any) -> "Path":
        pts = np.ascontiguousarray(np.asarray(waypoints, dtype=float).reshape(-1, 2))
        return cls(waypoints=pts, stats=PlanStats(length_m=polyline_length_m(pts),
                                                  plan_time_s=plan_time_s, **stats))

    def same_as(self, other: "Path") -> bool:
        """Bitwise-equal waypoints and equal counters (timings excluded)."""
        return (np.array_equal(self.waypoints, other.waypoints)
                and self.stats.iterations == other.stats.iterations
                and self.stats.evaluations == other.stats.evaluations
                and self.stats.cost_history == other.stats.cost_history)


@runtime_checkable
class Planner(Protocol):
    """The one planner seam: ``plan(problem, rng) -> Path``.

    Raises :class:`planners.errors.PlanningError` subclasses on failure.
    Planner parameters are the constructor's keyword arguments (dataclass fields).
    """

    name: ClassVar[str]

    def plan(self, problem: Problem, rng: np.random.Generator) -> Path: ...


def check_endpoints(problem: Problem) -> None:
    """Raise StartBlocked / GoalBlocked when an endpoint is outside the bounds or in an obstacle."""
    from planners.errors import GoalBlocked, StartBlocked

    for pose, error, label in ((problem.start, StartBlocked, "start"), (problem.goal, GoalBlocked, "goal")):
        if not problem.bounds.contains(pose.x_m, pose.y_m):
            raise error(f"{label} ({pose.x_m:g}, {pose.y_m:g}) is outside the bounds")
        kind, _, gap = problem.nearest_obstacle(pose.x_m, pose.y_m)
        if gap < -1e-9:  # touching is allowed (map cell centres touch inflated boxes)
            raise error(f"{label} ({pose.x_m:g}, {pose.y_m:g}) is inside an inflated {kind} obstacle "
                        f"(by {-gap:.3f} m)")
