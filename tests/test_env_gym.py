"""The Gymnasium adapter: Gymnasium's checker, registration, reset options, render, MCAP recording."""

import json
import subprocess
import sys
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from swarmnav.models.scenario import Seeds, load_scenario
from swarmnav.env import ENV_ID, NavigateEnv
from swarmnav.log.reader import read_log


@pytest.mark.parametrize("scenario, options", [
    ("restaurant-table-5", {}),
    ("gwo-scenario-2", {"path_planner": "astar", "tracked_obstacles": True}),
    ("dyn-crowd-3", {"path_planner": "astar"}),  # the detector sensing model: the obstacle list
])
def test_gymnasiums_env_checker_passes_without_a_warning_in_the_default_action_mode(scenario, options):
    env = NavigateEnv(scenario, time_limit_s=0.5, **options)
    assert all(np.all(np.isfinite(space.low)) and np.all(np.isfinite(space.high))
               for space in env.observation_space.values())
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env, skip_render_check=True)


def test_the_raw_wheels_action_mode_passes_with_only_the_not_normalised_warning():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(NavigateEnv("gwo-scenario-2", time_limit_s=0.5, action="wheels"), skip_render_check=True)
    assert len(caught) == 1 and "normalized" in str(caught[0].message)


def test_spaces_are_float32_and_the_goal_and_velocity_bounds_come_from_the_arena_and_wheels():
    env = NavigateEnv("dyn-crowd-3")
    scenario = load_scenario("dyn-crowd-3")
    drive = env.task.scene.drive
    space = env.observation_space
    assert all(s.dtype == np.float32 for s in space.values()) and env.action_space.dtype == np.float32
    assert space["goal"].high[0] == np.float32(np.hypot(scenario.arena_width_m, scenario.arena_height_m))
    top_speed = drive.wheel_radius_m * drive.max_wheel_speed_rad_s
    assert space["velocity"].high.tolist() == pytest.approx([top_speed, 2 * top_speed / drive.track_m], rel=1e-6)
    # Full speed forward, then spinning on the spot: the measured twist stays within the bounds unclipped.
    env.reset(seed=0)
    for action in [[1.0, 0.0]] * 50 + [[0.0, 1.0]] * 50:
        obs = env.step(np.array(action, dtype=np.float32))[0]
        twist = env.task.observation.twist
        assert obs["velocity"].tolist() == [np.float32(twist.linear_m_s), np.float32(twist.angular_rad_s)]
        assert obs in space
    assert abs(twist.angular_rad_s) > 0.3 * space["velocity"].high[1]  # really spinning


def test_make_by_module_and_id_in_a_fresh_interpreter():
    code = ("import gymnasium, json, numpy as np\n"
            f"env = gymnasium.make('swarmnav.env:{ENV_ID}', scenario='restaurant-table-5', time_limit_s=1.0)\n"
            "obs, info = env.reset(seed=0)\n"
            "done, n, ret = False, 0, 0.0\n"
            "while not done:\n"
            "    obs, r, term, trunc, info = env.step(env.action_space.sample())\n"
            "    done, n, ret = term or trunc, n + 1, ret + r\n"
            "print(json.dumps({'steps': n, 'trunc': trunc, 'outcome': info['outcome'], 'keys': sorted(obs)}))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    result = json.loads(out.stdout.strip().splitlines()[-1])
    control_hz = load_scenario("restaurant-table-5").sim.control_hz
    assert result == {"steps": round(1.0 * control_hz), "trunc": True, "outcome": "timeout",
                      "keys": ["goal", "ranges", "velocity"]}


def test_terminated_truncated_and_info_follow_the_outcome():
    env = NavigateEnv("restaurant-table-5", time_limit_s=60.0)
    obs, info = env.reset(seed=0)
    terminated = truncated = False
    costs = 0.0
    while not (terminated or truncated):
        distance, bearing = obs["goal"]
        obs, reward, terminated, truncated, info = env.step(np.array([1.0 if abs(bearing) < 0.3 else 0.0,
                                                                      np.clip(2.0 * bearing, -1.0, 1.0)]))
        costs += info["cost"]
    assert info["outcome"] == ("goal_reached" if terminated else "timeout")
    assert info["metrics"]["outcome"] == info["outcome"]
    assert info["metrics"]["collisions"] == costs == info["collisions"]
    assert np.isfinite(info["clearance_m"])


def test_reset_options_switch_scenario_and_world_seed():
    env = NavigateEnv("gwo-scenario-2", time_limit_s=1.0)
    env.reset(seed=1)
    assert env.task.scenario.name == "gwo-scenario-2"
    env.reset(seed=1, options={"scenario": "dense-field-30", "world_seed": 5})
    assert env.task.scenario.name == "dense-field-30" and env.task.scenario.world_seed == 5
    assert env.task.seeds.planner == Seeds.derived(1).planner
    assert env.unwrapped.dm_env.physics.model.ngeom != NavigateEnv("gwo-scenario-2").dm_env.physics.model.ngeom
    with pytest.raises(ValueError, match="unknown"):
        env.reset(options={"sceanrio": "x"})


def test_render_returns_frames_of_the_moving_robot():
    env = NavigateEnv("gwo-scenario-2", render_mode="rgb_array", width=160, height=120, time_limit_s=5.0)
    env.reset(seed=0)
    first = env.render()
    for _ in range(100):
        env.step(np.array([1.0, 0.5]))
    later = env.render()
    assert first.shape == (120, 160, 3) and first.dtype == np.uint8
    assert first.std() > 0 and not np.array_equal(first, later)
    env.close()


def test_an_episode_records_to_mcap_like_a_run(tmp_path):
    env = NavigateEnv("restaurant-table-5", time_limit_s=1.0, record_to=str(tmp_path / "ep{episode}.mcap"))
    env.reset(seed=0)
    truncated = False
    steps = 0
    while not truncated:
        _, _, _, truncated, info = env.step(np.array([0.5, 0.2]))
        steps += 1
    poses = env.task.stepper.poses[:steps + 1].copy()
    env.reset(seed=0)  # the second episode is closed before its end
    for _ in range(5):
        env.step(np.array([0.5, 0.2]))
    env.close()
    log = read_log(tmp_path / "ep0.mcap")
    assert log.complete and log.outcome["outcome"] == "timeout"
    assert len(log.time_s) == steps + 1
    assert np.array_equal(log.position_m[:, :2], poses[:, :2])
    assert read_log(tmp_path / "ep1.mcap").outcome["outcome"] == "interrupted"


def test_bench_env_quick_prints_the_three_rates_and_their_ratios_as_json():
    out = subprocess.run([sys.executable, "-m", "swarmnav.cli", "bench", "env", "--quick", "--json"],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    figures = json.loads(out.stdout)
    control_hz = load_scenario("dense-field-30").sim.control_hz
    assert figures["control_steps_per_run"] == round(4.0 * control_hz) and figures["repeats"] == 2
    for key in ("env", "runner", "bare_control", "env_replay", "vector_1", "vector_2"):
        assert figures[f"{key}_steps_per_s"] > 0
    assert figures["vector_2_vs_1"] == pytest.approx(figures["vector_2_steps_per_s"] / figures["vector_1_steps_per_s"],
                                                     rel=0.5)  # a median of interleaved ratios beside a ratio of medians
    assert figures["vector_steps_per_run"] * figures["vector_action_repeat"] <= figures["control_steps_per_run"]
    assert figures["env_vs_runner"] == pytest.approx(figures["env_steps_per_s"] / figures["runner_steps_per_s"],
                                                     rel=0.5)  # a median of ratios beside a ratio of medians
    bad = subprocess.run([sys.executable, "-m", "swarmnav.cli", "bench", "env", "--repeats", "0"],
                         capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "--repeats" in bad.stderr and "Traceback" not in bad.stderr


def _walker_tracks(env, **reset):
    env.reset(**reset)
    return env.task.stepper.obstacle_track_m.copy()


def test_reset_seed_derives_the_world_too_and_options_override_it():
    from swarmnav.models.scenario import Seeds, parse_scenario
    text = load_scenario("gwo-scenario-2").source_text.replace(
        'kind = "linear", speed_m_s = 0.05, heading_deg = 150.0, at_edge = "reflect"',
        'kind = "random_walk", step_m = 0.3, period_s = 1.0')
    env = NavigateEnv(parse_scenario(text, "random-walk.toml"), time_limit_s=5.0)
    one, again, two = (_walker_tracks(env, seed=s) for s in (1, 1, 2))
    assert np.array_equal(one, again) and not np.array_equal(one, two)
    assert env.task.seeds == Seeds.derived(2)
    pinned = _walker_tracks(env, seed=2, options={"world_seed": 1, "planner_seed": 9})
    assert env.task.seeds == Seeds(9, 1)
    assert np.array_equal(pinned, _walker_tracks(env, seed=5, options={"world_seed": 1}))
    # After a seeded reset, unseeded resets draw new worlds, the same sequence for the same first seed.
    sequence = [_walker_tracks(env, seed=3)] + [_walker_tracks(env) for _ in range(2)]
    assert not np.array_equal(sequence[1], sequence[2]) and not np.array_equal(sequence[0], sequence[1])
    replayed = [_walker_tracks(env, seed=3)] + [_walker_tracks(env) for _ in range(2)]
    assert all(np.array_equal(a, b) for a, b in zip(sequence, replayed))
