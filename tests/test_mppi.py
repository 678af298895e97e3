"""The mppi navigator: its unicycle rollouts, its choice among predicted obstacles, and a run in physics."""

import math
import os
from pathlib import Path

import numpy as np
import pytest

from swarmnav.controllers.navigators import make_navigator
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.scenario_generator import GeneratorOptions, generate
from swarmnav.sim.episode import EpisodeSpec, run_episode


def test_rollouts_integrate_the_unicycle():
    nav = make_navigator("mppi", {"samples": 2, "horizon_steps": 10})
    controls = np.zeros((2, 10, 2), dtype=np.float32)
    controls[0, :, 0] = 0.2                                   # straight at 0.2 m/s
    controls[1, :, 0] = 0.2
    controls[1, :, 1] = (math.pi / 2) / 1.0                   # a quarter turn over the 1 s horizon
    px, py = nav.rollouts(1.0, 2.0, 0.0, controls)
    assert px[0, -1] == pytest.approx(1.0 + 0.2 * 1.0, abs=1e-5) and py[0, -1] == pytest.approx(2.0, abs=1e-6)
    # A quarter circle of radius v / omega: ends near (x + r, y + r) (explicit Euler, 10 steps).
    r = 0.2 / (math.pi / 2)
    assert px[1, -1] == pytest.approx(1.0 + r, abs=0.02) and py[1, -1] == pytest.approx(2.0 + r, abs=0.03)


def test_bad_parameters_name_the_field():
    with pytest.raises(ConfigError, match="navigator.params.samples"):
        make_navigator("mppi", {"samples": 0})
    with pytest.raises(ConfigError, match="samples"):
        make_navigator("mppi", {"samples": 100_000, "horizon_steps": 100})


@pytest.mark.parametrize("kind", ["head_on", "crossing"])
def test_mppi_reaches_the_goal_without_collision_and_repeats_itself(kind):
    scenario = parse_scenario(generate(kind, 7, GeneratorOptions(obstacles=1, arena_m=5.0, speed_ratio=0.5,
                                                                 sensor_model="detector", range_m=1.0)))
    first = run_episode(EpisodeSpec(scenario, navigator="mppi")).result
    assert first.success, first.summary()
    again = run_episode(EpisodeSpec(scenario, navigator="mppi")).result
    assert np.array_equal(first.poses, again.poses)


@pytest.mark.parametrize("field, value", [("max_accel_m_s2", -1.0), ("max_accel_m_s2", 2000.0),
                                          ("hard_check_s", -0.1), ("hard_check_s", 11.0),
                                          ("hard_margin_m", -0.01), ("hard_margin_m", 2.0)])
def test_the_barn_options_are_bounded_and_name_the_field(field, value):
    with pytest.raises(ConfigError, match=f"navigator.params.{field}"):
        make_navigator("mppi", {field: value})


def test_the_hard_check_replaces_a_sequence_that_drives_the_box_into_a_cylinder():
    """The averaged sequence drives the Jackal's box straight at a cylinder 0.2 m ahead of its front face: the hard
    check replaces it by the cheapest sampled sequence that keeps the box ``hard_margin_m`` clear (here the one
    standing still), and by standing still when no sample does."""
    from swarmnav.models.world import Pose2D
    nav = make_navigator("mppi", {"samples": 3, "horizon_steps": 10, "hard_check_s": 0.5})
    nav.chassis, nav.chassis_reach = (np.array([-0.254, -0.215, 0.254, 0.215]), 0.333), (0.254, 0.215)
    nav.hard_steps, nav.step_times, nav.max_speed = 5, 0.1 * np.arange(1, 11), 2.0
    nav.near = (np.array([[0.254 + 0.075 + 0.2, 0.0]]), np.zeros((1, 2)), np.array([0.075]), np.zeros((0, 4)))
    pose = Pose2D(0.0, 0.0, 0.0)
    controls = np.zeros((3, 10, 2), dtype=np.float32)
    controls[0, :, 0] = 2.0                              # straight on: into the cylinder within 0.1 s
    controls[1, :, 0] = 1.0                              # straight on, slower: 0.2 m in 0.2 s, still in it
    cost = np.array([0.0, 1.0, 5.0], dtype=np.float32)   # the one standing still (2) is the dearest
    nav.nominal = controls[0].copy()
    nav._hard_check(pose, controls, cost)
    assert np.array_equal(nav.nominal, controls[2])
    nav.nominal = controls[0].copy()
    nav._hard_check(pose, controls[:2], cost[:2])        # no sample keeps clear: stand still
    assert not nav.nominal.any()
    assert nav._chassis_gaps(pose, np.zeros((1, 1, 2), dtype=np.float32))[0, 0] == pytest.approx(0.2)


BARN_MPPI = {"footprint": "box", "cost_weight": 10, "reference_speed_m_s": 0.2, "samples": 300}


@pytest.mark.skipif(not (Path(__file__).resolve().parents[2] / "shared/benchmarks/barn/worlds").is_dir()
                    and not os.environ.get("SWARMNAV_BARN_DIR"), reason="the BARN data (../shared) is not here")
def test_the_acceleration_limit_keeps_mppi_off_the_cylinder_it_hit_on_barn_world_99(tmp_path):
    """BARN world 99 (not a test world), run 0: mppi's BARN configuration stood 0.03 m from a cylinder with every
    rollout colliding from its first step, then drove off at 2 m/s into it (collision at 21.8 s, measured); with
    the rollouts' speed changes limited to 2 m/s^2 from the measured speed it reaches the goal untouched."""
    from swarmnav.benchmarks.barn import write_barn_suite
    from swarmnav.models.scenario import load_scenario
    (path,), _, _ = write_barn_suite(str(tmp_path), False, worlds=(99,), runs=1)
    scenario = load_scenario(path)
    base = run_episode(EpisodeSpec(scenario, navigator="mppi", navigator_params=BARN_MPPI)).result
    assert base.collisions == 1 and not base.reached
    limited = run_episode(EpisodeSpec(scenario, navigator="mppi",
                                      navigator_params={**BARN_MPPI, "max_accel_m_s2": 2.0})).result
    assert limited.reached and limited.collisions == 0
