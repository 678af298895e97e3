"""Agents that avoid each other (``orca``, ``social_force``) and, when they see it, the robot."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from swarmnav.controllers.controller import ControlCommand  # noqa: E402
from swarmnav.models.errors import ConfigError  # noqa: E402
from swarmnav.models.obstacle_motion import LinearMotion  # noqa: E402
from swarmnav.models.scenario import load_scenario  # noqa: E402
from swarmnav.sim.episode import EpisodeSpec, run_episode  # noqa: E402
from swarmnav.log.reader import read_log  # noqa: E402
from swarmnav.log.writer import McapRecorder  # noqa: E402
from swarmnav.sim.scene import compile_scene  # noqa: E402
from swarmnav.sim.stepper import EpisodeStepper  # noqa: E402

HEAD = """name = "{name}"
seed = 3
time_limit_s = {limit}
arena = {{ width_m = 10, height_m = 10, walls = false }}
robot = {{ radius_m = 0.3, max_speed_m_s = 0.5 }}
start = {{ x = {rx}, y = {ry}, heading_deg = 0.0 }}
goal = {{ x = 9.5, y = 9.5, tolerance_m = 0.1 }}
sensors = {{ model = "detector", count = 12, range_m = 1 }}
navigator = {{ name = "follow", params = {{}} }}
"""


def agent(x: float, y: float, kind: str, goal: tuple[float, float], extra: str = "") -> str:
    return (f"\n[[obstacles]]\nx = {x}\ny = {y}\nradius_m = 0.3\n"
            f"motion = {{ kind = \"{kind}\", goal = [{goal[0]}, {goal[1]}], v_pref_m_s = 1.0{extra} }}\n")


def write(tmp_path, text: str, name: str = "agents"):
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return path


HEAD_ON = (HEAD.format(name="agents-head-on", limit=10, rx=0.5, ry=9.5)
           + agent(2, 3, "orca", (8, 3)) + agent(8, 3, "orca", (2, 3))
           + agent(2, 6, "social_force", (8, 6)) + agent(8, 6, "social_force", (2, 6)))


def test_agents_walking_head_on_pass_without_touching_where_linear_obstacles_overlap(tmp_path):
    path = write(tmp_path, HEAD_ON)
    log_path = tmp_path / "run.mcap"
    run_episode(EpisodeSpec(load_scenario(str(path))), [McapRecorder(log_path)], time_limit_s=10.0)
    tracks = read_log(log_path).obstacle_tracks
    xy = [tracks[key][1] for key in sorted(tracks)]
    assert len(xy) == 4
    for a, b in ((0, 1), (2, 3)):
        gap = np.hypot(*(xy[a] - xy[b]).T)
        assert gap.min() >= 0.6  # closest centres at least the sum of the radii
        # ... and they did pass: each ends past where the other started, near its goal.
        assert xy[a][-1][0] > 7.5 and xy[b][-1][0] < 2.5
    # The same starts, speeds and headings as straight-line movers: they overlap.
    times = np.arange(0.0, 10.0, 0.02)
    left = LinearMotion((2.0, 3.0), 1.0, 0.0, "stop", (0.0, 0.0), (8.0, 10.0)).positions_at(times)
    right = LinearMotion((8.0, 3.0), 1.0, np.pi, "stop", (2.0, 0.0), (10.0, 10.0)).positions_at(times)
    assert np.hypot(*(left - right).T).min() < 0.6


def test_the_same_world_seed_gives_the_same_crowd_and_another_seed_another(tmp_path):
    scenario = load_scenario(str(write(tmp_path, HEAD_ON)))
    times = np.arange(0.0, 10.0, 0.02)
    first = np.stack([ob.trajectory().positions_at(times) for ob in scenario.obstacles])
    again = np.stack([ob.trajectory().positions_at(times) for ob in load_scenario(str(tmp_path / "agents.toml"))
                      .obstacles])
    other = np.stack([ob.trajectory().positions_at(times) for ob in scenario.with_world_seed(11).obstacles])
    assert np.array_equal(first, again)
    assert not np.array_equal(first, other)


def standing_robot_run(tmp_path, kind: str, sees: bool) -> np.ndarray:
    """An agent walks at a robot standing on its line; the agent's closest centre distance to the robot."""
    extra = ", sees_robot = true" if sees else ""
    text = HEAD.format(name=f"sees-{kind}-{sees}", limit=8, rx=5, ry=5) + agent(2, 5, kind, (8, 5), extra)
    scenario = load_scenario(str(write(tmp_path, text, f"{kind}-{sees}")))
    stepper = EpisodeStepper(scenario, compile_scene(scenario))
    stepper.reset()
    while not stepper.outcome:
        stepper.step(ControlCommand.stop(0))
    agent_xy = stepper.obstacle_track_m[:stepper.step_index + 1, 0]
    robot_xy = stepper.poses[:stepper.step_index + 1, :2]
    return np.hypot(*(agent_xy - robot_xy).T).min(), stepper.result.collisions


@pytest.mark.parametrize("kind", ["orca", "social_force"])
def test_agents_that_see_the_robot_go_round_it_and_others_walk_into_it(tmp_path, kind):
    seen_gap, seen_hits = standing_robot_run(tmp_path, kind, True)
    blind_gap, blind_hits = standing_robot_run(tmp_path, kind, False)
    assert seen_gap >= 0.6 and seen_hits == 0  # robot radius 0.3 + agent radius 0.3
    assert blind_gap < 0.6 and blind_hits >= 1  # walked into it (the kinematic agent shoves the robot)


@pytest.mark.parametrize("motion, field", [
    ('{ kind = "orca", v_pref_m_s = 1.0 }', "obstacles[0].motion.goal"),
    ('{ kind = "orca", goal = [2, 2], goals = [[1, 1], [2, 2]] }', "obstacles[0].motion.goal"),
    ('{ kind = "orca", goal = [2, 2], v_pref_m_s = 0 }', "obstacles[0].motion.v_pref_m_s"),
    ('{ kind = "social_force", goal = [2, 2], v_pref_m_s = 1e9 }', "obstacles[0].motion.v_pref_m_s"),
    ('{ kind = "orca", goal = [20, 2] }', "obstacles[0].motion.goal"),
    ('{ kind = "orca", goals = [[1, 1]] }', "obstacles[0].motion.goals"),
    ('{ kind = "orca", goal = [2, 2], sees_robot = "yes" }', "obstacles[0].motion.sees_robot"),
    ('{ kind = "orca", goal = [2, 2], tau_s = 1 }', "obstacles[0].motion.tau_s"),
])
def test_bad_agent_fields_name_the_field(tmp_path, motion, field):
    text = (HEAD.format(name="bad", limit=4, rx=5, ry=5)
            + f"\n[[obstacles]]\nx = 1\ny = 1\nradius_m = 0.3\nmotion = {motion}\n")
    with pytest.raises(ConfigError) as info:
        load_scenario(str(write(tmp_path, text)))
    assert info.value.field == field


def test_sees_robot_must_agree_over_the_agents(tmp_path):
    text = (HEAD.format(name="mixed", limit=4, rx=5, ry=5) + agent(1, 1, "orca", (2, 2))
            + agent(3, 3, "orca", (4, 4), ", sees_robot = true"))
    with pytest.raises(ConfigError) as info:
        load_scenario(str(write(tmp_path, text)))
    assert info.value.field == "obstacles[1].motion.sees_robot"


def test_a_run_among_agents_that_see_the_robot_gives_the_same_log_bytes_twice(tmp_path):
    from swarmnav.models.scenario import parse_scenario
    from swarmnav.models.scenario_generator import GeneratorOptions, generate
    scenario = parse_scenario(generate("crowdnav_circle", 2, GeneratorOptions(robot_visible=True)), "<t>")
    paths = [tmp_path / f"run{k}.mcap" for k in range(2)]
    for path in paths:
        run_episode(EpisodeSpec(scenario, navigator="velocity_obstacle"), [McapRecorder(path)], time_limit_s=3.0)
    assert paths[0].read_bytes() == paths[1].read_bytes()


@pytest.mark.parametrize("kind", ["orca", "social_force"])
def test_agents_never_enter_a_static_disc_in_their_way(tmp_path, kind):
    text = (HEAD.format(name=f"static-{kind}", limit=12, rx=0.5, ry=9.5)
            + "\n[[obstacles]]\nx = 5\ny = 3\nradius_m = 0.5\n"
            + agent(2, 3.05, kind, (8, 3)) + agent(2, 7.05, kind, (8, 7))
            + "\n[[obstacles]]\nx = 5\ny = 7\nradius_m = 0.5\n")
    scenario = load_scenario(str(write(tmp_path, text, f"static-{kind}")))
    times = np.arange(0.0, 12.0, 0.02)
    for agent_index, disc in ((1, 0), (2, 3)):
        xy = scenario.obstacles[agent_index].trajectory().positions_at(times)
        gap = np.hypot(xy[:, 0] - 5.0, xy[:, 1] - scenario.obstacles[disc].y_m)
        assert gap.min() >= 0.8 - 1e-3  # radii 0.3 + 0.5
        # ORCA walks round it; Helbing and Molnar's agent, aimed almost straight at it, stalls in front of it (the
        # model steers by forces alone, with no route round an obstacle: stated in the README)
        assert (xy[-1, 0] > 7.5) if kind == "orca" else (xy[-1, 0] < 5.0)


@pytest.mark.parametrize("kind", ["orca", "social_force"])
def test_agents_never_enter_a_static_box(tmp_path, kind):
    text = (HEAD.format(name=f"box-{kind}", limit=12, rx=0.5, ry=9.5) + agent(2, 3.4, kind, (8, 3.4))
            + "\n[[boxes]]\nx_min_m = 4.5\ny_min_m = 2.5\nx_max_m = 5.5\ny_max_m = 3.5\n")
    scenario = load_scenario(str(write(tmp_path, text, f"box-{kind}")))
    assert scenario.boxes  # the agent's world holds the box
    xy = scenario.obstacles[0].trajectory().positions_at(np.arange(0.0, 12.0, 0.02))
    outside = np.maximum(np.maximum(4.5 - xy[:, 0], xy[:, 0] - 5.5), 0.0) ** 2 \
        + np.maximum(np.maximum(2.5 - xy[:, 1], xy[:, 1] - 3.5), 0.0) ** 2
    assert np.sqrt(outside).min() >= 0.3 - 1e-3  # the agent's radius
