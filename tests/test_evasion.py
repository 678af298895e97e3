"""The evasion stage of the safety layer (``replan`` and ``dstar_replan`` take it by default): when it takes over, what it chooses, and a run."""

import math

import numpy as np
import pytest

from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.evasion import Evasion
from swarmnav.controllers.kinematics import DriveGeometry, WheelSpeeds
from swarmnav.controllers.navigator import DetectedObstacle
from swarmnav.controllers.navigators import make_driver, make_navigator
from swarmnav.controllers.prediction import LocalObstacles, time_to_collision_s
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.world import Pose2D
from swarmnav.sim.episode import EpisodeSpec, run_episode

GEOMETRY = DriveGeometry(wheel_radius_m=0.05, track_m=0.3, max_wheel_speed_rad_s=20.0)
NO_MAP = LocalObstacles(np.zeros((0, 2)), np.zeros(0), np.zeros((0, 4)))
FORWARD = ControlCommand(WheelSpeeds(4.0, 4.0), 0.2, 0.0, 3)
STOP = ControlCommand.stop(3)


def evasion(local=NO_MAP) -> Evasion:
    return Evasion(GEOMETRY, robot_radius_m=0.15, max_speed_m_s=0.2, local=local, trigger_s=2.0)


def test_an_obstacle_that_will_miss_leaves_the_command_alone():
    ev = evasion()
    passing = DetectedObstacle(1.0, 1.5, 0.2, 0.0, 0.2, 0)     # ahead and to the left, driving away
    out, started = ev.apply(Pose2D(0.0, 0.0, 0.0), FORWARD, (passing,))
    assert out is FORWARD and not started


def test_a_waiting_robot_steps_out_of_the_way_of_an_obstacle_driving_at_it():
    ev = evasion()
    pose = Pose2D(0.0, 0.0, 0.0)
    charging = DetectedObstacle(0.0, -0.8, 0.2, 0.0, 0.3, 0)   # from the right, 0.45 m gap, closing at 0.3 m/s
    out, started = ev.apply(pose, STOP, (charging,))
    assert started and ev.active and out is not STOP
    # The chosen velocity (robot frame = world frame here) keeps clear of it for the whole horizon.
    ttc = time_to_collision_s(np.zeros(2), ev.chosen_m_s[None, :], np.array([[0.0, -0.8]]), np.array([[0.0, 0.3]]),
                              np.array([0.2 + 0.15 + ev.margin_m]))
    assert ttc.min() >= ev.horizon_s and np.hypot(*ev.chosen_m_s) > 0.0
    _, started_again = ev.apply(pose, STOP, (charging,))
    assert not started_again                                    # one start per spell


def test_the_escape_keeps_off_the_known_map():
    pose = Pose2D(0.0, 0.0, 0.0)
    charging = DetectedObstacle(-0.8, 0.0, 0.2, 0.3, 0.0, 0)    # from behind, faster than the robot
    discs = np.array([[0.3, 0.6], [0.3, -0.6]])                 # the escape to either side is walled
    ev = evasion(LocalObstacles(discs, np.array([0.3, 0.3]), np.zeros((0, 4))))
    ev.apply(pose, STOP, (charging,))
    ttc_map = time_to_collision_s(np.zeros(2), ev.chosen_m_s[None, :], discs, np.zeros((2, 2)),
                                  np.array([0.3, 0.3]) + 0.15 + ev.margin_m)
    assert ttc_map.min() >= ev.horizon_s


@pytest.mark.parametrize("navigator", ["replan", "dstar_replan"])
def test_evade_is_a_named_option_of_the_layer_with_a_bounded_trigger(navigator):
    assert make_driver(navigator)[1].evade
    layer_off = make_driver(navigator, {"evade": False})[1]
    assert not layer_off.evade and not layer_off.on
    assert not hasattr(make_navigator(navigator), "evade")         # the layer's, not the navigator's
    with pytest.raises(ConfigError, match="evade_trigger_s"):
        make_navigator(navigator, {"evade_trigger_s": -1.0})


@pytest.mark.parametrize("navigator", ["follow", "oracle"])
def test_a_navigator_takes_only_the_layer_switches_it_offers(navigator):
    """``evade`` is offered by the path followers (replan, dstar_replan, iaco_local, immas_stepwise) and the
    local planners (dwa, mppi, velocity_obstacle) only."""
    with pytest.raises(ConfigError, match="navigator.params.evade"):
        make_driver(navigator, {"evade": True})


@pytest.mark.parametrize("navigator", ["dwa", "mppi", "velocity_obstacle"])
def test_the_local_planners_offer_the_evasion_off_by_default(navigator):
    assert not make_driver(navigator)[1].on  # their committed rows ran without it
    layer = make_driver(navigator, {"evade": True, "evade_trigger_s": 3.0})[1]
    assert layer.evade and layer.evade_trigger_s == 3.0 and not layer.safety_filter


def test_no_navigator_imports_the_safety_filter_or_the_evasion():
    """The layer after the navigator (controllers.safety_layer) is the only user of both."""
    import pathlib
    folder = pathlib.Path(__file__).resolve().parents[1] / "controllers" / "navigators"
    sources = {p.name: p.read_text() for p in folder.glob("*.py")}
    assert len(sources) >= 10
    for name, text in sources.items():
        assert "safety_filter import" not in text and "evasion import" not in text, name


CHASED = """
name = "chased"
seed = 13
time_limit_s = 60
arena = { width_m = 8, height_m = 8, walls = false }
robot = { radius_m = 0.15, max_speed_m_s = 0.2 }
start = { x = 1, y = 4, heading_deg = 0.0 }
goal = { x = 7, y = 4, tolerance_m = 0.1 }
sensors = { model = "detector", count = 12, range_m = 2 }
planner = { name = "astar", params = {} }
sim = { cell_m = 0.1 }

[[obstacles]]
x = 2.7315
y = 2.3587
radius_m = 0.3490
motion = { kind = "linear", speed_m_s = 0.2176, heading_deg = 90, at_edge = "reflect" }

[[obstacles]]
x = 4.6987
y = 8.0000
radius_m = 0.2793
motion = { kind = "linear", speed_m_s = 0.2385, heading_deg = -90, at_edge = "reflect" }

[[obstacles]]
x = 5.4984
y = 8.0000
radius_m = 0.2023
motion = { kind = "linear", speed_m_s = 0.2384, heading_deg = -90, at_edge = "reflect" }
"""


def test_dstar_replan_is_run_into_by_a_faster_crosser_unless_it_evades():
    """dyn300's d300-fast-13: D* Lite detours north, ahead of a crosser driving north faster than the robot,
    which runs into it when it stops to turn; the evasion steps aside."""
    scenario = parse_scenario(CHASED)
    plain = run_episode(EpisodeSpec(scenario, navigator="dstar_replan", navigator_params={"evade": False}),
                        stop_on_collision=True).result
    assert plain.collisions >= 1
    evading = run_episode(EpisodeSpec(scenario, navigator="dstar_replan")).result
    assert evading.success and evading.collisions == 0, evading.summary()


def test_velocity_obstacle_with_the_evasion_passes_a_crowd_it_runs_into_without():
    """CrowdNav's validation case 712 (robot invisible): velocity_obstacle alone collides with a human; the
    layer's evasion (``evade = true``, the option dwa, mppi and velocity_obstacle offer, off by default) gets
    it through."""
    from swarmnav.models.scenario_generator import GeneratorOptions, generate
    scenario = parse_scenario(generate("crowdnav_circle", 712, GeneratorOptions()))
    plain = run_episode(EpisodeSpec(scenario, navigator="velocity_obstacle"), stop_on_collision=True).result
    assert plain.collisions >= 1
    evading = run_episode(EpisodeSpec(scenario, navigator="velocity_obstacle", navigator_params={"evade": True})).result
    assert evading.success and evading.collisions == 0, evading.summary()


def test_replan_sweeps_near_leaves_out_only_detections_whose_sweep_keeps_off_the_path():
    from swarmnav.controllers.navigators.replan import sweeps_near
    from swarmnav.controllers.prediction import polyline_gap_m, swept_discs

    rng = np.random.default_rng(7)
    kept = left_out = 0
    for _ in range(300):
        polyline = np.cumsum(rng.uniform(-1, 1, (int(rng.integers(2, 5)), 2)), axis=0)
        detections = tuple(DetectedObstacle(*rng.uniform(-4, 4, 2), float(rng.uniform(0.1, 0.4)),
                                            *rng.uniform(-1, 1, 2), k) for k in range(8))
        near = sweeps_near(detections, polyline, 0.3, 3.0)
        for d in detections:
            if d in near:
                kept += 1
            else:
                left_out += 1
                assert polyline_gap_m(polyline, swept_discs((d,), 3.0), 0.3) > 0.0
    assert kept and left_out  # both kinds occur
