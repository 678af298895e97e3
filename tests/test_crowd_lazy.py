"""The stepper without the no-robot rollout of agents that see the robot (ReactiveCrowd.lazy): the same
episodes as with it (A/B in one test: observations, hop bounds, tracks, results), over two episodes."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402

from swarmnav.controllers.controller import ControlCommand  # noqa: E402
from swarmnav.controllers.kinematics import wheel_speeds  # noqa: E402
from swarmnav.models.scenario import load_scenario  # noqa: E402
from swarmnav.sim import crowd_stepping  # noqa: E402
from swarmnav.sim.scene import compile_scene  # noqa: E402
from swarmnav.sim.stepper import EpisodeStepper  # noqa: E402

TEXT = """name = "lazy-crowd"
seed = 3
time_limit_s = 1.5
arena = { width_m = 6, height_m = 6, walls = false }
robot = { radius_m = 0.3, max_speed_m_s = 0.5 }
start = { x = 1.0, y = 3.0, heading_deg = 0.0 }
goal = { x = 5.5, y = 5.5, tolerance_m = 0.1 }
sensors = { model = "detector", count = 12, range_m = 20 }
navigator = { name = "follow", params = {} }
"""


def agent(x: float, y: float, goal: tuple[float, float]) -> str:
    return (f"\n[[obstacles]]\nx = {x}\ny = {y}\nradius_m = 0.3\n"
            f"motion = {{ kind = \"orca\", goal = [{goal[0]}, {goal[1]}], v_pref_m_s = 1.0, sees_robot = true }}\n")


def episodes(path, lazy: bool, monkeypatch) -> tuple[list, EpisodeStepper, list[bool]]:
    """Two episodes (the robot driving on, into the agents' way) until the time limit: every observation's
    detections, the stepper, and whether the agents' rollout without a robot existed at each step."""
    if not lazy:
        monkeypatch.setattr(crowd_stepping, "rollout_unneeded", lambda crowd: False)
    scenario = load_scenario(str(path))
    stepper = EpisodeStepper(scenario, compile_scene(scenario))
    crowd = stepper._crowd.crowd
    monkeypatch.undo()
    seen, rolled = [], []
    for episode in range(2):
        observation = stepper.reset()
        seen.append(observation.detections)
        while not stepper.outcome:
            if episode == 0:
                rolled.append("track_m" in crowd.__dict__)
            geometry = stepper.scene.drive
            observation = stepper.step(ControlCommand(wheel_speeds(0.4, 0.1, geometry), 0.4, 0.1, 0))
            seen.append(observation.detections)
        seen.append(stepper.result.crowd)
        seen.append(stepper.obstacle_track_m[:stepper.step_index + 1].copy())
    return seen, stepper, rolled


def test_agents_that_see_the_robot_step_the_same_without_their_rollout(tmp_path, monkeypatch):
    path = tmp_path / "lazy.toml"
    path.write_text(TEXT + agent(4.0, 3.0, (0.5, 3.0)) + agent(3.0, 1.0, (3.0, 5.0)) + agent(5.0, 5.0, (1.0, 1.0)))
    eager, eager_stepper, eager_rolled = episodes(path, False, monkeypatch)
    lazy, lazy_stepper, lazy_rolled = episodes(path, True, monkeypatch)
    assert eager_stepper.outcome == lazy_stepper.outcome == "timeout"
    assert all(eager_rolled) and not any(lazy_rolled)  # the lazy stepper rolled the agents out at the end only,
    assert eager_stepper.obstacle_shift_m == lazy_stepper.obstacle_shift_m
    assert len(eager) == len(lazy)
    for a, b in zip(eager, lazy):  # and saw the same (the last step's velocities included)
        if isinstance(a, np.ndarray):
            assert np.array_equal(a, b)
        else:
            assert a == b


BLIND = """name = "rolled-crowd"
seed = 4
time_limit_s = 1.5
arena = { width_m = 6, height_m = 6, walls = true }
robot = { radius_m = 0.3, max_speed_m_s = 0.5 }
start = { x = 1.0, y = 3.0, heading_deg = 0.0 }
goal = { x = 5.5, y = 5.5, tolerance_m = 0.1 }
sensors = { model = "detector", count = 12, range_m = 20 }
navigator = { name = "follow", params = {} }

[[obstacles]]
x = 2.0
y = 5.0
radius_m = 0.2
motion = { kind = "linear", speed_m_s = 0.9, heading_deg = -20, at_edge = "reflect" }
"""


def blind_agent(x: float, y: float, kind: str, goal: tuple[float, float]) -> str:
    return (f"\n[[obstacles]]\nx = {x}\ny = {y}\nradius_m = 0.3\n"
            f"motion = {{ kind = \"{kind}\", goal = [{goal[0]}, {goal[1]}], v_pref_m_s = 1.0 }}\n")


def test_agents_blind_to_the_robot_rolled_out_as_the_episode_goes_are_the_same(tmp_path, monkeypatch):
    path = tmp_path / "rolled.toml"
    path.write_text(BLIND + blind_agent(4.0, 3.0, "orca", (0.5, 3.0)) + blind_agent(3.0, 1.0, "social_force", (3.0, 5.0))
                    + blind_agent(5.0, 5.0, "orca", (1.0, 1.0)))
    runs = []
    for rolled in (False, True):
        if not rolled:
            monkeypatch.setattr(crowd_stepping.RolledCrowd, "of", classmethod(lambda cls, *args: None))
        scenario = load_scenario(str(path))
        stepper = EpisodeStepper(scenario, compile_scene(scenario))
        monkeypatch.undo()
        crowd = next(ob.motion.crowd for ob in scenario.obstacles if hasattr(ob.motion, "crowd"))
        assert (stepper._rolled is not None) == rolled
        seen, early = [], []
        for _ in range(2):
            seen.append(stepper.reset().detections)
            while not stepper.outcome:
                early.append("track_m" in crowd.__dict__)
                seen.append(stepper.step(ControlCommand(wheel_speeds(0.4, 0.1, stepper.scene.drive), 0.4, 0.1, 0))
                            .detections)
                seen.append((stepper.clearance_bound_m(), stepper.obstacle_shift_m[:stepper.step_index + 1]))
            seen += [stepper.result.crowd, stepper.result.min_clearance_m,
                     stepper.obstacle_track_m[:stepper.step_index + 1].tolist()]
        runs.append((seen, early, stepper))
    (eager, eager_early, a), (rolled, rolled_early, b) = runs
    assert a.outcome == b.outcome == "timeout"
    assert all(eager_early) and not any(rolled_early)  # rolled out up front, or never whole
    assert a.obstacle_shift_m == b.obstacle_shift_m
    assert eager == rolled
