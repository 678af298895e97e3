"""``dstar_replan``: D* Lite (Koenig & Likhachev 2002) on the known map's cells, with the sensed
obstacles' swept footprints marked on the cells and cleared when they leave; the classic grid
replanning baseline.

Koenig & Likhachev (2002) plan backwards from the goal so that, as the robot
moves (``move_start``: the key modifier k_m grows by h(s_last, s_start), their
Fig. 4, lines 31-32) and as cells change cost (``update_cells``: lines 33-37),
only the part of the cost-to-goal field the changes reach is repaired.  The
paper's robot senses the cells around it and treats what it has not seen as
free; here the known map (static discs and boxes, inflated by the robot radius
and the scenario's clearance, rasterised as every grid planner does) is marked
at reset, and at every control step:

1. **Marking** (ours; the paper's cells are static once seen), every
   ``update_period_s`` (the paper senses once per cell moved): every sensed
   obstacle (``Observation.detections``) is swept along its estimated velocity
   over ``horizon_s`` (:func:`~controllers.prediction.swept_discs`), grown by
   the inflation plus ``margin_m``, and rasterised; a swept disc that would
   cover the robot's cell or the goal's is shrunk to leave them free (as
   ``replan`` does).  The cells whose state differs from the last step's go to
   ``update_cells``: newly covered ones are blocked, ones the sweeps have left
   are freed.  Cells of the known map never change.
2. **Start**: the robot's cell (``move_start``); if that cell is blocked (the
   robot cut into an inflation) the nearest free cell within two cells stands in.
3. **Replanning**: ``compute_shortest_path`` whenever cells changed or the
   start moved off the path; the new cell path is adopted (a ``replan`` event,
   a new ``/planner/path``) when the remainder of the current one crosses a
   sweep grown by the bare inflation (without ``margin_m``), when the robot
   left it, or when the new one is shorter by more than ``improvement_m``.
   Both are hystereses of ours: D* Lite's paths hug the marked cells, and
   without them a sweep growing by one cell would republish the path at
   nearly every step.
4. **Following**: the adopted cell path is shortened by line of sight on the
   current cells (greedy string pulling; a shortcut is taken only when the straight segment between the two
   cell centres also keeps the inflation from the known map's discs and boxes: a line of sight between free
   cells of a map grid can pass within centimetres of a box's corner, which the robot's 0.15 m radius then
   hit; this was ``dstar_replan``'s collision on ``immas-env3-dynamic``, at 33.7 s, with no moving obstacle
   near) and handed to the scenario's controller, from the robot's position to the exact goal.
5. **No path** (the sweeps close every way): stop, and try again at every
   step (the repair is incremental, so retrying is cheap); one
   ``replan_failed`` event per blocked spell.

**Its own planner.**  Every path this navigator follows, the first one included, is D* Lite's
on its grid: the run's planner plans the episode's first path (``plan --json``, the row's
``plan_*`` columns), but this navigator does not follow it.  Its ``planner`` parameter names
that (``"dstar_lite"``, the only value: an incremental repair needs D* Lite's cost-to-goal
field, which no swarm planner keeps), so a row of "gwo + dstar_replan" says in its
navigator parameters that the robot drove D* Lite's paths; the ``replan`` navigator is the
one that replans with the run's own planner and parameters.

**Evasion** (``evade``, on by default; ours): the safety layer's (:mod:`controllers.safety_layer`, applied
by the stepper after this navigator's step) velocity-obstacle evasion of :mod:`controllers.evasion`
overrides the command while a sensed obstacle's predicted time to collision with the robot is below
``evade_trigger_s``.  Why its collisions with the 2 m detector on dyn300 (e.g. ``d300-fast-13``): the sweeps are kept off the robot's cell (step 1), so an obstacle that comes at the robot (a crosser
faster than it, one that chases it along its detour) is marked everywhere but where the robot is, and D* Lite's
path, which hugs the marked cells, leads along or ahead of it; when the robot stops to turn onto a repaired
path (the controller turns on the spot), the obstacle runs into it.  A grid of swept cells without time cannot
say "step aside now"; the evasion does.  ``evade = false`` gives the earlier behaviour.

**A box chassis** (ours; all off by default, :mod:`controllers.footprint`): ``footprint = "box"`` blocks
the cells by the robot's inscribed circle instead of its circumscribed one (a Jackal's 0.215 m instead of
0.333 m, which closes BARN's 0.75 m passages), and checks every turn on the spot against the box (backing off,
or turning the other way, when a corner would hit); ``cost_weight`` > 0 adds D* Lite cell penalties
``cost_weight`` x (1 - d / ``cost_reach_m``)^2 near blocked cells, so that paths keep to the middle of
passages (and string pulling never cuts nearer the obstacles than the cells); ``max_decel_m_s2`` > 0 caps the
forward speed to stop before the path's next sharp turn and before the nearest mapped obstacle in the
chassis' corridor ahead.  BARN's configuration: ``footprint=box, cost_weight=10, max_decel_m_s2=2`` (docs/barn.md).

**Crowd options** (ours; all off by default, docs/navigation.md, measured among CrowdNav's ORCA humans on
validation cases): ``blocked_horizon_s`` > 0: when the sweeps over ``horizon_s`` leave no path (every human
converging on the centre of a circle crossing), they are marked over this shorter horizon and D* Lite plans again
instead of stopping there (the freezing robot problem, Trautman & Krause 2010); ``corner_merge_m`` > 0: corners
of the string-pulled path closer than this to the last one kept are dropped (a path adopted round sweeps pulls
into a staircase of corners a cell apart, at each of which the controller turned on the spot).  The evasion's
options ``evade_still_m_s``, ``evade_turn_cost_m_s_rad`` and ``evade_reverse`` (:mod:`controllers.evasion`) are
offered by this navigator (``safety_layer_options``; ``dwa``, ``iaco_local`` and ``immas_stepwise`` offer them too).

``cell_m`` = 0 uses the scenario's ``sim.cell_m`` (a map scenario's own cells
always).  The optional safety filter (``safety_filter``) is the same layer's.
Planning wall time (``replan_wall_s``) counts the D* Lite repairs only.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from swarmnav.models.parameters import above, param, within
from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.navigator import Belief, NavigationSetup, NavigationStep, Observation
from swarmnav.controllers.navigators.replan import keep_outside
from swarmnav.controllers.prediction import swept_discs
from swarmnav.controllers.footprint import (block_radius_m, braked, cell_penalty, chassis_box_m, chassis_extent_m,
                                            free_ahead_m, guarded_turn, no_costlier)
from swarmnav.models.geometry import segment_box_distances, segment_disc_distances
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario_limits import MAX_GRID_CELLS
from swarmnav.models.world import rasterise
from swarmnav.planners.dstar_lite import DStarLite
from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.grid_graph import Cell, grid_line_of_sight, octile_cells
from swarmnav.planners.problem import Path

NO_CELL: Cell = (-1, -1)


@dataclass
class DStarReplanNavigator:
    """D* Lite with sensed sweeps marked on its cells (see the module docstring).

    Args:
        horizon_s: how far sensed obstacles are swept along their estimated velocity.
        margin_m: extra distance beyond the inflation (robot radius + clearance) around sensed obstacles.
        cell_m: the grid's cell size; 0 = the scenario's.
        improvement_m: a new path replaces a still-free one only when shorter by more than this.
        update_period_s: the sweeps are marked (and D* Lite repaired) at most this often.
        planner: the planner of every path followed: ``"dstar_lite"`` (the only one; see the module docstring).
        footprint: ``"circle"`` (cells blocked by the robot radius) or ``"box"`` (by the chassis' inscribed
            circle, turns on the spot checked against the box).
        cost_weight: D* Lite's penalty on cells beside blocked ones (0: none).
        cost_reach_m: how far from a blocked cell the penalty reaches.
        max_decel_m_s2: the braking the forward speed is capped by (0: no cap).
        blocked_horizon_s: when the sweeps over ``horizon_s`` leave no path, plan on sweeps over this shorter
            horizon instead of stopping (0: off, stop and retry; see the module docstring).
        corner_merge_m: string-pulled corners closer than this to the previous one kept are dropped (0: none).
    """

    name: ClassVar[str] = "dstar_replan"
    safety_layer: ClassVar[dict[str, bool]] = {"safety_filter": False, "evade": True}  # controllers.safety_layer
    safety_layer_options: ClassVar[tuple[str, ...]] = ("evade_still_m_s", "evade_reverse",  # off by default
                                                       "evade_turn_cost_m_s_rad")
    uses_detections: ClassVar[bool] = True
    uses_planner: ClassVar[bool] = False
    replan_wall_s: float = field(default=0.0, init=False, repr=False)

    horizon_s: float = param(3.0, above(0, 600))
    margin_m: float = param(0.1, within(0, 100))
    cell_m: float = param(0.0, within(0, 100))
    improvement_m: float = param(0.5, within(0, 1e6))
    update_period_s: float = param(0.2, within(0, 1e6))
    planner: str = param("dstar_lite", choices=("dstar_lite",))  # it repairs D* Lite's own paths
    footprint: str = param("circle", choices=("circle", "box"))
    cost_weight: float = param(0.0, within(0, 1000))
    cost_reach_m: float = param(0.3, above(0, 100))
    max_decel_m_s2: float = param(0.0, within(0, 1000))
    blocked_horizon_s: float = param(0.0, within(0, 600))
    corner_merge_m: float = param(0.0, within(0, 100))

    def reset(self, setup: NavigationSetup) -> None:
        known = setup.map_problem
        self.known = known
        self.block_m = known.inflation_m if self.footprint == "circle" else block_radius_m(setup) + known.clearance_m
        self.setup = setup
        self.map_revision = setup.map_revision
        self.controller = setup.controller
        if known.grid_override is not None:
            self.grid = known.grid_override
        else:
            cell_m = self.cell_m or known.cell_m
            cells = (known.bounds.width_m / cell_m) * (known.bounds.height_m / cell_m)  # a float: never overflows
            if not cells <= MAX_GRID_CELLS:  # before the grid is allocated
                raise ConfigError("navigator.params.cell_m" if self.cell_m else "sim.cell_m",
                                  f"{cell_m:g} m cells over the {known.bounds.width_m:g} x {known.bounds.height_m:g} m "
                                  f"arena are {cells:.3g} grid cells, at most {MAX_GRID_CELLS:,} (MAX_GRID_CELLS)")
            self.grid = rasterise(known.bounds, known.obstacles, known.boxes, self.block_m, cell_m)
        self.static = np.asarray(self.grid.occupied, dtype=bool)
        self.current = self.static.copy()
        self.inflation_m = self.block_m + self.margin_m
        # Sweeps are kept this far from the robot and the goal, so their cells stay free.
        self.room_m = self.inflation_m + 1.5 * self.grid.cell_m
        self.goal_xy = (setup.goal.x_m, setup.goal.y_m)
        self.goal_cell = self.grid.cell_of(*self.goal_xy)
        start = self._free_cell_near(setup.problem.start.x_m, setup.problem.start.y_m)
        self.penalty = cell_penalty(self.current, self.grid.cell_m, self.cost_weight, self.cost_reach_m)
        self.dstar = DStarLite(self.static, start if start != NO_CELL else self.goal_cell, self.goal_cell,
                               penalty=self.penalty)
        self.cells: list[Cell] = []
        self.waypoints: list[tuple[float, float]] = []
        self.front_m, self.half_width_m = chassis_extent_m(setup)
        self.box_m, self.turn_sign = chassis_box_m(setup), 0.0
        self.at = 0  # index of the robot's cell in self.cells
        self.adopted = False  # a path has been adopted at least once
        self.blocked_spell = False
        self.next_update_s = 0.0
        self.sweeps: list = []
        self.replan_wall_s = 0.0

    # -- the step ------------------------------------------------------------
    def step(self, observation: Observation) -> NavigationStep:
        pose = observation.pose
        events: list[tuple[str, dict[str, Any]]] = []
        changed = False
        if observation.time_s >= self.next_update_s - 1e-9 or not self.cells:
            self.next_update_s = observation.time_s + self.update_period_s
            changed = self._mark(observation)
        start = self._free_cell_near(pose.x_m, pose.y_m)
        on_path = self._locate(start)
        new_path = None
        if start == NO_CELL:
            return self._finish(observation, self._stop(events, "the robot's cells are all blocked"), events, None)
        if changed or not on_path or not self.cells:
            wall0 = time.perf_counter()
            if start != self.dstar.start:
                self.dstar.move_start(start)
            try:
                cells = self.dstar.plan()
            except NoPathFound:
                cells = None
            if cells is None and self.blocked_horizon_s > 0 and observation.detections:
                cells, start = self._plan_short(observation, pose)
            self.replan_wall_s += time.perf_counter() - wall0
            if cells is None:
                self.cells = []
                return self._finish(observation, self._stop(events, "no path on the marked cells"), events, None)
            self.blocked_spell = False
            reason = self._reason(cells, on_path)
            if reason:
                new_path = self._adopt(cells, pose)
                if reason != "initial":
                    events.append(("replan", {"reason": reason, "tracks": [d.track_id for d in observation.detections],
                                              "length_m": round(new_path.stats.length_m, 6)}))
        command = self.controller.command(pose, observation.twist)
        if self.max_decel_m_s2 > 0:
            ahead_m = free_ahead_m(self.known, pose, self.front_m, self.half_width_m)
            command = braked(command, pose, self.controller, self.waypoints, self.max_decel_m_s2, ahead_m)
        if self.footprint == "box":
            command, self.turn_sign = guarded_turn(command, pose, self.controller, self.known, self.box_m,
                                                   self.turn_sign)
        return self._finish(observation, command, events, new_path)

    def _plan_short(self, observation: Observation, pose) -> tuple[list[Cell] | None, Cell]:
        """``blocked_horizon_s``: the sweeps over ``horizon_s`` close every way, so mark them over the shorter
        horizon and plan again (the cells stay so marked until the next marking, which tries ``horizon_s``
        first again); (the cell path or None, the start used)."""
        self._mark(observation, self.blocked_horizon_s)
        start = self._free_cell_near(pose.x_m, pose.y_m)
        if start == NO_CELL:
            return None, start
        if start != self.dstar.start:
            self.dstar.move_start(start)
        try:
            return self.dstar.plan(), start
        except NoPathFound:
            return None, start

    # -- cells ---------------------------------------------------------------
    def _mark(self, observation: Observation, horizon_s: float | None = None) -> bool:
        """Mark this step's sweeps (over ``horizon_s``, else the navigator's); True when any cell changed (and
        D* Lite was told)."""
        pose = observation.pose
        occupied = self._map_cells()
        self.sweeps = []
        if observation.detections:
            self.sweeps = keep_outside(swept_discs(observation.detections,
                                                   self.horizon_s if horizon_s is None else horizon_s),
                                       [(pose.x_m, pose.y_m), self.goal_xy], self.room_m)
            marks = self._rasterise(self.inflation_m)
            if marks is not None:
                occupied = occupied | marks
        if np.array_equal(occupied, self.current):
            return False
        self.current = occupied
        self.dstar.set_occupied(occupied)
        if self.cost_weight > 0:
            self.penalty = cell_penalty(occupied, self.grid.cell_m, self.cost_weight, self.cost_reach_m)
            self.dstar.update_penalty(self.penalty)
        return True

    def _map_cells(self) -> np.ndarray:
        """The map's blocked cells: fixed with a known map; with the map unknown, the sensed map's latest
        publication rasterised on this grid (its changes reach D* Lite with the sweeps', as cell updates)."""
        if self.setup.map_revision != self.map_revision:
            self.map_revision = self.setup.map_revision
            known = self.known = self.setup.map_problem
            cells = rasterise(known.bounds, known.obstacles, known.boxes, self.block_m, self.grid.cell_m).occupied
            if cells.shape == self.static.shape:
                self.static = cells
        return self.static

    def _rasterise(self, inflation_m: float) -> np.ndarray | None:
        """This step's sweeps on the grid's cells, grown by ``inflation_m`` (None with none)."""
        if not self.sweeps:
            return None
        marks = rasterise(self.known.bounds, tuple(self.sweeps), (), inflation_m, self.grid.cell_m).occupied
        return marks if marks.shape == self.static.shape else None

    def _swept(self, cells: list[Cell], inflation_m: float) -> bool:
        """Whether ``self._rasterise(inflation_m)`` marks any of ``cells``, tested on those cells only: the same
        rule and double operations as :func:`models.world.rasterise` (a cell is marked when its centre's squared
        distance to a sweep's centre is below the square of the sweep's radius + ``inflation_m`` + cell / sqrt 2;
        a cell beyond a sweep's window is farther than that by half a cell), not the whole grid."""
        if not self.sweeps or not cells:
            return False
        bounds, cell_m = self.known.bounds, self.grid.cell_m
        cols = max(1, int(math.ceil(bounds.width_m / cell_m - 1e-9)))
        rows = max(1, int(math.ceil(bounds.height_m / cell_m - 1e-9)))
        if (rows, cols) != self.static.shape:  # as _rasterise: marks of another grid are not used
            return False
        at = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
        xs = bounds.x_min_m + (at[:, 1] + 0.5) * cell_m
        ys = bounds.y_min_m + (at[:, 0] + 0.5) * cell_m
        reach = inflation_m + cell_m / math.sqrt(2.0)
        discs = np.array([(d.x_m, d.y_m, d.radius_m) for d in self.sweeps], dtype=float)
        grown = discs[:, 2] + reach
        dx = xs[:, None] - discs[None, :, 0]
        dy = ys[:, None] - discs[None, :, 1]
        return bool(np.any(dy ** 2 + dx ** 2 < grown * grown))

    def _free_cell_near(self, x_m: float, y_m: float) -> Cell:
        """The robot's cell, or the nearest free cell within two cells of it (NO_CELL if none)."""
        r0, c0 = self.grid.cell_of(x_m, y_m)
        if not self.current[r0, c0]:
            return (r0, c0)
        rows, cols = self.current.shape
        best, best_d = NO_CELL, math.inf
        for dr in range(-2, 3):
            for dc in range(-2, 3):
                r, c = r0 + dr, c0 + dc
                if 0 <= r < rows and 0 <= c < cols and not self.current[r, c]:
                    x, y = self.grid.centres_m(np.array([(r, c)]))[0]
                    d = math.hypot(x - x_m, y - y_m)
                    if d < best_d - 1e-12:
                        best, best_d = (r, c), d
        return best

    def _locate(self, cell: Cell) -> bool:
        """Advance ``self.at`` to the robot's cell on the current path; False if it is not on it."""
        for i in range(self.at, min(self.at + 4, len(self.cells))):
            if self.cells[i] == cell:
                self.at = i
                return True
        # Beside the path (the controller cuts corners between shortened waypoints) counts as on it.
        near = [i for i in range(self.at, min(self.at + 6, len(self.cells)))
                if max(abs(self.cells[i][0] - cell[0]), abs(self.cells[i][1] - cell[1])) <= 1]
        if near:
            self.at = near[0]
            return True
        return False

    def _reason(self, cells: list[Cell], on_path: bool) -> str:
        """Why the new cell path replaces the current one ("" to keep the current one)."""
        if not self.cells:
            return "path found again" if self.adopted else "initial"
        if not on_path:
            return "left the path"
        rest = self.cells[self.at:]
        if self.setup.world_map is not None and any(self.static[r, c] for r, c in rest):
            return "blocked on the sensed map"
        # Blocked: a sweep grown by the bare inflation (without margin_m) covers a cell still to come.
        if self._swept(rest, self.block_m):
            return "sensed obstacle on the path"
        if _cells_length(rest) - _cells_length(cells) > self.improvement_m / self.grid.cell_m:
            return "shorter path"
        return ""

    def _adopt(self, cells: list[Cell], pose) -> Path:
        self.adopted = True
        self.cells, self.at = cells, 0
        corners = self._string_pull(cells)
        middle = self.grid.centres_m(np.array(corners[1:-1])).reshape(-1, 2)
        if self.corner_merge_m > 0 and len(middle):
            middle = _merged(middle, (pose.x_m, pose.y_m), self.corner_merge_m)
        waypoints = np.vstack([[pose.x_m, pose.y_m], middle, [self.goal_xy]])
        path = Path.from_waypoints(waypoints, 0.0)
        self.waypoints = [(float(x), float(y)) for x, y in waypoints]
        self.controller.reset(path)
        return path

    def _string_pull(self, cells: list[Cell]) -> list[Cell]:
        """The cells where the path must turn: greedy line of sight on the current cells, a shortcut taken
        only when it also keeps the inflation from the known map (see step 4)."""
        free = self.dstar.free
        centres = self.grid.centres_m(np.array(cells)).reshape(-1, 2)
        out = [cells[0]]
        anchor = 0
        while anchor < len(cells) - 1:
            nxt = anchor + 1
            while nxt + 1 < len(cells) and grid_line_of_sight(free, cells[anchor], cells[nxt + 1]) \
                    and self._clear_of_map(centres[anchor], centres[nxt + 1]) \
                    and no_costlier(self.penalty, self.grid, centres[anchor], centres[nxt + 1], cells[anchor:nxt + 2]):
                nxt += 1
            out.append(cells[nxt])
            anchor = nxt
        return out

    def _clear_of_map(self, a_m: np.ndarray, b_m: np.ndarray) -> bool:
        """Whether the segment keeps the blocking inflation (robot radius, or the inscribed radius with
        ``footprint = "box"``, + clearance) from every known disc and box."""
        a, b = a_m.reshape(1, 2), b_m.reshape(1, 2)
        known = self.known
        if len(known.disc_centres_m) and np.any(segment_disc_distances(a, b, known.disc_centres_m)[0]
                                               < known.disc_radii_m + self.block_m - 1e-9):
            return False
        boxes = known.box_array_m
        return not (len(boxes) and np.any(segment_box_distances(a, b, boxes)[0] < self.block_m - 1e-9))

    def _stop(self, events: list, why: str) -> ControlCommand:
        if not self.blocked_spell:
            events.append(("replan_failed", {"reason": "sensed cells changed", "why": why}))
            self.blocked_spell = True
        return ControlCommand.stop(self.controller.waypoint_index)

    def _finish(self, observation: Observation, command: ControlCommand, events: list,
                new_path: Path | None) -> NavigationStep:
        return NavigationStep(command, new_path, tuple(events), Belief(observation.detections, self.horizon_s))


def _merged(corners_m: np.ndarray, start_m: tuple[float, float], merge_m: float) -> np.ndarray:
    """``corner_merge_m``: the corners without those closer than ``merge_m`` to the last one kept (the robot's
    position the first), so that a staircase of corners a cell apart becomes one turn."""
    kept, last = [], np.asarray(start_m, dtype=float)
    for corner in corners_m:
        if math.hypot(corner[0] - last[0], corner[1] - last[1]) >= merge_m:
            kept.append(corner)
            last = corner
    return np.array(kept, dtype=float).reshape(-1, 2)


def _cells_length(cells: list[Cell]) -> float:
    """Octile length of a cell path, in cells."""
    return sum(octile_cells(b[0] - a[0], b[1] - a[1]) for a, b in zip(cells, cells[1:]))
