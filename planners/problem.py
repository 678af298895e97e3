"""The planning seam: what a planner is given and what it returns.

Nothing here knows MuJoCo or files.  :func:`scenario_problem` builds a
:class:`Problem` from a validated scenario, :func:`map_problem` from a grid map;
``sim`` executes a :class:`Path`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np

from swarmnav.models.geometry import polyline_length_m, segment_box_distances, segment_disc_distances
from swarmnav.models.grid_map import inflated_map_grid, merge_boxes
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import Scenario
from swarmnav.planners.errors import GoalBlocked, StartBlocked
from swarmnav.models.world import Box, Disc, OccupancyGrid, Pose2D, Rect, endpoint_problem, nearest_obstacle, rasterise


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
        unknown_cells: with the map unknown, the never-seen cells of the sensed map (``occupied`` = unknown);
            None otherwise.
        unknown_cost: the extra weight of a move through an unknown cell, read by the grid searches ``astar``
            and ``dijkstra`` only (:mod:`planners.unknown_cost`); 0: unknown cells are free.
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
    unknown_cells: OccupancyGrid | None = field(default=None, repr=False)
    unknown_cost: float = 0.0

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
        """The obstacle nearest a point: ("disc" or "box", its index, signed gap to its inflated footprint)."""
        return nearest_obstacle(x_m, y_m, self.disc_centres_m, self.disc_radii_m, self.box_array_m, self.inflation_m)

    @property
    def obstacle_kinds(self) -> frozenset[str]:
        """The kinds of obstacle this problem has: "discs", "boxes"."""
        return frozenset(kind for kind, present in (("discs", self.obstacles), ("boxes", self.boxes)) if present)

    @cached_property
    def box_array_m(self) -> np.ndarray:
        """(B, 4) box footprints as rows of (x_min, y_min, x_max, y_max), not inflated."""
        return np.array([[b.x_min_m, b.y_min_m, b.x_max_m, b.y_max_m] for b in self.boxes],
                        dtype=float).reshape(-1, 4)

    def segment_clearances_m(self, a: np.ndarray, b: np.ndarray, cull_beyond_m: float = math.inf) -> np.ndarray:
        """Exact smallest gap between each segment ``a[k] -> b[k]`` and the inflated discs and boxes.

        The one implementation of "is this segment clear of the inflated
        obstacles" (bounds are separate: :meth:`in_bounds`): segment-disc
        distances less the inflated radii, segment-box distances less the
        inflation (a segment crossing a box scores ``-inflation_m``).  A point is
        the segment from it to itself.

        Args:
            a, b: (K, 2) segment ends in metres (or (2,) for one segment).
            cull_beyond_m: boxes that do not reach the segments' joint bounding box
                grown by the inflation plus this much are not measured; their gaps
                (all larger than ``cull_beyond_m``) read ``inf``.  A yes/no test
                ("is the gap >= 0?") passes 0; the default measures every box.

        Returns:
            (K,) signed gaps in metres, ``inf`` with no obstacle near.
        """
        a = np.asarray(a, dtype=float).reshape(-1, 2)
        b = np.asarray(b, dtype=float).reshape(-1, 2)
        a, b = np.broadcast_arrays(a, b)
        gap = np.full(a.shape[0], np.inf)
        if self.obstacles and gap.size:
            d = segment_disc_distances(a, b, self.disc_centres_m)
            gap = np.min(d - self.inflated_radii_m[None, :], axis=1)
        if self.boxes and gap.size:
            boxes = self.box_array_m
            reach_m = self.inflation_m + cull_beyond_m
            lo = np.minimum(a.min(axis=0), b.min(axis=0)) - reach_m
            hi = np.maximum(a.max(axis=0), b.max(axis=0)) + reach_m
            near = (boxes[:, 0] <= hi[0]) & (boxes[:, 2] >= lo[0]) & (boxes[:, 1] <= hi[1]) & (boxes[:, 3] >= lo[1])
            if near.any():
                d = segment_box_distances(a, b, boxes[near])
                gap = np.minimum(gap, d.min(axis=1) - self.inflation_m)
        return gap

    def path_clearance_m(self, waypoints: np.ndarray) -> float:
        """Exact smallest gap between a polyline and the inflated discs and boxes
        (the minimum of :meth:`segment_clearances_m` over its segments)."""
        pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
        if pts.shape[0] == 1:
            pts = np.vstack([pts, pts])
        return float(np.min(self.segment_clearances_m(pts[:-1], pts[1:]), initial=np.inf))

    def in_bounds(self, points: np.ndarray, tolerance_m: float = 0.0) -> np.ndarray:
        """(K,) whether each point lies inside the bounds grown by ``tolerance_m``."""
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        b = self.bounds
        return ((pts[:, 0] >= b.x_min_m - tolerance_m) & (pts[:, 0] <= b.x_max_m + tolerance_m)
                & (pts[:, 1] >= b.y_min_m - tolerance_m) & (pts[:, 1] <= b.y_max_m + tolerance_m))

    def is_collision_free(self, waypoints: np.ndarray, tolerance_m: float = 1e-6) -> bool:
        """Exact check: inside the bounds and clear of every inflated disc and box."""
        pts = np.asarray(waypoints, dtype=float).reshape(-1, 2)
        if not np.all(self.in_bounds(pts, tolerance_m)):
            return False
        return self.path_clearance_m(pts) >= -tolerance_m


@dataclass(frozen=True, eq=False)
class PlanStats:
    """What a planner measured about its own run.

    ``cost_history`` is the best cost after the initialisation and after each
    iteration (``iterations + 1`` entries, empty for a planner without iterations);
    ``evaluation_history`` has the same length and holds the objective evaluations
    (what ``evaluations`` counts for that planner) spent by then, cumulatively.  Its
    last entry is the end of the search: evaluations spent after it (the swarm loop's
    repair rounds, the continuous robust mode's final polish) are
    ``evaluations - evaluation_history[-1]``.  ``time_history`` (same length, or empty
    for a planner that does not record it) holds the wall seconds since the plan
    started at each entry: the anytime curves against time (never compared for
    determinism).
    """

    length_m: float
    plan_time_s: float
    iterations: int = 0
    evaluations: int = 0
    cost_history: tuple[float, ...] = ()
    evaluation_history: tuple[int, ...] = ()
    time_history: tuple[float, ...] = ()
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
                and self.stats.cost_history == other.stats.cost_history
                and self.stats.evaluation_history == other.stats.evaluation_history)


@runtime_checkable
class Planner(Protocol):
    """The one planner seam: ``plan(problem, rng) -> Path``.

    Raises :class:`planners.errors.PlanningError` subclasses on failure.
    Planner parameters are the constructor's keyword arguments (dataclass fields).
    """

    name: ClassVar[str]
    #: The obstacle kinds the planner handles ("discs", "boxes").
    supports: ClassVar[frozenset[str]]

    def plan(self, problem: Problem, rng: np.random.Generator) -> Path: ...


def check_supported(planner: Planner, problem: Problem) -> None:
    """Raise a :class:`ConfigError` on ``planner.name`` when ``problem`` has an obstacle kind
    the planner does not declare in ``supports``."""
    missing = problem.obstacle_kinds - type(planner).supports
    if missing:
        raise ConfigError("planner.name", f"{planner.name} supports {' and '.join(sorted(type(planner).supports))} "
                          f"only, this problem has {' and '.join(sorted(missing))}")


def check_endpoints(problem: Problem) -> None:
    """Raise StartBlocked / GoalBlocked when an endpoint is outside the bounds or in an obstacle.

    Touching is allowed (map cell centres touch inflated boxes).
    """
    for pose, error, label in ((problem.start, StartBlocked, "start"), (problem.goal, GoalBlocked, "goal")):
        why = endpoint_problem(pose, problem.bounds, problem.disc_centres_m, problem.disc_radii_m,
                               problem.box_array_m, problem.inflation_m, tolerance_m=1e-9)
        if why is not None:
            raise error(f"{label} {why}")


def scenario_problem(scenario: Scenario, cell_m: float | None = None, at_time_s: float = 0.0,
                     clearance_m: float | None = None) -> Problem:
    """A scenario's planning problem, with its obstacles frozen at ``at_time_s``."""
    clearance_m = scenario.clearance_m if clearance_m is None else clearance_m
    bounds = scenario.planning_bounds(scenario.robot_radius_m + clearance_m)
    discs = scenario.discs_at(at_time_s)
    grid = scenario.map_grid
    if grid is not None and discs:
        # A map with moving obstacles: the map's own cells plus the discs where they are now.
        frozen = rasterise(bounds, discs, (), scenario.robot_radius_m + clearance_m, grid.cell_m)
        grid = OccupancyGrid(grid.occupied | frozen.occupied, grid.cell_m, grid.origin_m)
    return Problem(start=scenario.start, goal=scenario.goal, bounds=bounds,
                   obstacles=discs, robot_radius_m=scenario.robot_radius_m,
                   clearance_m=clearance_m, boxes=scenario.boxes, cell_m=cell_m or scenario.cell_m,
                   grid_override=grid)


def map_problem(occupied: np.ndarray, cell_m: float, start_cell: tuple[int, int], goal_cell: tuple[int, int],
                robot_radius_m: float | None = None, clearance_m: float = 0.0):
    """A :class:`~planners.problem.Problem` on a world-grid map between two (row, col) cells' centres.

    The robot radius defaults to half a cell minus the clearance (the papers'
    one-cell robot); obstacles are the merged boxes, the grid is
    :func:`inflated_map_grid`.
    """
    from swarmnav.models.world import Pose2D, Rect
    from swarmnav.planners.problem import Problem

    occ = np.asarray(occupied, dtype=bool)
    rows, cols = occ.shape
    if robot_radius_m is None:
        robot_radius_m = cell_m / 2.0 - clearance_m
    boxes = merge_boxes(occ, cell_m)
    grid = inflated_map_grid(occ, cell_m, robot_radius_m + clearance_m, boxes)
    centre = lambda cell: Pose2D((cell[1] + 0.5) * cell_m, (cell[0] + 0.5) * cell_m)  # noqa: E731
    return Problem(start=centre(start_cell), goal=centre(goal_cell), bounds=Rect(0.0, 0.0, cols * cell_m, rows * cell_m),
                   obstacles=(), robot_radius_m=robot_radius_m, clearance_m=clearance_m, boxes=boxes,
                   cell_m=cell_m, grid_override=grid)
