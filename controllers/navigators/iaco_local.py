"""``iaco_local``: global IACO path plus local avoidance by collision type, Gong, Yang, Yuan & Wang (2022) §4.

The method of §4.3: plan an IACO path on the static map (Steps 1-2), then walk
it cell by cell; each time the robot reaches a cell it classifies every sensed
moving obstacle (:mod:`controllers.navigators.collision_types`) and acts
(Step 3) until it reaches the goal (Step 4):

* type 1 (crossing, the wait-and-avoid strategy of the paper's ref. [24], Fig. 5):
  go on to the cell before the crossing point (the first path cell within reach
  of the obstacle's track), stop, and wait until going on along the original path
  meets the obstacle no more;
* type 2 (head-on): Eq. (12) for each escape cell of Eq. (13) (even size) or
  Eq. (14) (odd size) that is free (static map, and no sensed obstacle on it)
  and connected to the goal; timing by Eqs. (15)-(17): go on D cells, or act
  now: move to the escape cell and replan IACO from each usable candidate,
  keeping the shortest (escape moves + IACO length);
* type 3 (overtaken from behind): as type 2 with Eqs. (18)-(20);
* type 4 (catching a slower obstacle): the type-2 manoeuvre once ``ng <= rg = V_rob / V_obs``.

``strategy = "wait_only"`` applies type 1's action to every type: ref. [24]'s
strategy, the comparison of §5.4.

Our choices where the paper is silent:

* Time base: one step is the robot's move to the next cell at its top speed
  (``cell_m / max_speed`` per straight cell); obstacles' Step_scale is their
  speed over the robot's.  The robot senses at each cell it reaches (§5.4: "detects
  environmental information every time it moves a grid"), and while waiting at
  every control step.
* When Eq. (12) fails for every candidate ("too_close") the robot still escapes
  to the best candidate (the paper does not say what to do); the event says so.
* A crossing obstacle that is predicted to miss the robot, or a same-line
  obstacle moving away, is no conflict (type 0) and is not logged.
* Replanning runs ``setup.planner`` when it is ``iaco``, else a default
  :class:`~planners.improved_ant_colony.ImprovedAntColonyPlanner`, on the known
  static world (``setup.map_problem``: the map and the static discs,
  :func:`~controllers.navigators.cell_path.static_grid`) from the escape cell.
* Reach of an obstacle: its radius + the robot's inflation (radius and
  clearance) + ``margin_m``.

Beyond the paper, each a named option off by default (the defaults are the paper's robot; ``docs/navigation.md``
has the figures), what BARN's protocol (Perille et al. 2020: the map unknown, a 0.508 x 0.430 m Jackal at 2 m/s)
needs, :mod:`controllers.navigators.sensed_grid`:

* ``map_updates = "replan"``: the paper plans once on a known static map (Steps 1-2); with the map unknown the
  robot starts with an empty one and drove straight into BARN's cylinders (0.94 of the 50 test worlds
  collided).  When the sensed map republishes a change, the grid is rebuilt; if a cell still to visit is
  blocked, IACO (Step 2) plans again from the robot's cell, at most every ``replan_period_s``; with no path
  the robot stops and retries.
* ``footprint = "box"``: cells blocked by the chassis' inscribed circle (0.215 m) instead of its circumscribed
  one (0.333 m, which closes BARN's 0.75 m passages), every turn on the spot checked against the box
  (``dstar_replan``'s option, :func:`controllers.footprint.guarded_turn`).
* ``drive = "pulled"``: the controller is handed the corners of the cell path (line of sight on the grid),
  not every cell centre: on 5-cm cells the robot turned at nearly every centre (3 m in 26 s on BARN world 1);
  cells are still counted as reached (and Step 3 decided at each) when the robot passes beside them.
* ``max_decel_m_s2``: the forward speed capped to stop before the nearest mapped obstacle ahead and the path's
  next sharp turn (:func:`controllers.footprint.braked`).

Beyond the paper too, for crowds whose people do not see the robot (CrowdNav's circle crossing with the robot
invisible, issue 35; diagnosed on validation cases 500-999 only), each off by default:

* ``turn_in_place_deg``: the heading error above which the run's controller turns on the spot (its own 25
  degrees by default).  With the safety layer's ``evade`` the evasion leaves the robot up to 60 degrees off its
  path; the controller then stopped to turn back, the evasion took over again, and the robot stood turning in
  the crowd, where people walked into it (10 of the 13 collisions of 50 cases had the robot at rest).
* ``wait_guard``: type 1's wait (go to the cell before the crossing point and stop) is taken only when no sensed
  obstacle is predicted to come within reach of the robot standing on that cell within the horizon (the paper
  waits for the one crossing obstacle; the others walked into the waiting robot); else the robot goes on, and a
  wait whose cell becomes unsafe ends.
* ``rejoin_m``: IACO (Step 2) again from the robot's cell when the robot stands further than ``rejoin_m`` from
  its path's next ``horizon_cells`` cells (the evasion took it off; it then drove back to a stale path, or stood
  behind people who had stopped on it) or when a sensed obstacle slower than ``standing_m_s`` stands on them;
  such obstacles' cells are blocked for that plan (their reach plus :data:`STANDING_CLEARANCE_M`), at most every
  ``replan_period_s``.
* ``arc_cap``: the run's controller holds its forward speed to what reaches the active waypoint on an arc at its
  top turn rate (:class:`~controllers.point_to_point.PointToPointController`'s ``arc_cap``).  With
  ``turn_in_place_deg = 60`` the robot drove at up to 0.5 m/s, 1.2 rad/s (a 0.42 m circle) round a corner left
  beside it by the evasion or a replan, never within the controller's 0.05 m, until the time limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from scipy import ndimage

from swarmnav.models.parameters import Range, above, param, within
from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.navigator import DetectedObstacle, NavigationSetup, NavigationStep, Observation
from swarmnav.controllers.navigators.cell_path import (Cell, CellWalker, cells_of_path, grid_problem, heading_of,
                                                       occupied_cells, step_line)
from swarmnav.controllers.navigators.sensed_grid import (FOOTPRINTS, MAP_UPDATES, ChassisGuard, MapWatch,
                                                         free_cell_near, navigator_grid)
from swarmnav.planners.grid_graph import grid_line_of_sight
from swarmnav.controllers.navigators.collision_types import (CATCHING_UP, CROSSING, NO_CONFLICT, Encounter, classify,
                                                             escape_moves, escape_offsets, first_band_index,
                                                             precondition_x_of_moves,
                                                             predicted_meeting_s, timing)
from swarmnav.models.errors import ConfigError
from swarmnav.models.world import OccupancyGrid
from swarmnav.planners.errors import PlanningError
from swarmnav.planners.improved_ant_colony import ImprovedAntColonyPlanner
from swarmnav.planners.problem import Path

STRATEGIES = ("paper", "wait_only")
DRIVES = ("cells", "pulled")
# rejoin_m: a standing obstacle's cells are blocked this much beyond its reach (radius, inflation, margin_m), so
# that the path round it passes outside the evasion's own margin (0.1 m; it held the robot on a path 0.05 m off).
STANDING_CLEARANCE_M = 0.15


@dataclass
class IacoLocalNavigator:
    """Gong et al. (2022)'s global IACO path with local avoidance by collision type.

    Args:
        strategy: "paper" (§4.2's four strategies) or "wait_only" (ref. [24]: type 1's action for every type).
        same_line_deg: largest angle between robot and obstacle directions that counts as one line.
        margin_m: extra distance kept from an obstacle's footprint in the predictions.
        horizon_cells: how many robot steps ahead conflicts are predicted.
        reach_m: distance to a cell's centre at which the robot has reached it.
        lead_steps: robot steps added to the escape's in Eq. (12) (ours; 0 = the paper), for the
            time our differential-drive robot needs to turn in place towards the escape cell,
            which the paper's grid robot does not spend.
        map_updates, footprint, drive, max_decel_m_s2, replan_period_s: beyond the paper, off by default (its
            robot plans once on a known map, a one-cell robot visiting every cell centre); what BARN's protocol
            (map unknown, a box Jackal at 2 m/s) needs: the module docstring's BARN section.
        turn_in_place_deg, wait_guard, rejoin_m, standing_m_s, arc_cap: beyond the paper, off by default (0, False,
            0, -, False; ``standing_m_s`` acts only with ``rejoin_m``): for crowds that do not see the robot, the
            module docstring's last section.
    """

    name: ClassVar[str] = "iaco_local"
    # The safety layer's evasion (controllers.safety_layer, after the step): off by default, not the paper's.
    safety_layer: ClassVar[dict[str, bool]] = {"evade": False}
    # The evasion's options (controllers.evasion), off by default, as dstar_replan offers them (docs/navigation.md).
    safety_layer_options: ClassVar[tuple[str, ...]] = ("evade_still_m_s", "evade_reverse", "evade_turn_cost_m_s_rad")
    uses_detections: ClassVar[bool] = True
    uses_planner: ClassVar[bool] = True
    replan_wall_s: ClassVar[float] = 0.0  # its replanning time is not measured
    strategy: str = param("paper", choices=STRATEGIES)
    same_line_deg: float = param(15.0, Range(0, 90, high_open=True))
    margin_m: float = param(0.05, within(0, 100))
    horizon_cells: int = param(12, within(1, 1000))
    reach_m: float = param(0.1, above(0, 100))
    lead_steps: int = param(0, within(0, 1000))
    map_updates: str = param("none", choices=MAP_UPDATES)
    footprint: str = param("circle", choices=FOOTPRINTS)
    drive: str = param("cells", choices=DRIVES)
    max_decel_m_s2: float = param(0.0, within(0, 1000))
    replan_period_s: float = param(0.5, within(0, 600))
    turn_in_place_deg: float = param(0.0, within(0, 180))
    rejoin_m: float = param(0.0, within(0, 100))
    standing_m_s: float = param(0.1, within(0, 100))
    wait_guard: bool = False
    arc_cap: bool = False
    counts: dict[str, int] = field(default_factory=dict, init=False, repr=False)

    def reset(self, setup: NavigationSetup) -> None:
        self.setup = setup
        problem = setup.map_problem  # static obstacles only: the moving ones are sensed
        self.problem = problem
        self.grid = navigator_grid(setup, self.footprint)
        self.planner = setup.planner if isinstance(setup.planner, ImprovedAntColonyPlanner) \
            else ImprovedAntColonyPlanner()
        self.inflation_m = problem.inflation_m
        self.speed_m_s = setup.max_speed_m_s
        self.step_s = self.grid.cell_m / self.speed_m_s
        start = self.grid.cell_of(problem.start.x_m, problem.start.y_m)
        goal = self.grid.cell_of(problem.goal.x_m, problem.goal.y_m)
        self.goal_cell = goal
        free = ~self.grid.occupied
        self.labels, _ = ndimage.label(free, structure=np.ones((3, 3), dtype=bool))
        replanned = not (setup.path.stats.extra.get("raw_cells") and len(setup.problem.obstacles) == len(problem.obstacles)
                         and isinstance(setup.planner, ImprovedAntColonyPlanner) and self.footprint == "circle")
        if replanned:  # Step 2: the IACO path on the static map (the first plan saw the moving obstacles at t = 0)
            cells = cells_of_path(self.planner.plan(grid_problem(problem, self.grid, start), setup.rng), self.grid)
        else:
            cells = cells_of_path(setup.path, self.grid)
        self.walker = CellWalker(setup.controller, self.grid, self.reach_m, pulled=self.drive == "pulled")
        handed = self.walker.start(cells)
        self._pending_path = handed if replanned else None
        self.wait_index: int | None = None
        self.escape_index: int | None = None  # the escape cell's index while the manoeuvre runs
        self.waiting = False
        self.counts = {"type1": 0, "type2": 0, "type3": 0, "type4": 0, "waits": 0, "escapes": 0, "replans": 0}
        self._first = True
        self.watch = MapWatch(setup)
        self.guard = ChassisGuard(setup, self.footprint, self.max_decel_m_s2)
        self.next_map_replan_s = 0.0
        self.no_path = False  # map_updates: the last replan on the sensed map found no path (the robot holds)
        self.next_rejoin_s = 0.0
        if self.turn_in_place_deg > 0:
            if not hasattr(setup.controller, "turn_in_place_rad"):
                raise ConfigError("navigator.params.turn_in_place_deg",
                                  f"the run's controller ({type(setup.controller).__name__}) has no turn on the spot")
            setup.controller.turn_in_place_rad = math.radians(self.turn_in_place_deg)
        if self.arc_cap:
            if not hasattr(setup.controller, "arc_cap"):
                raise ConfigError("navigator.params.arc_cap",
                                  f"the run's controller ({type(setup.controller).__name__}) has no arc cap")
            setup.controller.arc_cap = True

    # -- beyond the paper: the map built as the robot drives -------------------------------------------
    def step(self, observation: Observation) -> NavigationStep:
        """The paper's step (:meth:`paper_step`), after ``map_updates``' replanning and before ``footprint`` and
        ``max_decel_m_s2``'s checks of its command (all off by default)."""
        events: list[tuple[str, dict[str, Any]]] = []
        replanned = None
        if self.map_updates == "replan" and (self.watch.changed() or self.no_path) \
                and observation.time_s >= self.next_map_replan_s - 1e-9:
            replanned = self._follow_map(observation, events)
        if self.no_path:
            return NavigationStep(ControlCommand.stop(), replanned, tuple(events))
        if self.rejoin_m > 0 and observation.time_s >= self.next_rejoin_s - 1e-9 and not self.waiting \
                and self.escape_index is None and not self.walker.at_end:
            replanned = self._rejoin(observation, events) or replanned
        result = self.paper_step(observation)
        command = self.guard.apply(result.command, observation.pose, self.setup.controller, self.walker.waypoints)
        if replanned is None and not events and command is result.command:
            return result
        return NavigationStep(command, result.new_path or replanned, tuple(events) + result.events)

    def _follow_map(self, observation: Observation, events: list) -> Path | None:
        """The sensed map changed: the grid rebuilt; the path kept if its cells and its corners' lines of sight
        stay free, else IACO (Step 2) again from the robot's cell on the map as now known."""
        self.watch.take()
        self.problem = problem = self.setup.map_problem
        self.grid = self.walker.grid = navigator_grid(self.setup, self.footprint)
        free = ~self.grid.occupied
        self.labels, _ = ndimage.label(free, structure=np.ones((3, 3), dtype=bool))
        rest = self.walker.cells[self.walker.index:]
        if not self.no_path and not any(self.grid.occupied[c] for c in rest):
            if self.drive == "pulled":
                corners = [self.grid.cell_of(x, y) for x, y in self.walker.waypoints]
                free_list = free.tolist()
                if not all(grid_line_of_sight(free_list, a, b) for a, b in zip(corners[1:], corners[2:])):
                    return self.walker.start(self.walker.cells, self.walker.index)
            return None
        self.next_map_replan_s = observation.time_s + self.replan_period_s
        pose = observation.pose
        here = free_cell_near(self.grid.occupied, self.grid.cell_of(pose.x_m, pose.y_m))
        self.counts["replans"] += 1
        try:
            if here is None:
                raise PlanningError("the robot's cells are all blocked")
            path = self.planner.plan(grid_problem(problem, self.grid, here), self.setup.rng)
        except PlanningError as exc:
            if not self.no_path:
                events.append(("replan_failed", {"reason": str(exc)[:120]}))
            self.no_path = True
            return None
        self.no_path = False
        self.escape_index = None
        self.wait_index = None
        self.waiting = False
        events.append(("replan", {"reason": "blocked on the sensed map", "length_m": round(path.stats.length_m, 6)}))
        return self.walker.start(cells_of_path(path, self.grid))

    # -- beyond the paper: back to a path after the evasion, round people standing on it -------------
    def _rejoin(self, observation: Observation, events: list) -> Path | None:
        """``rejoin_m``: IACO (Step 2) again from the robot's cell when the robot stands further than ``rejoin_m``
        from the cells ahead (the evasion took it off its path) or a sensed obstacle slower than ``standing_m_s``
        stands on them; those obstacles' cells are blocked for that plan only."""
        pose = observation.pose
        ahead = self.walker.cells[self.walker.index:self.walker.index + self.horizon_cells + 1]
        centres = self.grid.centres_m(np.array(ahead)).reshape(-1, 2)
        off_m = float(np.min(np.hypot(centres[:, 0] - pose.x_m, centres[:, 1] - pose.y_m)))
        standing = [d for d in observation.detections if math.hypot(d.vx_m_s, d.vy_m_s) < self.standing_m_s]
        blocked = self.grid.occupied
        if standing:
            blocked = blocked | occupied_cells(self.grid, np.array([[d.x_m, d.y_m] for d in standing]),
                                               np.array([self._reach_m(d) + STANDING_CLEARANCE_M for d in standing]))
        on_path = any(blocked[c] for c in ahead[1:])
        if off_m <= self.rejoin_m and not on_path:
            return None
        self.next_rejoin_s = observation.time_s + self.replan_period_s
        here = free_cell_near(blocked, self.grid.cell_of(pose.x_m, pose.y_m))
        grid = OccupancyGrid(blocked, self.grid.cell_m, self.grid.origin_m)
        try:
            if here is None or blocked[self.goal_cell]:
                raise PlanningError("the robot's or the goal's cells are blocked")
            path = self.planner.plan(grid_problem(self.problem, grid, here), self.setup.rng)
        except PlanningError as exc:
            events.append(("rejoin_failed", {"reason": str(exc)[:120]}))
            return None
        self.counts["replans"] += 1
        self.wait_index = None
        self._first = True
        events.append(("rejoin", {"off_path_m": round(off_m, 4), "standing_on_path": on_path,
                                  "length_m": round(path.stats.length_m, 6)}))
        self.walker.grid = grid  # the corners pulled round the standing obstacles too (until the next plan)
        return self.walker.start(cells_of_path(path, grid))

    # -- one control step -------------------------------------------------------------------------
    def paper_step(self, observation: Observation) -> NavigationStep:
        """The paper's step (the safety layer's ``evade``, off by default, acts after it)."""
        events: list[tuple[str, dict[str, Any]]] = []
        new_path, self._pending_path = self._pending_path, None
        if self.waiting:
            if self._conflicts(observation, self.walker.index) and not self._wait_unsafe(observation, self.walker.index):
                # Hold on the wait cell's centre (a stop would leave the robot up to reach_m short).
                centre = self.walker.centre(self.walker.cell)
                self.setup.controller.reset(Path.from_waypoints(np.array([centre, centre]), 0.0))
                return NavigationStep(self.setup.controller.command(observation.pose, observation.twist),
                                      new_path, tuple(events))
            self.waiting = False
            self.wait_index = None
            events.append(("resume", {"cell": list(self.walker.cell)}))
            self.walker.start(self.walker.cells, self.walker.index)
        command, reached = self.walker.command(observation.pose, observation.twist)
        if reached and self.escape_index is not None and self.walker.index >= self.escape_index:
            self.escape_index = None
        if (reached or self._first) and not self.walker.at_end and self.escape_index is None:
            self._first = False
            decided = self._decide(observation, events)
            if decided is not None:
                new_path = decided
                command, _ = self.walker.command(observation.pose, observation.twist)
        if self.wait_index is not None and self.walker.index >= self.wait_index and not self.waiting:
            self.waiting = True
            self.counts["waits"] += 1
            events.append(("wait", {"cell": list(self.walker.cell)}))
        if self.waiting:
            centre = self.walker.centre(self.walker.cell)
            self.setup.controller.reset(Path.from_waypoints(np.array([centre, centre]), 0.0))
            command = self.setup.controller.command(observation.pose, observation.twist)
        return NavigationStep(command, new_path, tuple(events))

    # -- Step 3 -------------------------------------------------------------------------------------
    def _path_xy(self, index: int) -> np.ndarray:
        return self.grid.centres_m(np.array(self.walker.cells[index:index + self.horizon_cells + 1]))

    def _reach_m(self, det: DetectedObstacle) -> float:
        return det.radius_m + self.inflation_m + self.margin_m

    def _conflicts(self, observation: Observation, index: int) -> bool:
        """Would going on now along the path from cell ``index`` meet a sensed obstacle?"""
        path = self._path_xy(index)
        horizon = self.horizon_cells * self.step_s * math.sqrt(2.0)
        return any(predicted_meeting_s(path, self.speed_m_s, (d.x_m, d.y_m), (d.vx_m_s, d.vy_m_s),
                                       self._reach_m(d), horizon) is not None for d in observation.detections)

    def _wait_unsafe(self, observation: Observation, index: int) -> bool:
        """``wait_guard`` (beyond the paper): would a sensed obstacle come within reach of the robot standing on
        cell ``index`` within the horizon?  Always False with the option off (the paper's wait)."""
        if not self.wait_guard:
            return False
        here = self._path_xy(index)[:1]
        horizon = self.horizon_cells * self.step_s * math.sqrt(2.0)
        return any(predicted_meeting_s(here, self.speed_m_s, (d.x_m, d.y_m), (d.vx_m_s, d.vy_m_s), self._reach_m(d),
                                       horizon) is not None for d in observation.detections)

    def _decide(self, observation: Observation, events: list) -> Any:
        """Classify every sensed obstacle at this cell; act on the nearest conflict."""
        index = self.walker.index
        here = self.walker.cell
        heading = heading_of(self.walker.cells, index)
        robot_xy = self.walker.centre(here)
        path = self._path_xy(index)
        horizon = self.horizon_cells * self.step_s * math.sqrt(2.0)
        found = []
        for det in observation.detections:
            xy, v = np.array([det.x_m, det.y_m]), np.array([det.vx_m_s, det.vy_m_s])
            meet = predicted_meeting_s(path, self.speed_m_s, xy, v, self._reach_m(det), horizon)
            enc = classify(robot_xy, heading, xy, v, det.radius_m, self.inflation_m, self.speed_m_s,
                           self.grid.cell_m, meet is not None, math.radians(self.same_line_deg))
            if enc.kind == NO_CONFLICT or (enc.kind != CROSSING and meet is None):
                continue
            found.append((meet, det, enc))
        found.sort(key=lambda item: item[0])
        for meet, det, enc in found:
            self.counts[f"type{enc.kind}"] += 1
            action, extra = self._action(observation, det, enc, path)
            handed = extra.pop("_path", None)
            events.append(("collision_type", {**enc.details(), "track_id": det.track_id, "action": action,
                                              "cell": list(here), **extra}))
            if action == "escape":
                return handed
            if action in ("wait", "go_to_wait"):
                return None
        return None

    def _action(self, observation: Observation, det: DetectedObstacle, enc: Encounter, path: np.ndarray
                ) -> tuple[str, dict[str, Any]]:
        index = self.walker.index
        if self.strategy == "wait_only" or enc.kind == CROSSING:
            band = first_band_index(path, (det.x_m, det.y_m), (det.vx_m_s, det.vy_m_s), self._reach_m(det),
                                    self.horizon_cells * self.step_s * math.sqrt(2.0))
            stop = index + max(0, (band if band is not None else 0) - 1)
            if self._wait_unsafe(observation, stop):
                return "go_on", {"unsafe_wait_cell": list(self.walker.cells[stop])}
            self.wait_index = stop
            return ("wait" if stop == index else "go_to_wait"), {"wait_cell": list(self.walker.cells[stop])}
        if enc.kind == CATCHING_UP:
            rg = math.inf if enc.step_scale <= 0 else 1.0 / enc.step_scale
            if enc.ng > rg:
                return "go_on", {"rg": rg if math.isfinite(rg) else None}
            return self._escape(observation, det, enc, -math.inf)
        heading = heading_of(self.walker.cells, index)
        offsets = escape_offsets(heading, enc.grid_scale)
        xs = [precondition_x_of_moves(escape_moves(heading, o), enc.step_scale, enc.grid_scale, self.lead_steps)
              for o in offsets]
        usable = [x for o, x in zip(offsets, xs) if self._candidate_ok(observation, o, det)]
        if not usable:
            return "no_escape_cell", {}
        when, d = timing(enc.kind, enc.ng, min(usable), enc.step_scale)
        if when == "go_on":
            return "go_on", {"D": d, "X": min(usable)}
        return self._escape(observation, det, enc, enc.ng if when == "act" else -math.inf, too_close=when == "too_close")

    def _candidate_ok(self, observation: Observation, offset: Cell, det: DetectedObstacle | None = None) -> bool:
        here = self.walker.cell
        cell = (here[0] + offset[0], here[1] + offset[1])
        rows, cols = self.grid.shape
        if not (0 <= cell[0] < rows and 0 <= cell[1] < cols):
            return False
        if any(self.grid.occupied[c] for c in step_line(here, cell)[1:]):
            return False
        if self.labels[cell] != self.labels[self.goal_cell]:
            return False
        centre = self.walker.centre(cell)
        if det is not None and math.hypot(det.vx_m_s, det.vy_m_s) > 0:
            # An escape cell lies off the obstacle's track (ours: the paper's obstacles are centred on the robot's line).
            w = np.array([det.vx_m_s, det.vy_m_s]) / math.hypot(det.vx_m_s, det.vy_m_s)
            rel = centre - np.array([det.x_m, det.y_m])
            if abs(rel[0] * w[1] - rel[1] * w[0]) < det.radius_m + self.inflation_m:
                return False
        return all(math.hypot(centre[0] - d.x_m, centre[1] - d.y_m) >= d.radius_m + self.inflation_m
                   for d in observation.detections)

    def _escape(self, observation: Observation, det: DetectedObstacle, enc: Encounter, ng_limit: float, too_close: bool = False
                ) -> tuple[str, dict[str, Any]]:
        """Move to an escape cell (Eqs. 13-14) and replan IACO from each usable one, keeping the shortest."""
        here = self.walker.cell
        heading = heading_of(self.walker.cells, self.walker.index)
        best = None
        tried = 0
        for offset in escape_offsets(heading, enc.grid_scale):
            x = precondition_x_of_moves(escape_moves(heading, offset), enc.step_scale, enc.grid_scale, self.lead_steps)
            # Eq. (12), X <= ng, to within the noise of a sensed Step_scale (0.6 / 0.2 is not exactly 3).
            if not self._candidate_ok(observation, offset, det) or (x > ng_limit + 1e-6 and ng_limit != -math.inf):
                continue
            cell = (here[0] + offset[0], here[1] + offset[1])
            tried += 1
            try:
                path = self.planner.plan(grid_problem(self.problem, self.grid, cell), self.setup.rng)
            except PlanningError:
                continue
            moves = step_line(here, cell)
            length = sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(moves, moves[1:])) \
                * self.grid.cell_m + path.stats.length_m
            if best is None or length < best[0]:
                best = (length, moves + cells_of_path(path, self.grid)[1:], cell)
        if best is None:
            return "no_escape_cell", {"candidates": tried}
        self.counts["escapes"] += 1
        self.counts["replans"] += tried
        handed = self.walker.start(best[1])
        self.wait_index = None
        self.escape_index = len(step_line(here, best[2])) - 1
        return "escape", {"escape_cell": list(best[2]), "candidates": tried, "too_close": too_close,
                          "new_length_m": round(best[0], 4), "_path": handed}
