"""The navigator seam: between the sensors and the controller, one call per control step.

A navigator is reset once with a :class:`NavigationSetup` (the path planned at
t = 0, the known map, the planner and its generator, the controller and the
goal checker), then receives an :class:`Observation` every control step and
returns a :class:`NavigationStep`: the wheel command, optionally a new path
(which the runner logs and draws), and events (replans, stops) to log.  No
MuJoCo type crosses this seam: the simulation converts its sensors into plain
arrays first.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

import numpy as np

from swarmnav.controllers.controller import ControlCommand, Controller, Twist
from swarmnav.controllers.goal import GoalChecker
from swarmnav.models.scenario import Scenario
from swarmnav.models.world import Pose2D
from swarmnav.planners.problem import Path, Planner, Problem


@dataclass(frozen=True)
class DetectedObstacle:
    """A moving obstacle as the robot's sensing reports it (never the true future).

    With the ``detector`` sensing model these are exact within the range; with
    ``rangefinder`` they are a tracker's estimates from the rays' hits.

    Attributes:
        x_m, y_m: centre in the world.
        radius_m: footprint radius (an estimate or a lower bound for the rangefinder tracker).
        vx_m_s, vy_m_s: velocity in the world.
        track_id: a stable id while the obstacle stays sensed.
    """

    x_m: float
    y_m: float
    radius_m: float
    vx_m_s: float = 0.0
    vy_m_s: float = 0.0
    track_id: int = -1


@dataclass(frozen=True, eq=False, init=False)
class Observation:
    """What the robot senses at one control step.

    Attributes:
        time_s: simulation time.
        pose: the base pose (x, y, heading) in the world.
        twist: the measured forward speed and turn rate.
        ranges_m: (K,) rangefinder distances from each sensor site on the rim;
            ``inf`` where nothing is in range.
        range_angles_rad: (K,) beam directions in the base frame, CCW from +x.
        range_offset_m: distance of the sensor sites from the base's centre.
        detections: moving obstacles as sensed: exact within range with the ``detector``
            sensing model, the tracker's estimates from the rays' unknown hits with
            ``rangefinder`` (both computed in ``sim/runtime/detector.py``).
        range_cutoff_m: the rangefinders' reach (``inf``: unknown).
    """

    time_s: float
    pose: Pose2D
    twist: Twist
    ranges_m: np.ndarray
    range_angles_rad: np.ndarray
    range_offset_m: float
    detections: tuple[DetectedObstacle, ...] = ()
    range_cutoff_m: float = math.inf

    def __init__(self, time_s: float, pose: Pose2D, twist: Twist, ranges_m: np.ndarray,
                 range_angles_rad: np.ndarray, range_offset_m: float, detections: tuple[DetectedObstacle, ...] = (),
                 range_cutoff_m: float = math.inf):
        # One built every control step: the fields go straight into the instance's dict, once (the
        # generated frozen __init__ sets each through object.__setattr__, four times the cost).
        # Still frozen: assigning a field afterwards raises FrozenInstanceError.
        self.__dict__.update(time_s=time_s, pose=pose, twist=twist, ranges_m=ranges_m,
                             range_angles_rad=range_angles_rad, range_offset_m=range_offset_m,
                             detections=detections, range_cutoff_m=range_cutoff_m)


@dataclass(frozen=True, eq=False)
class NavigationSetup:
    """What a navigator is given before the first step.

    Attributes:
        path: the path planned at t = 0 on ``problem``.
        problem: the planning problem the first path was planned on.
        planner: the run's planner (the one that planned ``path``), for navigators that declare
            ``uses_planner``; None for the others.
        rng: the generator of the run's ``seed`` (planner and navigator randomness).
        controller: turns a path into wheel speeds.
        goal: the goal checker.
        control_dt_s: the control period.
        max_speed_m_s: the robot's speed limit.
        known_problem: what the robot knows in advance for replanning: ``problem``
            without the moving obstacles (the map); None = ``problem``.
        scenario: the scenario being run (its sensing model and moving obstacles'
            sizes and speeds give the ``policy`` navigator its observation layout).
        world_map: with the map unknown, the map the laser builds (:class:`controllers.world_map.SensedMap`,
            fed by the runner every step); :attr:`map_problem` is then its latest publication.  None: the
            map is known (``known_problem``).
    """

    path: Path
    problem: Problem
    planner: Planner | None
    rng: np.random.Generator
    controller: Controller
    goal: GoalChecker
    control_dt_s: float
    max_speed_m_s: float
    known_problem: Problem | None = None
    scenario: Scenario | None = None
    world_map: Any = None

    @property
    def map_problem(self) -> Problem:
        """The map (static obstacles only) as a planning problem: the known one, or the sensed map's latest."""
        if self.world_map is not None:
            return self.world_map.problem()
        return self.known_problem if self.known_problem is not None else self.problem

    @property
    def plan_problem(self) -> Problem:
        """The map as the planners see it: :attr:`map_problem`, or with the map unknown the sensed map's
        cells grown into the space not seen free behind them (:meth:`~controllers.world_map.SensedMap.planning_problem`)."""
        if self.world_map is not None:
            return self.world_map.planning_problem()
        return self.map_problem

    @property
    def map_revision(self) -> int:
        """Grows whenever :attr:`map_problem` changes (always 0 with the map known)."""
        return self.world_map.revision if self.world_map is not None else 0


@dataclass(frozen=True, eq=False)
class Belief:
    """What a navigator acted on at one step, for the log's ``/navigator`` channel.

    Attributes:
        obstacles: the sensed obstacles it used (centres, radii, velocities).
        horizon_s: how far it predicted them along their velocities (0: not at all).
    """

    obstacles: tuple[DetectedObstacle, ...] = ()
    horizon_s: float = 0.0


@dataclass(frozen=True, eq=False, init=False)
class NavigationStep:
    """A navigator's answer for one control step.

    Attributes:
        command: the wheel command to apply now.
        new_path: a path that replaces the one being followed (logged and drawn), or None.
        events: ``(kind, details)`` pairs to log, e.g. ``("replan", {"reason": ...})``.
        belief: what it acted on (logged on ``/navigator``); None for navigators that ignore
            the sensed obstacles (``follow``), which then write no such channel.
    """

    command: ControlCommand
    new_path: Path | None = None
    events: tuple[tuple[str, dict[str, Any]], ...] = ()
    belief: Belief | None = None

    def __init__(self, command: ControlCommand, new_path: Path | None = None,
                 events: tuple[tuple[str, dict[str, Any]], ...] = (), belief: Belief | None = None):
        # One a control step: set once, straight into the dict (see Observation.__init__).
        self.__dict__.update(command=command, new_path=new_path, events=events, belief=belief)


class Navigator(Protocol):
    """What a navigator is, and what it declares it uses (every navigator states all three).

    Attributes:
        name: the registry name.
        uses_detections: whether :meth:`step` reads ``Observation.detections``; when False
            they stay empty and the sensing model's work is spared.  Read after :meth:`reset`
            (a navigator may decide per run, e.g. from the scenario).
        uses_planner: whether :meth:`step` may call ``NavigationSetup.planner`` (replanning
            with the run's planner); when False the setup's ``planner`` is None.
        replan_wall_s: wall time spent planning inside :meth:`step` since :meth:`reset`
            (0 for a navigator that never plans); reported as the run's ``replan_wall_s``.
    """

    name: ClassVar[str]
    uses_detections: bool
    uses_planner: ClassVar[bool]
    replan_wall_s: float

    def reset(self, setup: NavigationSetup) -> None: ...
    def step(self, observation: Observation) -> NavigationStep: ...


DECLARATIONS = ("uses_detections", "uses_planner", "replan_wall_s")  # what every navigator class states


def check_declarations(cls: type) -> type:
    """``cls`` if it declares what it uses (:class:`Navigator`'s ``uses_detections``, ``uses_planner`` as
    booleans and ``replan_wall_s`` as a number, on the class); TypeError naming what is missing."""
    missing = [name for name, kind in zip(DECLARATIONS, (bool, bool, (int, float)))
               if not isinstance(getattr(cls, name, None), kind)]
    if missing:
        raise TypeError(f"navigator {cls.__name__} does not declare {', '.join(missing)} "
                        "(controllers.navigator.Navigator)")
    return cls
