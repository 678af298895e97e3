"""Driving through IMMAS's walk instead of stopping at each cell: the ``lookahead_cells`` and ``carrot_m``
options of ``immas_stepwise`` (beyond Hasan, Abdullah & Saleh (2023); off by default).

Why (measured on ``bench navigation --suite dyn300``, detector): the paper's robot occupies a cell and
moves one cell per step; driven cell by cell in physics (:class:`~controllers.navigators.cell_path.CellWalker`
hands the controller one cell at a time, the controller slows into its last waypoint and turns on the spot),
our robot crossed the 0.1-m cells of dyn300 at about half its top speed (6 m in 63 s on ``d300-cross-3``,
30 s at top speed) and most failures were timeouts.

What it does (ours):

* **The walk ahead** (:func:`walk_ahead`): at each decision, the next cell is Eq. (3)'s choice from the cell
  the robot has reached (:meth:`StepwiseWalk.choose`, the paper's), and the walk is carried on for
  ``lookahead_cells`` cells, each the choice Eq. (3) would make from the one before among the cells free of
  the same sensed obstacles (the ``Dobstacle`` of this decision), visited marks included.  Only the first
  cell is a commitment: the walk is chosen again at every cell the robot reaches, with fresh sensing.
* **A carrot** (:func:`carrot_on`): the controller is handed a straight segment from the robot to the point
  of the walk ahead ``carrot_m`` further on from the walk's cell nearest the robot, every control step, so it
  neither slows into each cell (the carrot is beyond its slow-down radius until the walk ends) nor turns on
  the spot at each 45-degree bend (the carrot rounds them).
* **Reaching a cell**: the robot has reached the walk's cell nearest to it (the latest of a tie), once that
  is past the cell it stands on; every cell passed on the way counts as a move (the route cost k of each
  added, line 25).
* **Diverting**: when a sensed obstacle is now on the next cell, §4.1's divert chooses that cell instead (the
  paper's rule, :meth:`StepwiseWalk.divert`) and the walk is carried on from it; when one is on a later cell
  of the walk ahead, the walk ahead is chosen again.
* **Looking further** (``predict_s``, in ``immas_stepwise``): the decision's Dobstacle swept along the sensed
  velocities over ``predict_s`` instead of up to the obstacles' next node.
* **Blocked**: when no neighbour is free the robot stops where it is (the paper's robot stays) and the walk is
  chosen again at every step, from the cell the robot stands on (the evasion may have moved it off the walk).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from swarmnav.controllers.controller import ControlCommand, Controller, Twist
from swarmnav.controllers.navigators.cell_path import Cell
from swarmnav.models.world import OccupancyGrid, Pose2D
from swarmnav.planners.problem import Path

# "now": the cells sensed obstacles occupy now; "step": the paper's Dobstacle (now and up to their next node);
# "decision": the Dobstacle a decision uses ("step", or the sweeps over ``predict_s``).
Occupancy = Callable[[str], np.ndarray]


def walk_ahead(here: Cell, goal: Cell, count: int, visited: np.ndarray, dynamic: np.ndarray,
               first: Callable[[Cell, np.ndarray, np.ndarray], Cell | None],
               then: Callable[[Cell, np.ndarray, np.ndarray], Cell | None]) -> list[Cell]:
    """``[here, c1, ..., cn]``: ``c1 = first(here, visited, dynamic)``, then ``then`` from each, up to
    ``count`` cells after ``c1`` (fewer at the goal or where no neighbour is free)."""
    cells = [here]
    marks = visited.copy()
    marks[here] = True
    step = first
    while len(cells) < count + 2 and cells[-1] != goal:
        nxt = step(cells[-1], marks, dynamic)
        if nxt is None:
            break
        cells.append(nxt)
        marks[nxt] = True
        step = then
    return cells


def nearest_index(centres_m: np.ndarray, x_m: float, y_m: float) -> int:
    """The index of the centre nearest (x, y); among ties, the latest."""
    d = np.hypot(centres_m[:, 0] - x_m, centres_m[:, 1] - y_m)
    return int(len(d) - 1 - np.argmin(d[::-1]))


def carrot_on(centres_m: np.ndarray, index: int, distance_m: float) -> np.ndarray:
    """The point ``distance_m`` along the polyline through ``centres_m`` from centre ``index`` (its end if
    shorter)."""
    left = distance_m
    for a, b in zip(centres_m[index:-1], centres_m[index + 1:]):
        length = math.hypot(*(b - a))
        if length >= left:
            return a + (b - a) * (left / length)
        left -= length
    return centres_m[-1].copy()


@dataclass
class WalkTally:
    """Algorithm 3's tally of one walk, kept by both ways of driving it: the cells visited (the robot does not
    re-enter one while an unvisited candidate is left), the moves, their route cost k summed (line 25) and
    the §4.1 diverts."""

    visited: np.ndarray
    route_cost: np.ndarray
    moves: int = 0
    arc_cost: float = 0.0
    diverts: int = 0

    def move(self, cell: Cell, diverted: bool) -> tuple[str, dict[str, Any]]:
        """A cell reached: marked visited and counted; its ``immas_move`` event."""
        self.visited[cell] = True
        self.moves += 1
        self.arc_cost += float(self.route_cost[cell])
        return ("immas_move", {"cell": list(cell), "moves": self.moves, "total_arc_cost": round(self.arc_cost, 4),
                               "diverted": diverted})


@dataclass
class DriveThrough:
    """The robot driving through the walk ahead (see the module's docstring); one per run.

    Args:
        walk: the paper's choices (:class:`~controllers.navigators.immas_stepwise.StepwiseWalk`).
        grid: the known static world's cells.
        controller: the run's controller, handed the carrot every step.
        lookahead_cells: cells of the walk ahead beyond the next one.
        carrot_m: the carrot's distance along the walk ahead.
        start: the robot's first cell.
        looks_further: the "decision" Dobstacle is the sweeps over ``predict_s``: where it leaves no free
            neighbour, the decision is taken again on the paper's Dobstacle (a sweep ahead must not freeze the
            robot in front of the obstacle that sweeps it).
    """

    walk: Any
    grid: OccupancyGrid
    controller: Controller
    lookahead_cells: int
    carrot_m: float
    start: Cell
    tally: WalkTally
    looks_further: bool = False

    def __post_init__(self) -> None:
        self.visited = self.tally.visited
        self.cells: list[Cell] = []
        self._diverted = False

    def _plan(self, here: Cell, occupancy: Occupancy, first: Cell | None = None) -> Path:
        """The walk ahead from ``here`` (its next cell ``first`` when committed, else Eq. (3)'s choice)."""
        choose = self.walk.choose
        start = choose if first is None else (lambda _cell, _marks, _dyn: first)
        ahead = self.lookahead_cells
        self.cells = walk_ahead(here, self.walk.goal, ahead, self.visited, occupancy("decision"), start, choose)
        if len(self.cells) == 1 and self.looks_further:
            self.cells = walk_ahead(here, self.walk.goal, ahead, self.visited, occupancy("step"), start, choose)
        self.centres_m = self.grid.centres_m(np.array(self.cells))
        return Path.from_waypoints(self.centres_m, 0.0)

    def _standing(self, pose: Pose2D, held: Cell) -> Cell:
        """The cell the robot stands on (the evasion may have moved it off the walk), else the held one."""
        cell = self.grid.cell_of(pose.x_m, pose.y_m)                   # clamped to the grid
        analysis = self.walk.analysis
        return cell if not analysis.blocked[cell] and math.isfinite(analysis.route_cost[cell]) else held

    def step(self, pose: Pose2D, twist: Twist, occupancy: Occupancy
             ) -> tuple[ControlCommand, Path | None, list[tuple[str, dict[str, Any]]]]:
        """This control step's command, the new walk ahead (None: unchanged) and the events."""
        events: list[tuple[str, dict[str, Any]]] = []
        new_path = None
        if not self.cells:
            new_path = self._plan(self.start, occupancy)
        reached = nearest_index(self.centres_m, pose.x_m, pose.y_m)
        if reached >= 1:
            for cell in self.cells[1:reached + 1]:
                events.append(self.tally.move(cell, self._diverted))
                self._diverted = False
            new_path = self._plan(self.cells[reached], occupancy)
        elif len(self.cells) == 1:
            if self.cells[0] != self.walk.goal:                     # held: choose again, from where it stands
                held = self.cells
                new_path = self._plan(self._standing(pose, self.cells[0]), occupancy)
                new_path = None if self.cells == held else new_path
        else:
            now = occupancy("now")
            here, nxt = self.cells[0], self.cells[1]
            if now[nxt] and not self._diverted:
                other = self.walk.divert(here, occupancy("decision"))
                if other is None and self.looks_further:
                    other = self.walk.divert(here, occupancy("step"))
                self._diverted = True
                self.tally.diverts += 1
                events.append(("immas_divert", {"from": list(here), "blocked": list(nxt),
                                                "to": None if other is None else list(other)}))
                if other is None:                                   # no free neighbour: hold the cell
                    self.cells, self.centres_m = [here], self.centres_m[:1].copy()
                    new_path = Path.from_waypoints(self.centres_m, 0.0)
                else:
                    new_path = self._plan(here, occupancy, other)
            elif any(now[cell] for cell in self.cells[2:]):
                new_path = self._plan(here, occupancy, nxt)
        if len(self.cells) == 1 and self.cells[0] != self.walk.goal:
            return ControlCommand.stop(), new_path, events              # no free neighbour: the robot stays
        index = nearest_index(self.centres_m, pose.x_m, pose.y_m)
        carrot = carrot_on(self.centres_m, index, self.carrot_m)
        self.controller.reset(Path.from_waypoints(np.array([[pose.x_m, pose.y_m], carrot]), 0.0))
        return self.controller.command(pose, twist), new_path, events
