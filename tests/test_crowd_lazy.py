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
