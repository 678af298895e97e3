"""The clearance is measured from every part of the robot that can touch an obstacle."""

import math

import mujoco
import numpy as np

from swarmnav.models.scenario import load_scenario
from swarmnav.sim.clearance import CLEARANCE_HORIZON_M, ClearanceProbe
from swarmnav.sim.simulation import Simulation


def test_the_probe_equals_the_smallest_gap_over_every_robot_collision_geom():
    simulation = Simulation(load_scenario("dense-field-30"))
    scene, model = simulation.scene, simulation.model
    probe = ClearanceProbe(scene)
    rng = np.random.default_rng(0)
    fromto = np.zeros(6)
    checked = 0
    for _ in range(200):
        data = simulation.reset()
        adr = scene.free_qpos_adr
        x, y, heading = rng.uniform(0.5, 9.5), rng.uniform(0.5, 9.5), rng.uniform(-math.pi, math.pi)
        data.qpos[adr:adr + 3] = [x, y, data.qpos[adr + 2]]
        data.qpos[adr + 3:adr + 7] = [math.cos(heading / 2), 0.0, 0.0, math.sin(heading / 2)]
        mujoco.mj_forward(model, data)
        every = min(mujoco.mj_geomDistance(model, data, int(g), ob.geom_id, CLEARANCE_HORIZON_M, fromto)
                    for g in scene.robot_geom_ids for ob in scene.obstacles)
        if every < 0.3:  # near an obstacle, where the nearest-obstacle pick matters
            checked += 1
            assert probe.measure(data, x, y) == every
    assert checked >= 20
