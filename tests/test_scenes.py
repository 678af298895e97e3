"""Contract tests over every bundled scenario's compiled scene (menagerie style)."""

import mujoco
import numpy as np
import pytest

from swarmnav.models.scenario import list_scenarios, load_scenario
from swarmnav.sim.simulation import Simulation
from swarmnav.sim.sensing import ranges_from_sensors
from swarmnav.sim.scene import compile_scene

SCENARIOS = list_scenarios()


@pytest.fixture(scope="module", params=SCENARIOS)
def compiled(request):
    return load_scenario(request.param), compile_scene(load_scenario(request.param))


def test_there_are_bundled_scenarios():
    for name in ("gwo-scenario-1", "gwo-scenario-2", "gwo-scenario-3", "restaurant-table-2",
                 "restaurant-table-5", "dense-field-30"):
        assert name in SCENARIOS


def test_scene_steps_one_second_with_random_wheel_commands_without_warnings(compiled):
    scenario, scene = compiled
    simulation = Simulation(scenario, scene)
    data = simulation.reset()
    rng = np.random.default_rng(0)
    model = scene.model
    for _ in range(int(round(1.0 / model.opt.timestep / 10))):
        data.ctrl[:] = rng.uniform(model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1])
        mujoco.mj_step(model, data, 10)
    assert all(w.number == 0 for w in data.warning), [w.number for w in data.warning]
    assert np.all(np.isfinite(data.qpos))


def test_every_element_is_named(compiled):
    _, scene = compiled
    m = scene.model
    for kind, count in ((mujoco.mjtObj.mjOBJ_BODY, m.nbody), (mujoco.mjtObj.mjOBJ_GEOM, m.ngeom),
                        (mujoco.mjtObj.mjOBJ_SITE, m.nsite), (mujoco.mjtObj.mjOBJ_SENSOR, m.nsensor),
                        (mujoco.mjtObj.mjOBJ_ACTUATOR, m.nu), (mujoco.mjtObj.mjOBJ_JOINT, m.njnt)):
        start = 1 if kind == mujoco.mjtObj.mjOBJ_BODY else 0  # the world body is implicit
        unnamed = [i for i in range(start, count) if not mujoco.mj_id2name(m, kind, i)]
        assert unnamed == [], (kind, unnamed)


def test_robot_matches_the_scenario(compiled):
    scenario, scene = compiled
    m = scene.model
    assert m.geom("chassis").size[0] == pytest.approx(scenario.robot_radius_m)
    assert len(scene.range_sensor_adr) == scenario.sensor_count
    assert scene.range_cutoff_m == pytest.approx(scenario.sensor_range_m)
    assert m.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    assert np.allclose(np.diff(scene.range_angles_rad), 2 * np.pi / scenario.sensor_count)
    moving = sum(ob.moving for ob in scenario.obstacles)
    assert m.nmocap == moving
    # One geom per obstacle, plus walls.
    assert sum(ob.scenario_index >= 0 for ob in scene.obstacles) == len(scenario.obstacles)


def test_rangefinder_convention_inf_for_nothing_in_range():
    raw = np.array([-1.0, -0.4, 0.4, 0.25, 0.0])
    out = ranges_from_sensors(raw, 0.4)
    assert np.isinf(out[:3]).all()
    assert out[3] == 0.25 and out[4] == 0.0


def test_rangefinders_see_an_obstacle_in_front(tmp_path):
    from swarmnav.models.scenario import parse_scenario
    text = """
name = "probe"
arena = { width_m = 4.0, height_m = 4.0 }
start = { x = 1.0, y = 2.0, heading_deg = 0.0 }
goal = { x = 3.5, y = 3.5 }
[[obstacles]]
x = 1.55
y = 2.0
radius_m = 0.1
"""
    scenario = parse_scenario(text)
    simulation = Simulation(scenario)
    data = simulation.reset()
    mujoco.mj_step(simulation.model, data)
    ranges = ranges_from_sensors(data.sensordata[simulation.scene.range_sensor_adr], 0.4)
    # Beam 0 points along +x from the rim (0.155 m): the disc surface is at 1.45 m.
    assert ranges[0] == pytest.approx(1.45 - 1.0 - 0.155, abs=2e-3)
    assert np.isinf(ranges[1:]).sum() >= 9
