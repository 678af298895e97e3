"""The two grid papers' navigators on a map they must build and with a box chassis: options beyond the papers.

Gong et al. (2022) and Hasan et al. (2023) plan once on a known static map for a one-cell robot.  Under BARN's
protocol (Perille et al. 2020; ``docs/barn.md``) the map is unknown (the laser builds it as the robot drives,
:mod:`controllers.world_map`) and the robot is a Jackal, a 0.508 x 0.430 m box whose circumscribed circle
(0.333 m) closes BARN's 0.75 m passages on the grid.  This module holds what ``iaco_local``'s and
``immas_stepwise``'s named options (all off by default; ``docs/navigation.md``) share:

* :func:`navigator_grid`: the known static world on the problem's cells, blocked by the robot radius (the
  papers' grid, :func:`~controllers.navigators.cell_path.static_grid`) or, ``footprint = "box"``, by the
  chassis' inscribed circle (:func:`controllers.footprint.block_radius_m`, as ``dstar_replan``'s option);
* :class:`MapWatch`: whether the sensed map has republished since the grid was built (``map_updates``);
* :func:`free_cell_near`: the robot's cell, or the nearest free one, to plan from;
* :class:`ChassisGuard`: ``dstar_replan``'s speed cap and guarded turn on the spot
  (:func:`controllers.footprint.braked`, :func:`controllers.footprint.guarded_turn`).

No MuJoCo here.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.footprint import block_radius_m, braked, chassis_box_m, chassis_extent_m, free_ahead_m, \
    guarded_turn
from swarmnav.controllers.navigators.cell_path import Cell, static_grid
from swarmnav.models.world import OccupancyGrid

FOOTPRINTS = ("circle", "box")
MAP_UPDATES = ("none", "replan")


def navigator_grid(setup: Any, footprint: str) -> OccupancyGrid:
    """The static world the navigator knows now (``setup.map_problem``) on its cells, blocked by the robot
    radius (``"circle"``) or by the chassis' inscribed circle (``"box"``), plus the clearance."""
    problem = setup.map_problem
    if footprint == "box":
        problem = replace(problem, robot_radius_m=block_radius_m(setup))
    return static_grid(problem)


@dataclass
class MapWatch:
    """Whether the sensed map republished a change since the last :meth:`take` (never with the map known)."""

    setup: Any

    def __post_init__(self) -> None:
        self.revision = self.setup.map_revision

    def changed(self) -> bool:
        return self.setup.map_revision != self.revision

    def take(self) -> None:
        self.revision = self.setup.map_revision


def free_cell_near(occupied: np.ndarray, cell: Cell, reach_cells: int = 4) -> Cell | None:
    """``cell`` if free, else the nearest free cell within ``reach_cells`` (Chebyshev), else None."""
    if not occupied[cell]:
        return cell
    rows, cols = occupied.shape
    r0, c0 = cell
    rs = slice(max(0, r0 - reach_cells), min(rows, r0 + reach_cells + 1))
    cs = slice(max(0, c0 - reach_cells), min(cols, c0 + reach_cells + 1))
    free = np.argwhere(~occupied[rs, cs])
    if not len(free):
        return None
    free += np.array([rs.start, cs.start])
    d = np.hypot(free[:, 0] - r0, free[:, 1] - c0)
    r, c = free[int(np.argmin(d))]
    return (int(r), int(c))


@dataclass
class ChassisGuard:
    """``max_decel_m_s2`` and ``footprint = "box"``'s turn check on a navigator's command (``dstar_replan``'s,
    :mod:`controllers.footprint`), against the map the navigator knows now."""

    setup: Any
    footprint: str
    max_decel_m_s2: float

    def __post_init__(self) -> None:
        self.front_m, self.half_width_m = chassis_extent_m(self.setup)
        self.box_m = chassis_box_m(self.setup)
        self.turn_sign = 0.0

    @property
    def active(self) -> bool:
        return self.max_decel_m_s2 > 0 or (self.footprint == "box" and self.box_m is not None)

    def apply(self, command: ControlCommand, pose: Any, controller: Any,
              waypoints: list[tuple[float, float]]) -> ControlCommand:
        if not self.active:
            return command
        known = self.setup.map_problem
        if self.max_decel_m_s2 > 0:
            ahead_m = free_ahead_m(known, pose, self.front_m, self.half_width_m)
            command = braked(command, pose, controller, waypoints, self.max_decel_m_s2, ahead_m)
        if self.footprint == "box":
            command, self.turn_sign = guarded_turn(command, pose, controller, known, self.box_m, self.turn_sign)
        return command


def path_waypoints(grid: OccupancyGrid, cells: list[Cell]) -> list[tuple[float, float]]:
    """Cell centres as (x, y) tuples (what :func:`controllers.footprint.braked` reads)."""
    return [(float(x), float(y)) for x, y in grid.centres_m(np.array(cells)).reshape(-1, 2)]
