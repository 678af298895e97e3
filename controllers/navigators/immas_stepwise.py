"""``immas_stepwise``: IMMAS's robot walking among random-walk obstacles, Hasan, Abdullah & Saleh (2023).

Algorithm 1 (pheromone propagation from the goal, clean weights, gate raising,
tight-tunnel closing; :func:`planners.pheromone_propagation.analyse_environment`)
runs once before the robot moves.  Then Algorithm 3 walks the robot cell by
cell: at each step the dynamic obstacles move (UpdateDynObs, line 10; the
scenario's ``random_walk`` motion), the neighbours an obstacle occupies
("Dobstacle", line 12) are excluded, and the next cell is the neighbour with the
smallest value of Eq. (3)'s numerator ``(tau + clean)^alpha * eta^beta`` (lines
13-20), alpha = 3 and beta = 1 (line 4).  When an obstacle moves onto the
robot's next cell, the robot moves instead to the neighbour with the least
chance of contact (§4.1, Fig. 3-b).  No replanning, as the paper.  Each move adds
the new cell's route cost k to the total arc cost (line 25).

Our choices where the paper is silent or ambiguous:

* Minimum, not maximum: the pseudo-code keeps the smallest P (lines 14-20) and the
  prose the "optimal" one; with tau the propagated route cost (it grows away from the
  goal), clean a penalty near walls and eta a distance, the smallest value is the
  optimal one, so both agree (the same reading as the ``immas`` planner).
* As in the ``immas`` planner the robot does not re-enter a cell while an unvisited
  candidate is left; otherwise it may (the planner follows the propagation tree,
  which a dynamic obstacle may block).
* "Least chance of contact": the free neighbour with the fewest obstacle-occupied
  cells among its own 8 neighbours (cells an obstacle could step onto next), ties
  broken by Eq. (3).  With no free neighbour the robot stays.
* An obstacle occupies the cells whose centres lie within its radius plus the
  robot's inflation (radius and clearance) of its centre: where the robot, on that
  cell's centre, would touch it.
* In the closed loop (continuous time) the robot decides at each cell it reaches,
  from the sensed obstacles now and along their velocities up to their next node
  (a walker turns there; :func:`time_to_next_node_s`), and diverts while moving if
  an obstacle comes onto its target cell.

Time base and collisions (measured on ``immas-dynamic-10x10``, world seeds 0-19):
the paper's loop moves the obstacles once per robot move and checks cells only.
Our differential-drive robot needs 2.7 s at least and 3.6 s in the median per
cell move (it decelerates into each cell and turns in place), so walkers with a
2-s period moved ~1.8 times per robot move (4 of 20 runs clean, 67 collisions);
the scenarios therefore give their walkers the robot's measured step, 3.5 s (10
of 20 clean, 26 collisions).  The collisions left are the paper's model: its
random walkers do not see the robot and may step onto its cell, or cross its
move, while it turns or waits, and the robot has no rule for that (no replanning).

Beyond the paper, each a named option off by default (the defaults are the paper's robot): ``evade``
(the safety layer's evasion, :mod:`controllers.safety_layer`), ``lookahead_cells`` and ``carrot_m`` (drive
through the walk instead of stopping at each cell, :mod:`controllers.navigators.immas_drive`) and ``predict_s`` (a longer Dobstacle for that walk);
the next cell stays Eq. (3)'s choice at every cell reached.  The class docstring says why, with figures.
For BARN's protocol (the map unknown, a box Jackal; :mod:`controllers.navigators.sensed_grid`), also off by
default: ``map_updates`` (Algorithm 1 again on the sensed map when it changes: the paper analyses a known map
once, and with the empty map it starts with the robot drove into BARN's cylinders), ``footprint`` and
``max_decel_m_s2`` (``dstar_replan``'s box chassis and speed cap).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable, ClassVar, Iterable

import numpy as np

from swarmnav.models.parameters import above, param, within
from swarmnav.controllers.navigator import NavigationSetup, NavigationStep, Observation
from swarmnav.controllers.navigators.cell_path import MOVES, Cell, CellWalker, occupied_cells
from swarmnav.controllers.navigators.immas_drive import DriveThrough, WalkTally
from swarmnav.controllers.navigators.sensed_grid import (FOOTPRINTS, MAP_UPDATES, ChassisGuard, MapWatch,
                                                         free_cell_near, navigator_grid)
from swarmnav.planners.errors import PlanningError
from swarmnav.models.errors import ConfigError
from swarmnav.models.world import OccupancyGrid
from swarmnav.planners.improved_max_min_ant_system import ImprovedMaxMinAntSystemPlanner, tour_scores
from swarmnav.planners.pheromone_propagation import EnvironmentAnalysis, analyse_environment


def time_to_next_node_s(grid: OccupancyGrid, centres_m: np.ndarray, velocities_m_s: np.ndarray,
                        default_s: float) -> np.ndarray:
    """(N,) time until each obstacle, moving along its velocity, is on a cell centre again.

    The random walkers of map scenarios step from cell centre to cell centre (the
    ``grid`` walk); along each moving axis the next centre ahead is found, and the
    latest of the axes is taken (a diagonal step reaches both at once).  An obstacle
    at rest gives 0; one whose next centre is further than ``default_s`` away (not a
    grid walker) gives ``default_s``.
    """
    xy = np.asarray(centres_m, dtype=float).reshape(-1, 2)
    v = np.asarray(velocities_m_s, dtype=float).reshape(-1, 2)
    k = (xy - np.asarray(grid.origin_m)) / grid.cell_m - 0.5            # cell-centre coordinates
    eps = 1e-3
    ahead = np.where(v > 0, np.floor(k + eps) + 1.0, np.ceil(k - eps) - 1.0)
    moving = np.abs(v) > 1e-9
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(moving, (ahead - k) * grid.cell_m / np.where(moving, v, 1.0), 0.0)
    return np.minimum(t.max(axis=1), default_s)


@dataclass
class StepwiseWalk:
    """Algorithm 3's choice of the next cell on the result of Algorithm 1."""

    analysis: EnvironmentAnalysis
    goal: Cell
    alpha: float = 3.0
    beta: float = 1.0

    def __post_init__(self) -> None:
        rows, cols = self.analysis.blocked.shape
        rr, cc = np.mgrid[0:rows, 0:cols]
        self.eta = np.hypot(rr - self.goal[0], cc - self.goal[1])

    def neighbours(self, here: Cell, dynamic: np.ndarray) -> list[Cell]:
        """Free neighbours: not an obstacle, not a Dobstacle, no corner cut, reached by the propagation."""
        a = self.analysis
        rows, cols = a.blocked.shape
        r, c = here
        out = []
        for dr, dc in MOVES:
            yr, yc = r + dr, c + dc
            if not (0 <= yr < rows and 0 <= yc < cols) or a.blocked[yr, yc] or dynamic[yr, yc]:
                continue
            if dr and dc and (a.blocked[r, yc] or a.blocked[yr, c]):
                continue
            if math.isfinite(a.route_cost[yr, yc]):
                out.append((yr, yc))
        return out

    def scores(self, cells: list[Cell]) -> np.ndarray:
        idx = np.array(cells)
        a = self.analysis
        return tour_scores(a.pheromone[idx[:, 0], idx[:, 1]], a.clean[idx[:, 0], idx[:, 1]],
                           self.eta[idx[:, 0], idx[:, 1]], self.alpha, self.beta)

    def choose(self, here: Cell, visited: np.ndarray, dynamic: np.ndarray) -> Cell | None:
        """Lines 11-20: the free neighbour with the smallest Eq. (3) value (unvisited ones first)."""
        free = self.neighbours(here, dynamic)
        fresh = [cell for cell in free if not visited[cell]]
        pool = fresh or free
        if not pool:
            return None
        return pool[int(np.argmin(self.scores(pool)))]

    def divert(self, here: Cell, dynamic: np.ndarray) -> Cell | None:
        """§4.1: the free neighbour with the least chance of contact, ties by Eq. (3)."""
        free = self.neighbours(here, dynamic)
        if not free:
            return None
        padded = np.pad(dynamic.astype(np.int64), 1)
        contact = np.array([padded[r:r + 3, c:c + 3].sum() for r, c in free])
        scores = self.scores(free)
        order = np.lexsort((scores, contact))
        return free[int(order[0])]


@dataclass
class WalkResult:
    """A grid-level run of Algorithm 3 among moving obstacles: the paper's figures."""

    cells: list[Cell]
    moves: int
    total_arc_cost: float
    diverts: int
    stays: int
    reached: bool
    time_s: float
    obstacle_cells: list[np.ndarray] = field(repr=False, default_factory=list)


def stepwise_walk(walk: StepwiseWalk, start: Cell, dynamic_at: Callable[[int], np.ndarray],
                  max_moves: int) -> WalkResult:
    """Algorithm 3 on the grid: at step k the robot is at ``cells[k]`` and the obstacles occupy ``dynamic_at(k)``.

    Each step: choose the next cell among the neighbours free at step k; the
    obstacles move (step k + 1); if one is now on the chosen cell, divert (§4.1);
    move.  Time is the wall time of the walk (Algorithm 1 not included).
    """
    t0 = time.perf_counter()
    shape = walk.analysis.blocked.shape
    visited = np.zeros(shape, dtype=bool)
    visited[start] = True
    cells = [start]
    cost = 0.0
    diverts = stays = 0
    occupied = [dynamic_at(0)]
    here = start
    for k in range(max_moves):
        if here == walk.goal:
            break
        nxt = walk.choose(here, visited, occupied[k])
        occupied.append(dynamic_at(k + 1))
        if nxt is None or occupied[k + 1][nxt]:
            nxt = walk.divert(here, occupied[k + 1])
            diverts += nxt is not None
        if nxt is None:
            stays += 1
            nxt = here
        else:
            cost += float(walk.analysis.route_cost[nxt])
        here = nxt
        visited[here] = True
        cells.append(here)
    return WalkResult(cells, len(cells) - 1 - stays, cost, diverts, stays, here == walk.goal,
                      time.perf_counter() - t0, occupied)


@dataclass
class ImmasStepwiseNavigator:
    """Hasan et al. (2023)'s robot: Algorithm 1 once, then Algorithm 3 cell by cell among moving obstacles.

    Args:
        alpha, beta: Eq. (3)'s weights; None takes the scenario's ``immas`` planner's, else 3 and 1 (line 4).
        reach_m: distance to a cell's centre at which the robot has reached it.
        lookahead_cells, carrot_m: beyond the paper, off by default (0: the paper's robot, which stops at
            each cell): drive through the walk, the next cell still Eq. (3)'s choice at each cell reached,
            the controller steering at a carrot ``carrot_m`` along the walk carried on ``lookahead_cells``
            cells ahead (:mod:`controllers.navigators.immas_drive`, which says why: stopping at every cell
            made most of its dyn300 runs time out).  With ``evade``, dyn300's 55-scene sample (5 a group):
            0.31 solved without it, 0.87 with ``lookahead_cells = 6``.
        predict_s: beyond the paper, off by default (0: the paper's Dobstacle, the obstacles' cells now and
            on their way to their next node, at most one cell move ahead); with ``lookahead_cells`` only: the
            cells each sensed obstacle sweeps along its velocity over ``predict_s`` (sampled every cell move,
            no node cap) are the decision's Dobstacle.  Why: on dyn300's 0.1-m cells the next node is at most
            0.5 s ahead, so the walk, driven at top speed, went into the path of crossers twice the robot's
            speed and left the rest to ``evade`` (2 of the 5 ``fast2`` scenes of the 55-scene sample collided;
            with ``predict_s = 1`` none, and 0.87 -> 0.93 solved over the 55).
        map_updates, footprint, max_decel_m_s2, replan_period_s: beyond the paper, off by default (its robot
            analyses a known map once, a one-cell robot): ``map_updates = "replan"`` runs Algorithm 1 again on
            the sensed map (map unknown) from the robot's cell when it has changed, at most every
            ``replan_period_s``; ``footprint = "box"`` blocks cells by the chassis' inscribed circle and checks
            turns on the spot against the box; ``max_decel_m_s2`` caps the speed to stop before the mapped
            obstacles ahead (:mod:`controllers.navigators.sensed_grid`, after ``dstar_replan``'s options).
    """

    name: ClassVar[str] = "immas_stepwise"
    # The safety layer's evasion (controllers.safety_layer, after the step): off by default, not the paper's.
    safety_layer: ClassVar[dict[str, bool]] = {"evade": False}
    # The evasion's options (controllers.evasion), off by default, as dstar_replan offers them (docs/navigation.md).
    safety_layer_options: ClassVar[tuple[str, ...]] = ("evade_still_m_s", "evade_reverse", "evade_turn_cost_m_s_rad")
    uses_detections: ClassVar[bool] = True
    uses_planner: ClassVar[bool] = True
    replan_wall_s: ClassVar[float] = 0.0  # its replanning time is not measured
    alpha: float | None = param(None, within(0, 100))
    beta: float | None = param(None, within(0, 100))
    reach_m: float = param(0.1, above(0, 100))
    lookahead_cells: int = param(0, within(0, 1000))
    carrot_m: float = param(0.4, above(0, 100))
    predict_s: float = param(0.0, within(0, 600))
    map_updates: str = param("none", choices=MAP_UPDATES)
    footprint: str = param("circle", choices=FOOTPRINTS)
    max_decel_m_s2: float = param(0.0, within(0, 1000))
    replan_period_s: float = param(0.5, within(0, 600))

    def __post_init__(self) -> None:
        if self.predict_s and not self.lookahead_cells > 0:  # a rule between two fields (each one's range: param)
            raise ConfigError("navigator.params.predict_s", "needs lookahead_cells > 0 (it changes the walk driven "
                                                            f"through), got {self.predict_s!r}")

    def reset(self, setup: NavigationSetup) -> None:
        problem = setup.map_problem  # static obstacles only: the moving ones are sensed
        self.setup = setup
        self.grid = grid = navigator_grid(setup, self.footprint)
        given = isinstance(setup.planner, ImprovedMaxMinAntSystemPlanner)
        self.planner = planner = setup.planner if given else ImprovedMaxMinAntSystemPlanner()
        alpha = planner.alpha if self.alpha is None and given else (3.0 if self.alpha is None else self.alpha)
        beta = planner.beta if self.beta is None and given else (1.0 if self.beta is None else self.beta)
        start = grid.cell_of(problem.start.x_m, problem.start.y_m)
        goal = grid.cell_of(problem.goal.x_m, problem.goal.y_m)
        t0 = time.perf_counter()
        analysis = planner.analyse(grid.occupied, start, goal)
        self.analysis_time_s = time.perf_counter() - t0
        self.walk = StepwiseWalk(analysis, goal, alpha, beta)
        self.walker = CellWalker(setup.controller, grid, self.reach_m)
        self.walker.start([start])
        self.tally = WalkTally(np.zeros(grid.shape, dtype=bool), analysis.route_cost)
        self.tally.visited[start] = True
        self.visited = self.tally.visited
        self.inflation_m = problem.inflation_m
        self.step_s = grid.cell_m / setup.max_speed_m_s
        self.target: Cell | None = None
        self._diverted = False
        self._started = False
        self._reached_unhandled = False  # a cell reached inside a step that then started a new move
        self.drive = (DriveThrough(self.walk, grid, setup.controller, self.lookahead_cells, self.carrot_m, start,
                                   self.tally, self.predict_s > 0)
                      if self.lookahead_cells > 0 else None)
        self.watch = MapWatch(setup)
        self.guard = ChassisGuard(setup, self.footprint, self.max_decel_m_s2)
        self.next_analysis_s = 0.0
        self.analyses = 1

    def _dynamic(self, observation: Observation, ahead_s: Iterable[float]) -> np.ndarray:
        """Cells an obstacle occupies now and (``ahead_s`` > 0) on its way to its next node.

        Time base (the fix of this module's first version, which extrapolated every sensed
        velocity over a whole robot step): a random walker changes direction at each of
        its nodes, so it is predicted along its current velocity only up to its next node
        (:func:`time_to_next_node_s`), never past it; the cells it sweeps on the way are
        Algorithm 3's "Dobstacle" for the robot's step (lines 10-12 with UpdateDynObs seen).
        """
        dets = observation.detections
        if not dets:
            return np.zeros(self.grid.shape, dtype=bool)
        xy = np.array([[d.x_m, d.y_m] for d in dets])
        v = np.array([[d.vx_m_s, d.vy_m_s] for d in dets])
        reach = np.array([d.radius_m for d in dets]) + self.inflation_m
        limit = time_to_next_node_s(self.grid, xy, v, self.step_s)
        out = np.zeros(self.grid.shape, dtype=bool)
        for t in ahead_s:
            out |= occupied_cells(self.grid, xy + np.minimum(t, limit)[:, None] * v, reach)
        return out

    def _swept(self, observation: Observation, horizon_s: float) -> np.ndarray:
        """``predict_s`` > 0 (beyond the paper): the cells the sensed obstacles sweep along their velocities
        over ``horizon_s`` (sampled every cell move), no node cap."""
        dets = observation.detections
        out = np.zeros(self.grid.shape, dtype=bool)
        if not dets:
            return out
        xy = np.array([[d.x_m, d.y_m] for d in dets])
        v = np.array([[d.vx_m_s, d.vy_m_s] for d in dets])
        reach = np.array([d.radius_m for d in dets]) + self.inflation_m
        for t in np.append(np.arange(0.0, horizon_s, self.step_s), horizon_s):
            out |= occupied_cells(self.grid, xy + t * v, reach)
        return out

    def _go(self, here: Cell, target: Cell) -> Any:
        self.target = target
        return self.walker.start([here, target])

    def step(self, observation: Observation) -> NavigationStep:
        """The paper's step, or driving through the walk (the safety layer's ``evade``, off by default,
        acts after it); ``map_updates`` before it and the ``footprint`` and ``max_decel_m_s2`` checks of its
        command after it (all off by default)."""
        events: tuple = ()
        if self.map_updates == "replan" and self.watch.changed() and observation.time_s >= self.next_analysis_s - 1e-9:
            events = self._follow_map(observation)
        result = self._paper_step(observation) if self.drive is None else self._drive_step(observation)
        if not self.guard.active and not events:
            return result
        waypoints = self.walker.waypoints if self.drive is None else []
        command = self.guard.apply(result.command, observation.pose, self.setup.controller, waypoints)
        return NavigationStep(command, result.new_path, events + result.events)

    def _follow_map(self, observation: Observation) -> tuple:
        """The sensed map changed: Algorithm 1 again on it, from the robot's cell (beyond the paper)."""
        self.watch.take()
        self.next_analysis_s = observation.time_s + self.replan_period_s
        grid = navigator_grid(self.setup, self.footprint)
        pose = observation.pose
        here = free_cell_near(grid.occupied, grid.cell_of(pose.x_m, pose.y_m))
        try:
            if here is None:
                raise PlanningError("the robot's cells are all blocked")
            analysis = self.planner.analyse(grid.occupied, here, self.walk.goal)
        except PlanningError as exc:
            return (("replan_failed", {"reason": str(exc)[:120]}),)
        self.analyses += 1
        self.grid = self.walker.grid = grid
        self.walk = StepwiseWalk(analysis, self.walk.goal, self.walk.alpha, self.walk.beta)
        self.tally.route_cost = analysis.route_cost
        if self.drive is not None:
            self.drive.walk, self.drive.grid = self.walk, grid
            if self.drive.cells:  # the walk ahead chosen again from where the robot stands, on the new field
                self.drive.cells, self.drive.centres_m = self.drive.cells[:1], self.drive.centres_m[:1].copy()
        return (("replan", {"reason": "the sensed map changed", "analyses": self.analyses}),)

    def _drive_step(self, observation: Observation) -> NavigationStep:
        """``lookahead_cells`` > 0: driving through the walk (:class:`~controllers.navigators.immas_drive.DriveThrough`)."""
        command, new_path, events = self.drive.step(
            observation.pose, observation.twist,
            lambda kind: self._swept(observation, self.predict_s) if kind == "decision" and self.predict_s
            else self._dynamic(observation, (0.0,) if kind == "now" else (0.0, self.step_s)))
        return NavigationStep(command, new_path, tuple(events))

    def _paper_step(self, observation: Observation) -> NavigationStep:
        events: list[tuple[str, dict[str, Any]]] = []
        new_path = None
        command, reached = self.walker.command(observation.pose, observation.twist)
        reached, self._reached_unhandled = reached or self._reached_unhandled, False
        if reached or not self._started:
            if self._started:
                events.append(self.tally.move(self.walker.cell, self._diverted))
            self._started = True
            self._diverted = False
            here = self.walker.cell
            if here != self.walk.goal:
                nxt = self.walk.choose(here, self.visited, self._dynamic(observation, (0.0, self.step_s)))
                if nxt is not None:
                    new_path = self._go(here, nxt)
                    command, self._reached_unhandled = self.walker.command(observation.pose, observation.twist)
                else:
                    self.walker.start([here])
                    command, _ = self.walker.command(observation.pose, observation.twist)
        elif self.target is not None and not self._diverted and self._dynamic(observation, (0.0,))[self.target]:
            here = self.walker.cells[0]
            other = self.walk.divert(here, self._dynamic(observation, (0.0, self.step_s)))
            self._diverted = True
            self.tally.diverts += 1
            events.append(("immas_divert", {"from": list(here), "blocked": list(self.target),
                                            "to": None if other is None else list(other)}))
            new_path = self._go(here, other if other is not None else here)
            # A divert onto a cell the robot already stands within reach_m of is reached at once: the next
            # step decides from it (the walker reports a cell reached once; losing that report froze the walk)
            command, self._reached_unhandled = self.walker.command(observation.pose, observation.twist)
        return NavigationStep(command, new_path, tuple(events))
