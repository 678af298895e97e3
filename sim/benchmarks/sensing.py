"""``bench sim``'s sensing lines: the laser, the sensed map and the BARN-like closed loop (issue 33).

* ``laser_cast_*_us``: one control step's worth of a 270-beam laser on the Jackal in dense-field-30, as
  MuJoCo rangefinder sensors (computed at every physics step: 10 per control step) and as one
  ``mj_multiRay`` (what ``sim.laser`` casts); each the extra time over the same ``mj_step`` calls without
  rangefinders.
* ``occupancy_update_720_ms``: one :meth:`models.occupancy.LogOddsGrid.integrate` of a real 720-beam
  360-degree scan (10 m) at dense-field-30's start, median over repeats (target at most 0.5 ms).
* ``jackal_laser_unknown_realtime_factor``: the closed loop with the Jackal, a 270-beam 270-degree 10 m
  laser and the map unknown (``replan``) on dense-field-30, no log (target at least 20); beside it
  ``jackal_bare_realtime_factor``, bare ``mj_step`` replaying the same wheel commands (the physics alone).
"""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import replace

import mujoco
import numpy as np

from swarmnav.models.occupancy import LogOddsGrid
from swarmnav.models.robots import ROBOTS
from swarmnav.models.scenario import load_scenario
from swarmnav.sim.episode import EpisodeSpec, plan_episode, run_episode
from swarmnav.sim.laser import LaserCaster
from swarmnav.sim.scene import compile_scene
from swarmnav.sim.stepper import reset_data

TARGET_OCCUPANCY_MS, TARGET_JACKAL_REALTIME = 0.5, 20.0


def jackal_laser(scenario_name: str = "dense-field-30", count: int = 270, fov_deg: float = 270.0,
                 map_knowledge: str = "unknown"):
    """The scenario with the Jackal, a ``count``-beam laser over ``fov_deg`` (10 m) and the map as asked."""
    base = load_scenario(scenario_name)
    jackal = ROBOTS["jackal"]
    return replace(base, robot_model="jackal", robot_radius_m=jackal.planning_radius_m,
                   max_speed_m_s=0.5, sensor_count=count, sensor_fov_deg=fov_deg, sensor_range_m=10.0,
                   map_knowledge=map_knowledge)


def _with_rangefinders(scene) -> mujoco.MjModel:
    """The laser scene with one rangefinder sensor per beam at the laser's site (the per-sensor way)."""
    spec = mujoco.MjSpec.from_string(scene.xml)
    site = spec.site("laser")
    base = spec.body("base_link")
    for k, angle in enumerate(scene.range_angles_rad.tolist()):
        quat = np.zeros(4)
        mujoco.mju_quatZ2Vec(quat, np.array([math.cos(angle), math.sin(angle), 0.0]))
        base.add_site(name=f"beam_{k}", pos=list(site.pos), quat=quat)
        sensor = spec.add_sensor(name=f"beam_range_{k}", type=mujoco.mjtSensor.mjSENS_RANGEFINDER,
                                 objtype=mujoco.mjtObj.mjOBJ_SITE, objname=f"beam_{k}")
        sensor.cutoff = scene.range_cutoff_m
        sensor.intprm[0] = 1  # MuJoCo's rangefinder data spec: the distance
    return spec.compile()


def laser_cast_us(repeats: int = 200) -> dict[str, float]:
    scenario = jackal_laser(map_knowledge="known")
    scene = compile_scene(scenario)
    k = 10
    times: dict[str, list[float]] = {"bare": [], "sensors": [], "multiray": []}
    sensors_model = _with_rangefinders(scene)
    data_bare = reset_data(scenario, scene)
    data_sensors = mujoco.MjData(sensors_model)
    data_sensors.qpos[:] = data_bare.qpos
    caster = LaserCaster(scene, data_bare)
    for _ in range(repeats):
        t0 = time.perf_counter()
        mujoco.mj_step(scene.model, data_bare, k)
        t1 = time.perf_counter()
        mujoco.mj_step(sensors_model, data_sensors, k)
        t2 = time.perf_counter()
        caster.scan(0.0)
        t3 = time.perf_counter()
        times["bare"].append(t1 - t0)
        times["sensors"].append(t2 - t1)
        times["multiray"].append(t3 - t2)
    bare = statistics.median(times["bare"])
    return {"laser_beams": len(scene.range_angles_rad),
            "laser_cast_rangefinder_sensors_us": round((statistics.median(times["sensors"]) - bare) * 1e6, 1),
            "laser_cast_multiray_us": round(statistics.median(times["multiray"]) * 1e6, 1)}


def occupancy_update_ms(repeats: int = 200) -> float:
    scenario = jackal_laser(count=720, fov_deg=360.0, map_knowledge="known")
    scene = compile_scene(scenario)
    data = reset_data(scenario, scene)
    start = scenario.start
    ranges = LaserCaster(scene, data).scan(start.heading_rad)
    grid = LogOddsGrid(scenario.bounds, scenario.map_cell_m)
    samples = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        grid.integrate(start.x_m, start.y_m, start.heading_rad, ranges, scene.range_angles_rad, 0.0,
                       scene.range_cutoff_m)
        samples.append(time.perf_counter() - t0)
    return statistics.median(samples) * 1e3


def jackal_realtime_factor(duration_s: float, repeats: int) -> tuple[float, float]:
    """(closed loop's realtime factor, bare mj_step's replaying its wheel commands), medians over repeats."""
    planned = plan_episode(EpisodeSpec(jackal_laser(), navigator="replan"))
    simulation = planned.simulation
    factors, bare = [], []
    for _ in range(repeats):
        result = run_episode(planned, time_limit_s=duration_s).result
        factors.append(result.sim_time_s / result.wall_time_s)
        model, data, k = simulation.model, simulation.reset(), simulation.steps_per_control
        t0 = time.perf_counter()
        for left, right in result.wheel_command_rad_s.tolist():
            data.ctrl[0], data.ctrl[1] = left, right
            mujoco.mj_step(model, data, k)
        bare.append(len(result.wheel_command_rad_s) * k * float(model.opt.timestep) / (time.perf_counter() - t0))
    return statistics.median(factors), statistics.median(bare)


def sensing_figures(duration_s: float, repeats: int) -> dict[str, float | int]:
    figures: dict[str, float | int] = dict(laser_cast_us())
    figures["occupancy_update_720_ms"] = round(occupancy_update_ms(), 4)
    figures["target_occupancy_update_ms"] = TARGET_OCCUPANCY_MS
    loop, bare = jackal_realtime_factor(duration_s, repeats)
    figures["jackal_laser_unknown_realtime_factor"] = round(loop, 2)
    figures["jackal_bare_realtime_factor"] = round(bare, 2)  # its physics alone (bare mj_step, same commands)
    figures["target_jackal_realtime_factor"] = TARGET_JACKAL_REALTIME
    return figures
