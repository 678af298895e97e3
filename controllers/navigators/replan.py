"""``replan``: follow the path, and plan again when a sensed obstacle's sweep blocks the way ahead.

After Abdulla & Hadi (2025, §5 and Figs. 9-10): the robot follows the
path its planner found, its 12 sensors watch a range around it (§5.2), and when
an obstacle is detected "the robot decided to deviate from its initial path and
instead used the ABC and GWO algorithms to create new paths".  The paper gives
neither the trigger, nor the planning budget, nor whether obstacle velocities
are used; our choices:

* **Trigger**: a sensed obstacle (``Observation.detections``: in range, or a
  track still coasting) whose footprint, swept along its estimated velocity
  over ``horizon_s`` (:func:`~controllers.prediction.swept_discs`) and grown by
  the robot radius plus ``margin_m``, comes within reach of the path ahead of
  the robot (the next ``lookahead_m`` of it).  Velocities are used.
* **Replanning**: with the run's one configured planner (any registered planner, with the
  parameters and mode the run names, under the run's budget if a study set one, built from
  the same spec as the first plan's planner; the run's generator), from the current pose
  to the goal, on the known map (the static obstacles only: ``NavigationSetup.map_problem``)
  plus the swept discs
  of every sensed obstacle.  A swept disc that would contain the robot's
  current position (an obstacle already close) is shrunk to leave it outside,
  or dropped; likewise for the goal's future sweeps.  But while a sensed
  obstacle's *current* footprint (grown by the inflation) covers the goal,
  the replan fails and the robot waits (a random walker on the goal, or a
  slower obstacle just ahead on it, will leave; driving on runs into it).
  A path the planner returns that is not
  collision-free on that problem counts as a failure (swarm planners return
  their best attempt).
* **Cooldown**: at least ``cooldown_s`` between two replans.
* **No path**: stop, wait ``retry_s``, try again (while waiting, an obstacle
  may still run into the robot: that counts as a collision, as in BARN).
* **Latency**: a new path takes effect ``planning_latency_s`` of simulated time
  after the replan (default 0); meanwhile the robot drives on the old path.
* **Safety layer** (:mod:`controllers.safety_layer`, applied by the stepper after this navigator's step;
  ``safety_layer`` below offers its two switches): the Nav2 "approach" filter (``safety_filter``, off by
  default) and the evasion (``evade``, on by default; ours, beyond the paper, which has no moving obstacle
  that comes at the robot): the velocity-obstacle evasion of :mod:`controllers.evasion` overrides the command
  while a sensed obstacle's predicted time to collision with the robot is below ``evade_trigger_s``.  The sweeps
  this navigator plans around are kept off the robot's own position, so an obstacle coming at it was
  invisible exactly where it mattered: on the dyn300 suite most failures were collisions with crossers faster
  than the robot and walkers, after which the robot reached its goal (``evade = false``: the earlier
  behaviour; the before and after figures are in the README).

**A box chassis** (named options, ours; all off by default, as ``dstar_replan``'s, :mod:`controllers.footprint`):
``footprint = "box"`` replans with :class:`controllers.centred_path.CentredPlanner` on the map's obstacles (and
the sweeps) grown by the chassis' inscribed circle instead of the robot radius (a Jackal's 0.215 m, not its
0.333 m circumscribed circle, which closes BARN's 0.75 m passages), not with the run's planner (which plans
for the robot radius), judges the path blocked on that planner's cells, and checks every turn on the spot
against the box (:func:`controllers.footprint.guarded_turn`); ``cost_weight`` > 0 prices the cells near
obstacles so that paths keep to the middle of passages; ``max_decel_m_s2`` > 0 caps the forward speed to stop
before the path's next sharp turn and before the nearest mapped obstacle ahead (:func:`controllers.footprint.
braked`).  BARN's configuration: ``footprint=box, cost_weight=10, max_decel_m_s2=2`` (docs/barn.md).

Events: ``replan`` (reason, the obstacles' track ids, planning wall time is
not logged: it is not deterministic), ``replan_failed``; the layer's ``evade`` and ``safety_trigger``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace, field
from typing import Any, ClassVar

import numpy as np

from swarmnav.models.parameters import above, param, within
from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.navigator import Belief, DetectedObstacle, NavigationSetup, NavigationStep, Observation
from swarmnav.controllers.prediction import detection_arrays, path_ahead, polyline_gap_m, swept_discs
from swarmnav.controllers.centred_path import CentredPlanner
from swarmnav.controllers.footprint import (block_radius_m, braked, chassis_box_m, chassis_extent_m, free_ahead_m,
                                            guarded_turn)
from swarmnav.controllers.guided import free_start
from swarmnav.models.world import Disc, Pose2D, rasterise
from swarmnav.planners.errors import PlanningError, StartBlocked
from swarmnav.planners.problem import Path, Problem


def keep_outside(discs: list[Disc], points: list[tuple[float, float]], inflation_m: float) -> list[Disc]:
    """Shrink (or drop) discs so that none, grown by ``inflation_m``, contains any of the points."""
    out = []
    hypot = math.hypot
    for d in discs:
        radius = d.radius_m
        for x, y in points:
            room = hypot(d.x_m - x, d.y_m - y) - inflation_m - 1e-3
            if room < radius:  # min(radius, room), without the call
                radius = room
        if radius > 0.02:
            out.append(Disc(d.x_m, d.y_m, radius))
    return out


def sweeps_near(detections: tuple[DetectedObstacle, ...], polyline: np.ndarray, inflation_m: float,
                horizon_s: float) -> tuple[DetectedObstacle, ...]:
    """The detections whose sweep (:func:`~controllers.prediction.swept_discs`: discs of the detection's radius
    centred between its position and where its velocity takes it in ``horizon_s``) may come within ``inflation_m``
    of the polyline: the sweep's bounding box grown by the radius and ``inflation_m`` (and 1 um to spare) meets the
    polyline's.  Every disc of a detection left out keeps more than ``inflation_m`` from the polyline."""
    if not detections:
        return ()
    centres, velocities, radii = detection_arrays(detections)
    ends = centres + velocities * horizon_s
    grow = (radii + inflation_m + 1e-6)[:, None]
    low, high = np.minimum(centres, ends) - grow, np.maximum(centres, ends) + grow
    apart = np.any((low > polyline.max(axis=0)) | (high < polyline.min(axis=0)), axis=1)
    return tuple(d for d, away in zip(detections, apart) if not away)


def endpoint_room_m(known: Problem) -> float:
    """How far a sensed disc's inflated rim is kept from the start and goal: the inflation plus
    1.5 cells, so that grid planners, which block cells whose centres come within the inflation
    plus half a cell diagonal, still find the endpoints' cells free."""
    return known.inflation_m + 1.5 * known.cell_m


def sensed_problem(known: Problem, pose: Pose2D, sensed: list[Disc]) -> Problem:
    """The known map from the current pose, plus the sensed (swept) discs kept off the start and goal."""
    discs = keep_outside(sensed, [(pose.x_m, pose.y_m), (known.goal.x_m, known.goal.y_m)], endpoint_room_m(known))
    start = Pose2D(pose.x_m, pose.y_m, pose.heading_rad)
    problem = replace(known, start=start, obstacles=tuple(known.obstacles) + tuple(discs))
    if known.grid_override is not None and discs:
        # A bare map grid: mark the sensed discs on it as well.
        extra = rasterise(known.bounds, tuple(discs), (), known.inflation_m, known.grid_override.cell_m)
        grid = replace(known.grid_override, occupied=known.grid_override.occupied | extra.occupied)
        problem = replace(problem, grid_override=grid)
    return problem


@dataclass
class ReplanNavigator:
    """Follow, and replan with the run's planner when a sensed sweep blocks the path ahead.

    Args:
        lookahead_m: how much of the path ahead is checked.
        horizon_s: how far obstacles are predicted (swept) along their estimated velocity.
        margin_m: extra distance kept beyond the robot radius in the trigger.
        cooldown_s: least simulated time between two replans.
        retry_s: wait after a failed replan before trying again (stopped meanwhile).
        planning_latency_s: simulated time before a new path takes effect.
        footprint: ``"circle"`` (the run's planner, for the robot radius) or ``"box"`` (replans for the chassis'
            inscribed circle by the centred planner, turns on the spot checked against the box).
        cost_weight: with ``footprint = "box"``, the replans' penalty on cells near obstacles (0: none).
        cost_reach_m: how far from a blocked cell the penalty reaches.
        max_decel_m_s2: the braking the forward speed is capped by (0: no cap).
    """

    name: ClassVar[str] = "replan"
    safety_layer: ClassVar[dict[str, bool]] = {"safety_filter": False, "evade": True}  # controllers.safety_layer
    uses_detections: ClassVar[bool] = True
    uses_planner: ClassVar[bool] = True
    replan_wall_s: float = field(default=0.0, init=False, repr=False)

    lookahead_m: float = param(2.5, above(0, 1000))
    horizon_s: float = param(6.0, above(0, 600))
    margin_m: float = param(0.05, within(0, 100))
    cooldown_s: float = param(0.5, within(0, 1e6))
    retry_s: float = param(0.5, above(0, 1e6))
    planning_latency_s: float = param(0.0, within(0, 1e6))
    footprint: str = param("circle", choices=("circle", "box"))
    cost_weight: float = param(0.0, within(0, 1000))
    cost_reach_m: float = param(0.3, above(0, 100))
    max_decel_m_s2: float = param(0.0, within(0, 1000))

    @property
    def known(self) -> Problem:
        """The map it plans on (``NavigationSetup.map_problem``: the known map, or the sensed map's latest)."""
        return self.setup.map_problem

    def reset(self, setup: NavigationSetup) -> None:
        self.setup = setup
        self.checked_revision = setup.map_revision
        self.controller = setup.controller
        self.path = setup.path
        self.controller.reset(setup.path)
        self.next_replan_s = 0.0
        self.pending: tuple[float, Path] | None = None
        self.waiting_until_s: float | None = None
        self.replan_wall_s = 0.0
        self.centred = None
        if self.footprint == "box":
            self.centred = CentredPlanner(block_radius_m(setup) + setup.map_problem.clearance_m, self.cost_weight,
                                          self.cost_reach_m)
        self.front_m, self.half_width_m = chassis_extent_m(setup)
        self.box_m, self.turn_sign = chassis_box_m(setup), 0.0

    # -- the step ------------------------------------------------------------
    def step(self, observation: Observation) -> NavigationStep:
        t = observation.time_s
        events: list[tuple[str, dict[str, Any]]] = []
        new_path = None
        if self.pending is not None and t >= self.pending[0] - 1e-9:
            new_path = self._adopt(self.pending[1])
            self.pending = None
        if self.waiting_until_s is not None:
            if t < self.waiting_until_s - 1e-9:
                return self._finish(observation, ControlCommand.stop(self.controller.waypoint_index), events, None)
            reason = "retry"
        else:
            reason = self.blocked(observation)
        if reason and t >= self.next_replan_s - 1e-9 and self.pending is None:
            planned = self._replan(observation, reason, events)
            if planned is None:
                self.waiting_until_s = t + self.retry_s
                return self._finish(observation, ControlCommand.stop(self.controller.waypoint_index), events,
                                    new_path)
            self.waiting_until_s = None
            if self.planning_latency_s > 0:
                self.pending = (t + self.planning_latency_s, planned)
            else:
                new_path = self._adopt(planned)
        elif reason == "retry":
            self.waiting_until_s = None
        command = self.controller.command(observation.pose, observation.twist)
        if self.max_decel_m_s2 > 0:
            waypoints = [(float(x), float(y)) for x, y in self.path.waypoints]
            ahead_m = free_ahead_m(self.known, observation.pose, self.front_m, self.half_width_m)
            command = braked(command, observation.pose, self.controller, waypoints, self.max_decel_m_s2, ahead_m)
        if self.footprint == "box":
            command, self.turn_sign = guarded_turn(command, observation.pose, self.controller, self.known, self.box_m,
                                                   self.turn_sign)
        return self._finish(observation, command, events, new_path)

    def blocked(self, observation: Observation) -> str:
        """A reason to replan ("blocked by sensed obstacle", "blocked on the sensed map") or ""."""
        pose = observation.pose
        if self.centred is not None and self.setup.map_revision != self.checked_revision:
            return "the sensed map changed"  # footprint = "box": replanned at every change (kept until it is)
        if self.setup.map_revision != self.checked_revision:  # the sensed map changed (never with a known map)
            self.checked_revision = self.setup.map_revision
            rest = path_ahead(pose, self.path.waypoints, self.controller.waypoint_index, math.inf)
            if self.setup.world_map.blocks(rest):
                return "blocked on the sensed map"
        if not observation.detections:
            return ""
        ahead = path_ahead(pose, self.path.waypoints, self.controller.waypoint_index, self.lookahead_m)
        inflation = (self.known.robot_radius_m if self.centred is None else self.centred.block_m) + self.margin_m
        near = sweeps_near(observation.detections, ahead, inflation, self.horizon_s)
        if not near:  # no sweep comes near the path ahead (the same verdict as sweeping them all)
            return ""
        sweeps = swept_discs(near, self.horizon_s)
        # keep_outside below only shrinks or drops discs, and each disc's gap is its own distance minus its grown
        # radius (monotone in the radius, rounding included): sweeps that leave the path ahead free at full size
        # leave it free after, so the common case is decided without it (the same verdict).
        if polyline_gap_m(ahead, sweeps, inflation) >= 0.0:
            return ""
        # The same discs a replan would plan around (kept off the robot), so a fresh path is not blocked at once.
        sweeps = keep_outside(sweeps, [(pose.x_m, pose.y_m)], endpoint_room_m(self.known))
        return "blocked by sensed obstacle" if polyline_gap_m(ahead, sweeps, inflation) < 0.0 else ""

    # -- helpers -------------------------------------------------------------
    def _replan(self, observation: Observation, reason: str, events: list) -> Path | None:
        t = observation.time_s
        self.next_replan_s = t + self.cooldown_s
        if self.centred is not None:
            self.checked_revision = self.setup.map_revision
        problem = sensed_problem(self.setup.plan_problem, observation.pose,
                                 swept_discs(observation.detections, self.horizon_s))
        wall0 = time.perf_counter()
        goal = self.setup.goal
        on_goal = [d.track_id for d in observation.detections
                   if math.hypot(d.x_m - goal.x_m, d.y_m - goal.y_m) < d.radius_m + self.known.inflation_m]
        try:
            if on_goal:
                raise PlanningError(f"the goal is inside sensed obstacle(s) {on_goal}: wait for it to leave")
            if self.centred is not None:
                path, why = self._centred_path(problem, observation.pose), ""
            else:
                path, why = self._planned_path(problem)
        except PlanningError as exc:
            path, why = None, f"{type(exc).__name__}: {exc}"
        self.replan_wall_s += time.perf_counter() - wall0
        tracks = [d.track_id for d in observation.detections]
        if why:
            events.append(("replan_failed", {"reason": reason, "why": why, "tracks": tracks}))
            return None
        events.append(("replan", {"reason": reason, "tracks": tracks, "length_m": round(path.stats.length_m, 6),
                                  "takes_effect_s": round(t + self.planning_latency_s, 6)}))
        return path

    def _planned_path(self, problem: Problem) -> tuple[Path, str]:
        """The run's planner's path on ``problem`` and why it is refused ("" if it is not)."""
        try:
            path = self.setup.planner.plan(problem, self.setup.rng)
        except StartBlocked:
            # The robot has cut within the clearance of a known obstacle: plan with no clearance
            # (and, on a sensed map, whose cells are coarser than the obstacles, from the nearest free point).
            problem = replace(problem, clearance_m=0.0) if self.setup.world_map is None else free_start(problem)
            path = self.setup.planner.plan(problem, self.setup.rng)
        ok = problem.is_collision_free(path.waypoints, tolerance_m=1e-6)
        return path, "" if ok else "the planner's path is not collision-free"

    def _centred_path(self, problem: Problem, pose: Pose2D) -> Path:
        """``footprint = "box"``: the centred planner's path on the map (the sensed map's own cells, not the
        planners' grown ones) plus the sweeps of ``problem``."""
        known = self.known
        sweeps = problem.obstacles[len(self.setup.plan_problem.obstacles):]
        on_map = replace(known, obstacles=tuple(known.obstacles) + tuple(sweeps)) if sweeps else known
        return Path.from_waypoints(self.centred.plan(on_map, (pose.x_m, pose.y_m)), 0.0)

    def _adopt(self, path: Path) -> Path:
        self.path = path
        self.controller.reset(path)
        return path

    def _finish(self, observation: Observation, command: ControlCommand, events: list,
                new_path: Path | None) -> NavigationStep:
        return NavigationStep(command, new_path, tuple(events), Belief(observation.detections, self.horizon_s))
