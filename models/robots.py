"""The robot catalogue: one MJCF per robot under ``models/<name>/`` (``robot.xml`` the robot alone, ``scene.xml``
including it with floor, light and camera, as MuJoCo Menagerie lays out its models), and what the rest of
swarmnav needs to know of each without reading MuJoCo.

A scenario picks one with ``robot = { model = "jackal" }``; its other ``robot`` fields override the entry's
defaults (the planning radius, the top speed).  Every robot file follows the same names, which ``sim/runtime/scene.py``
reads: a ``base_link`` body with the free joint ``base_free``, the collision footprint ``chassis``, the wheel
bodies ``left_wheel`` / ``right_wheel`` (their tyres ``left_wheel_tyre`` / ..., hinges ``left_wheel_hinge`` /
..., speed sensors ``left_wheel_speed`` / ...), the actuators ``left_wheel_motor`` / ``right_wheel_motor``
and the template rangefinder ``range_00`` on the site ``range_site_00``.  The wheel radius, the track and the
wheel speed limit are read from the compiled model (``sim.scene.index_scene``), never restated here.

**Physics and planning.**  In MuJoCo the chassis collides with its own shape (a cylinder for ``diff_drive``,
a box of the published footprint for the others).  Planners and navigators plan for a disc: the robot's
``robot_radius_m``, by default the entry's ``planning_radius_m``, the footprint's **circumscribed circle about
the turning centre** (the base origin), so a path clear for the disc is clear for every heading of the box.
The inscribed circle (``inscribed_radius_m``) is what the box surely covers; a cylinder between the two
circles may or may not touch the chassis, depending on the heading (``tests/test_robots.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path as FilePath

MODELS_DIR = FilePath(__file__).resolve().parent


@dataclass(frozen=True)
class RobotModel:
    """One catalogue entry.

    Attributes:
        name: the scenario's ``robot.model``.
        folder: the folder holding ``robot.xml`` and ``scene.xml``.
        footprint_m: (x_min, y_min, x_max, y_max) of the chassis' plan view in the base frame (metres;
            x forward, the base origin at the wheels' axle); for ``diff_drive`` the disc's bounding square.
        round_chassis: the chassis is a cylinder about the base origin (``diff_drive``: its radius is the
            scenario's ``robot.radius_m``, and the base is scaled to it); else a box of ``footprint_m``.
        max_speed_m_s: the published top speed (the default ``robot.max_speed_m_s``).
        ring_sensors: rangefinders sit on the chassis rim, each pointing outward (the papers' 12-ray ring);
            else all beams start at the laser's site (``range_site_00``), as a scanning laser's do.
        default_range_m: the default ``sensors.range_m`` (the robot's usual laser).
        max_angular_rad_s: the published turn-rate limit, the PTP controller's ``max_angular_rad_s`` (None:
            the controller's default, 1.2 rad/s).
        ptp_limits: the PTP controller's drift and corner limits for this robot (``max_drift_m``,
            ``max_deceleration_m_s2``: :mod:`controllers.point_to_point`); None: off, the paper's controller.
        sources: where every figure of the robot file comes from (also in the file's header comment).
    """

    name: str
    folder: FilePath
    footprint_m: tuple[float, float, float, float]
    round_chassis: bool
    max_speed_m_s: float
    ring_sensors: bool
    default_range_m: float
    sources: str
    max_angular_rad_s: float | None = None
    ptp_limits: tuple[float, float] | None = None

    @property
    def scene_xml(self) -> FilePath:
        return self.folder / "scene.xml"

    @property
    def planning_radius_m(self) -> float:
        """The footprint's circumscribed circle about the base origin (the disc planners plan for)."""
        x0, y0, x1, y1 = self.footprint_m
        return max(math.hypot(x, y) for x in (x0, x1) for y in (y0, y1)) if not self.round_chassis else x1

    @property
    def inscribed_radius_m(self) -> float:
        """The largest circle about the base origin inside the footprint."""
        x0, y0, x1, y1 = self.footprint_m
        return min(-x0, -y0, x1, y1)


ROBOTS: dict[str, RobotModel] = {}
#: The real platforms' PTP limits: 0.05 m of drift (the default planning clearance), braking at 2.0 m/s^2.
PTP_LIMITS = (0.05, 2.0)


def _register(robot: RobotModel) -> None:
    if robot.name in ROBOTS:
        raise ValueError(f"robot model {robot.name!r} registered twice")
    ROBOTS[robot.name] = robot


_register(RobotModel(
    name="diff_drive", folder=MODELS_DIR / "diff_drive", footprint_m=(-0.15, -0.15, 0.15, 0.15),
    round_chassis=True, max_speed_m_s=0.2, ring_sensors=True, default_range_m=0.4,
    sources="Abdulla & Hadi (2025), sections 2 and 5.2: a 0.15 m disc robot, 0.2 m/s, 12 rangefinders"))
_register(RobotModel(
    name="jackal", folder=MODELS_DIR / "jackal", footprint_m=(-0.254, -0.215, 0.254, 0.215),
    round_chassis=False, max_speed_m_s=2.0, ring_sensors=False, default_range_m=10.0,
    sources="MuJoCo Menagerie clearpath_jackal/jackal.xml (masses, inertia, wheel radius 0.095 m, "
            "track 0.37559 m, wheelbase 0.262 m, +-26 rad/s); Clearpath Robotics Jackal specifications "
            "(508 x 430 x 250 mm, 2.0 m/s, skid-steer); Clearpath jackal_control config/control.yaml "
            "(wheel_separation_multiplier 1.5, angular max_velocity 4.0 rad/s); the effective track "
            "(track_multiplier 1.95) calibrated on the model by spins on the spot (robot.xml)",
    max_angular_rad_s=4.0, ptp_limits=PTP_LIMITS))
_register(RobotModel(
    name="turtlebot3_burger", folder=MODELS_DIR / "turtlebot3_burger", footprint_m=(-0.102, -0.089, 0.038, 0.089),
    round_chassis=False, max_speed_m_s=0.22, ring_sensors=False, default_range_m=3.5,
    sources="ROBOTIS e-Manual TurtleBot3 specifications (138 x 178 x 192 mm, 0.22 m/s, 2.84 rad/s); ROBOTIS "
            "turtlebot3 burger.yaml (wheel radius 0.033 m, separation 0.160 m) and turtlebot3_burger.urdf "
            "(base box, wheel, caster and LDS positions)",
    max_angular_rad_s=2.84, ptp_limits=PTP_LIMITS))


def robot_model(name: str) -> RobotModel:
    """The catalogue entry called ``name`` (KeyError if there is none; scenarios check the name first)."""
    return ROBOTS[name]
