"""Compose the MuJoCo scene for a scenario with ``MjSpec``.

The scenario's robot of the catalogue (:mod:`models.robots`: ``models/<robot>/scene.xml``, which includes
its ``robot.xml``) is the base.  We resize the disc robot to the scenario's radius, lay out the
rangefinders (the disc's ring on its rim, or a laser's fan from one site), then add the
arena: walls, static cylinders (plain geoms), moving cylinders (mocap bodies,
moved kinematically by the runner) and box obstacles from grid maps.  Every
element gets a name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path as FilePath

import mujoco
import numpy as np

from swarmnav.controllers.kinematics import DriveGeometry
from swarmnav.models.robots import ROBOTS
from swarmnav.models.scenario import Scenario

MODEL_DIR = FilePath(__file__).resolve().parent.parent / "models" / "diff_drive"
SCENE_XML = MODEL_DIR / "scene.xml"
ROBOT_ROOT = "base_link"  # every body under it is the robot's
LASER_SITE = "laser"  # the origin of a scanning laser's beams (see _set_laser)
STATIC_RGBA = (0.55, 0.45, 0.38, 1.0)
MOVING_RGBA = (0.95, 0.55, 0.1, 1.0)
WALL_RGBA = (0.4, 0.4, 0.45, 1.0)
WALL_THICKNESS_M = 0.1
WALL_HEIGHT_M = 0.3


@dataclass(frozen=True)
class ObstacleGeom:
    """A compiled obstacle: its geom id, and its mocap index when it moves (else -1)."""

    name: str
    geom_id: int
    mocap_index: int
    scenario_index: int  # index in Scenario.obstacles, -1 for walls and boxes


@dataclass(frozen=True, eq=False)
class CompiledScene:
    """The compiled model and every index the runner needs, looked up once."""

    model: mujoco.MjModel
    xml: str
    drive: DriveGeometry
    free_qpos_adr: int
    free_qvel_adr: int
    wheel_qvel_adr: tuple[int, int]
    range_sensor_adr: np.ndarray   # (K,) sensordata indices of the rangefinders (empty with a laser)
    range_angles_rad: np.ndarray   # (K,) beam directions in base_link, in [0, 2 pi), CCW from +x
    range_cutoff_m: float
    range_offset_m: float          # distance of the rangefinder sites from the base origin
    range_height_m: float          # their height above the base origin
    robot_geom_ids: np.ndarray     # every robot geom that collides: chassis, casters, wheel tyres
    chassis_geom_id: int
    obstacles: tuple[ObstacleGeom, ...]
    is_robot_geom: np.ndarray      # (ngeom,) bool
    is_obstacle_geom: np.ndarray   # (ngeom,) bool
    laser_site_id: int = -1        # a scanning laser's origin site (sim.laser casts its beams), -1 with rangefinders


def build_spec(scenario: Scenario) -> mujoco.MjSpec:
    """The scene for a scenario as an editable spec (not yet compiled)."""
    robot = ROBOTS[scenario.robot_model]
    spec = mujoco.MjSpec.from_file(str(robot.scene_xml))
    spec.modelname = f"swarmnav_{scenario.name}"
    spec.option.timestep = scenario.sim.timestep_s

    radius = scenario.robot_radius_m
    if robot.round_chassis:
        _fit_base(spec, radius)
        _fit_top_speed(spec, scenario.max_speed_m_s)
    if robot.ring_sensors and scenario.sensor_fov_deg == 360.0:
        _set_rangefinders(spec, scenario.sensor_count, radius, scenario.sensor_range_m)
    else:
        _set_laser(spec, scenario.sensor_count, scenario.sensor_fov_deg, scenario.sensor_range_m,
                   robot.ring_sensors)

    width, height = scenario.arena_width_m, scenario.arena_height_m
    floor = spec.geom("floor")
    floor.size = [width / 2 + 1.0, height / 2 + 1.0, 0.05]
    floor.pos = [width / 2, height / 2, 0.0]
    top = spec.camera("top")
    aspect = 4.0 / 3.0
    half_extent = max(height / 2, width / 2 / aspect) * 1.08
    top.pos = [width / 2, height / 2, half_extent / math.tan(math.radians(top.fovy / 2))]

    world = spec.worldbody
    if scenario.walls:
        t = WALL_THICKNESS_M
        for name, cx, cy, hx, hy in (
                ("wall_south", width / 2, -t / 2, width / 2 + t, t / 2),
                ("wall_north", width / 2, height + t / 2, width / 2 + t, t / 2),
                ("wall_west", -t / 2, height / 2, t / 2, height / 2),
                ("wall_east", width + t / 2, height / 2, t / 2, height / 2)):
            world.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_BOX, size=[hx, hy, WALL_HEIGHT_M / 2],
                           pos=[cx, cy, WALL_HEIGHT_M / 2], rgba=list(WALL_RGBA))
    for i, ob in enumerate(scenario.obstacles):
        name = f"obstacle_{i:02d}"
        size = [ob.radius_m, ob.height_m / 2, 0.0]
        if ob.moving:
            body = world.add_body(name=f"{name}_body", mocap=True, pos=[ob.x_m, ob.y_m, ob.height_m / 2])
            body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=size, rgba=list(MOVING_RGBA))
        else:
            world.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=size,
                           pos=[ob.x_m, ob.y_m, ob.height_m / 2], rgba=list(STATIC_RGBA))
    for k, box in enumerate(scenario.boxes):
        world.add_geom(name=f"map_box_{k:03d}", type=mujoco.mjtGeom.mjGEOM_BOX,
                       size=[(box.x_max_m - box.x_min_m) / 2, (box.y_max_m - box.y_min_m) / 2, 0.25],
                       pos=[(box.x_min_m + box.x_max_m) / 2, (box.y_min_m + box.y_max_m) / 2, 0.25],
                       rgba=list(STATIC_RGBA))
    return spec


def _fit_base(spec: mujoco.MjSpec, radius_m: float) -> None:
    """Give the chassis the scenario's radius, so that the whole robot fits in it.

    The base in ``robot.xml`` (wheels at +-0.11 m, 0.04 m tyres, casters) has a
    footprint of exactly the chassis radius it declares.  A larger robot keeps
    that base under a wider chassis.  A smaller one scales the whole base with
    the radius (positions and sizes of every geom, the wheel bodies and the
    sites), so no wheel or caster sticks out of the radius the planners plan
    for; the wheel speed limit grows by the same factor, which keeps the top
    linear speed (wheel radius x wheel speed) of the full-size base.  Masses are
    unchanged.
    """
    chassis = spec.geom("chassis")
    base_radius_m = float(chassis.size[0])
    if radius_m < base_radius_m:
        scale = radius_m / base_radius_m
        for body in (spec.body(name) for name in ("base_link", "left_wheel", "right_wheel")):
            if body.name != "base_link":
                body.pos = np.asarray(body.pos) * scale
            for geom in body.geoms:
                geom.pos = np.asarray(geom.pos) * scale
                geom.size = np.asarray(geom.size) * scale
            for site in body.sites:
                site.pos = np.asarray(site.pos) * scale
        for actuator in spec.actuators:
            actuator.ctrlrange = np.asarray(actuator.ctrlrange) / scale
    chassis.size = [radius_m, chassis.size[1], 0.0]


def _fit_top_speed(spec: mujoco.MjSpec, max_speed_m_s: float) -> None:
    """Let the wheels turn fast enough for the scenario's top speed when the base's own limit is below it.

    The base's wheel speed limit (10 rad/s on 0.04 m tyres: 0.4 m/s) stays as it is for every robot at or
    below it; a faster robot (CrowdNav's, 1 m/s) gets the wheel speed ``max_speed_m_s / wheel radius``.
    """
    wheel_radius_m = float(spec.geom("left_wheel_tyre").size[0])
    need_rad_s = max_speed_m_s / wheel_radius_m
    for actuator in spec.actuators:
        limit = float(np.abs(np.asarray(actuator.ctrlrange)).min())
        if need_rad_s > limit:
            actuator.ctrlrange = np.array([-need_rad_s, need_rad_s])


def _set_rangefinders(spec: mujoco.MjSpec, count: int, body_radius_m: float, cutoff_m: float) -> None:
    """Place ``count`` rangefinders evenly on the rim, pointing outward, above the wheels."""
    template = spec.site("range_site_00")
    z = float(template.pos[2])
    # The XML's own sensor is the template (what it measures lives in intprm).
    _replace_rangefinders(spec, count)
    rim = body_radius_m + 0.005
    for k in range(count):
        angle = 2.0 * math.pi * k / count
        site = spec.site(f"range_site_{k:02d}")
        site.pos = [rim * math.cos(angle), rim * math.sin(angle), z]
        # z axis outward: rotate +z onto (cos a, sin a, 0).
        quat = np.zeros(4)
        mujoco.mju_quatZ2Vec(quat, np.array([math.cos(angle), math.sin(angle), 0.0]))
        site.quat = quat
        spec.sensor(f"range_{k:02d}").cutoff = cutoff_m


def laser_angles_rad(count: int, fov_deg: float) -> np.ndarray:
    """Beam directions of a laser: a full circle from straight ahead counter-clockwise (fov 360: no beam twice),
    else ``count`` beams evenly from -fov/2 to +fov/2 (a LaserScan's angle_min to angle_max)."""
    if fov_deg >= 360.0:
        return 2.0 * math.pi * np.arange(count) / count
    fov = math.radians(fov_deg)
    return -fov / 2 + fov * np.arange(count) / max(count - 1, 1) if count > 1 else np.zeros(1)


def _replace_rangefinders(spec: mujoco.MjSpec, count: int) -> None:
    """``count`` rangefinder sites and sensors in place of the file's (the first is the template)."""
    existing = [s for s in spec.sites if s.name.startswith("range_site_")]
    if len(existing) == count:
        return
    data_spec = np.array(spec.sensor("range_00").intprm)
    for sensor in [s for s in spec.sensors if s.name.startswith("range_")]:
        spec.delete(sensor)
    for site in existing:
        spec.delete(site)
    site_class = spec.find_default("range")
    base = spec.body("base_link")
    for k in range(count):
        base.add_site(name=f"range_site_{k:02d}", default=site_class)
        sensor = spec.add_sensor(name=f"range_{k:02d}", type=mujoco.mjtSensor.mjSENS_RANGEFINDER,
                                 objtype=mujoco.mjtObj.mjOBJ_SITE, objname=f"range_site_{k:02d}")
        sensor.intprm = data_spec


def _set_laser(spec: mujoco.MjSpec, count: int, fov_deg: float, cutoff_m: float, centred: bool) -> None:
    """A scanning laser: ``count`` beams over ``fov_deg`` (:func:`laser_angles_rad`) from one origin, the site
    ``laser`` (the robot file's ``range_site_00``; put on the base's axis when ``centred``, as for the disc
    robot's fan), declared by the numerics ``laser_count``, ``laser_fov_deg`` and ``laser_range_m``.

    No rangefinder sensor remains: MuJoCo computes sensors at every physics step, and ``sim.laser`` casts
    the beams once per control step with ``mj_multiRay`` instead (``bench sim`` measures both).
    """
    template = spec.site("range_site_00")
    x, y, z = (float(v) for v in template.pos)
    for sensor in [s for s in spec.sensors if s.name.startswith("range_")]:
        spec.delete(sensor)
    for site in [s for s in spec.sites if s.name.startswith("range_site_") and s.name != "range_site_00"]:
        spec.delete(site)
    template.name = LASER_SITE
    template.pos = [0.0, 0.0, z] if centred else [x, y, z]
    template.quat = [1.0, 0.0, 0.0, 0.0]
    for name, value in (("laser_count", float(count)), ("laser_fov_deg", float(fov_deg)),
                        ("laser_range_m", float(cutoff_m))):
        spec.add_numeric(name=name, data=[value])


def compile_scene(scenario: Scenario) -> CompiledScene:
    """Compile the scene and look up every index the runner uses."""
    spec = build_spec(scenario)
    spec.compile()
    xml = spec.to_xml()
    # Run exactly the model that the log attaches: to_xml rounds numbers, so the
    # model is compiled from that text rather than from the spec.
    model = mujoco.MjModel.from_xml_string(xml)
    return index_scene(model, xml)


def _has_numeric(model: mujoco.MjModel, name: str) -> bool:
    return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, name) >= 0


def index_scene(model: mujoco.MjModel, xml: str) -> CompiledScene:
    """Look up the runner's indices in a compiled swarmnav scene (also for replaying a log's MJCF)."""
    def gid(name: str) -> int:
        return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)

    free = model.joint("base_free")
    left = model.joint("left_wheel_hinge")
    right = model.joint("right_wheel_hinge")
    wheel_radius = float(model.geom("left_wheel_tyre").size[0])
    # A skid-steer's effective track: the wheel separation times the robot file's track_multiplier, if any
    # (Clearpath's wheel_separation_multiplier: the commands and the odometry both use it).
    multiplier = model.numeric("track_multiplier").data[0] if _has_numeric(model, "track_multiplier") else 1.0
    track = float(np.linalg.norm(model.body("left_wheel").pos - model.body("right_wheel").pos)) * float(multiplier)
    max_wheel = float(min(abs(model.actuator("left_wheel_motor").ctrlrange).min(),
                          abs(model.actuator("right_wheel_motor").ctrlrange).min()))
    drive = DriveGeometry(wheel_radius_m=wheel_radius, track_m=track, max_wheel_speed_rad_s=max_wheel)

    # In model order, which is the order of the angles (names stop sorting by angle past 100 sensors).
    range_ids = [i for i in range(model.nsensor) if model.sensor_type[i] == mujoco.mjtSensor.mjSENS_RANGEFINDER]
    range_adr = np.array([model.sensor_adr[i] for i in range_ids], dtype=np.int64)
    angles, offsets, heights = [], [], []
    for i in range_ids:
        site = model.sensor_objid[i]
        p = model.site_pos[site]
        angles.append(math.atan2(p[1], p[0]) % (2.0 * math.pi))
        offsets.append(math.hypot(p[0], p[1]))
        heights.append(float(p[2]))
    cutoff = float(model.sensor_cutoff[range_ids[0]]) if range_ids else 0.0
    laser_site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, LASER_SITE)
    if laser_site >= 0:
        numeric = {name: float(model.numeric(name).data[0]) for name in ("laser_count", "laser_fov_deg",
                                                                          "laser_range_m")}
        angles = laser_angles_rad(int(round(numeric["laser_count"])), numeric["laser_fov_deg"]).tolist()
        offsets = [0.0]
        heights = [float(model.site_pos[laser_site][2])]
        cutoff = numeric["laser_range_m"]

    root = model.body(ROBOT_ROOT).id
    robot_bodies = {b for b in range(model.nbody) if model.body_rootid[b] == root}
    # A robot geom that can touch an obstacle (contype / conaffinity 1, the obstacles' bit): wheels that
    # touch only the floor (bit 2, the catalogue's box robots) are not.
    is_robot = np.array([model.geom_bodyid[g] in robot_bodies and bool((model.geom_contype[g]
                                                                        | model.geom_conaffinity[g]) & 1)
                         for g in range(model.ngeom)])
    obstacles = []
    is_obstacle = np.zeros(model.ngeom, dtype=bool)
    for g in range(model.ngeom):
        name = model.geom(g).name
        if name.startswith(("obstacle_", "wall_", "map_box_")):
            is_obstacle[g] = True
            body = model.geom_bodyid[g]
            mocap = int(model.body_mocapid[body])
            index = int(name.split("_")[1]) if name.startswith("obstacle_") else -1
            obstacles.append(ObstacleGeom(name, g, mocap, index))
    return CompiledScene(
        model=model, xml=xml, drive=drive, free_qpos_adr=int(free.qposadr[0]),
        free_qvel_adr=int(free.dofadr[0]),
        wheel_qvel_adr=(int(left.dofadr[0]), int(right.dofadr[0])),
        range_sensor_adr=range_adr, range_angles_rad=np.array(angles), range_cutoff_m=cutoff,
        range_offset_m=float(np.mean(offsets)) if offsets else 0.0,
        range_height_m=float(np.mean(heights)) if heights else 0.0,
        robot_geom_ids=np.flatnonzero(is_robot), chassis_geom_id=gid("chassis"),
        obstacles=tuple(obstacles), is_robot_geom=is_robot, is_obstacle_geom=is_obstacle, laser_site_id=laser_site)
