"""``swarmnav bench env``: the Gymnasium environment against the closed-loop runner and bare ``mj_step``.

All three run in this process, interleaved, on ``dense-field-30``: the
environment with uniformly random normalised (v, omega) actions (episodes
reset as they end), the runner's ``follow`` loop (planned once, before
timing), and ``mj_step`` with constant wheel commands on the same compiled
model.  Rates are control steps per second (bare: physics steps per second
divided by the physics steps per control step), so the ratios compare like
with like.  Target: environment >= 0.9 x runner.

Random actions and the ``follow`` loop drive different trajectories, and the
physics costs more near obstacles (the step-by-step contact check), so a
fourth figure compares like with like: the environment in ``wheels`` mode
replaying the runner's own wheel commands (the same trajectory, bit for bit),
``env_replay_vs_runner``: the environment's overhead alone.

Vectorised throughput: ``gymnasium.vector.AsyncVectorEnv`` (one process per
environment, the way SB3's ``SubprocVecEnv`` and Gymnasium users scale out) with 2
workers against the same AsyncVectorEnv with 1, environment steps per second summed
over the workers (``vector_2_vs_1``, the median of the interleaved repeats' ratios;
target >= 1.7 on 2 free cores, a machine shared with other work gives less).  The
workers are spawned with one BLAS / OpenMP thread each (MuJoCo steps on the calling
thread), each step holds its action for ``vector_action_repeat`` control periods so
that the worker's step, not the pipe's round trip and the parent's batching, is what
is measured, and the actions are drawn before the clock starts.  ``--quick`` runs
the same measurement over 4 simulated seconds twice (a smoke run; noisier).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import time

import mujoco
import numpy as np

from swarmnav.benchmarks.figures import print_figures
from swarmnav.sim.episode import EpisodeSpec, plan_episode, run_episode
from swarmnav.sim.defaults import BENCH_ENV_QUICK, SINGLE_THREAD_ENVIRONMENT
from swarmnav.sim.simulation import Simulation

VECTOR_ACTION_REPEAT = 5  # control periods per vectorised environment step (about 1 ms of work in the worker)


def _env_steps_per_s(env, actions: np.ndarray) -> float:
    """Steps per second of ``env`` driven by ``actions`` (drawn before the clock starts)."""
    env.reset(seed=0)
    t0 = time.perf_counter()
    for action in actions:
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            env.reset()
    return len(actions) / (time.perf_counter() - t0)


@contextlib.contextmanager
def _single_thread_environment():
    """The thread limits of ``SINGLE_THREAD_ENVIRONMENT`` in ``os.environ`` while workers are spawned."""
    saved = {name: os.environ.get(name) for name in SINGLE_THREAD_ENVIRONMENT}
    os.environ.update(SINGLE_THREAD_ENVIRONMENT)
    try:
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


def _vector_steps_per_s(scenario_name: str, workers: int, steps: int) -> float:
    """Environment steps per second of an AsyncVectorEnv of ``workers`` processes, ``steps`` batched steps.

    The workers are spawned (fresh interpreters, nothing inherited from this process) with one BLAS / OpenMP
    thread each, so that each runs on one core; each environment step holds its action for
    ``VECTOR_ACTION_REPEAT`` control periods (a step worth the inter-process round trip); the actions are
    drawn before the clock starts.
    """
    import functools

    import gymnasium

    from swarmnav.env import NavigateEnv
    with _single_thread_environment():
        vector = gymnasium.vector.AsyncVectorEnv(
            [functools.partial(NavigateEnv, scenario_name, action_repeat=VECTOR_ACTION_REPEAT)] * workers,
            context="spawn")
    try:
        vector.action_space.seed(0)
        actions = [vector.action_space.sample() for _ in range(steps)]
        vector.reset(seed=0)
        vector.step(vector.action_space.sample())  # the workers are up before the clock starts
        t0 = time.perf_counter()
        for action in actions:
            vector.step(action)  # episodes reset on their own (next-step autoreset)
        return workers * steps / (time.perf_counter() - t0)
    finally:
        vector.close()


def _runner_steps_per_s(simulation: Simulation, planned, duration_s: float):
    """The runner's rate and its wheel commands (for the replay)."""
    result = run_episode(planned, time_limit_s=duration_s).result
    return result.steps / result.wall_time_s, result.wheel_command_rad_s[:-1]


def _env_replay_steps_per_s(env, wheel_commands: np.ndarray) -> float:
    env.reset(seed=0)
    t0 = time.perf_counter()
    for command in wheel_commands:
        _, _, terminated, truncated, _ = env.step(command)
        if terminated or truncated:  # a --duration beyond the scenario's time limit: the next episode
            env.reset()
    return len(wheel_commands) / (time.perf_counter() - t0)


def _bare_control_steps_per_s(simulation: Simulation, control_steps: int) -> float:
    data = simulation.reset()
    data.ctrl[:] = [3.0, 3.2]
    steps = control_steps * simulation.steps_per_control
    t0 = time.perf_counter()
    mujoco.mj_step(simulation.model, data, steps)
    return control_steps / (time.perf_counter() - t0)


def benchmark_env(scenario_name: str = "dense-field-30", duration_s: float = 20.0,
                  repeats: int = 3) -> dict[str, float | int | str]:
    """Median control steps per second of the three, and the environment's ratios to the other two."""
    from swarmnav.env import NavigateEnv  # dm_control and Gymnasium load only for this benchmark
    env = NavigateEnv(scenario_name)
    replay_env = NavigateEnv(scenario_name, action="wheels")
    planned = plan_episode(EpisodeSpec(env.task.scenario))
    simulation = planned.simulation
    control_steps = int(round(duration_s / simulation.control_dt_s))
    actions = np.random.default_rng(0).uniform(-1.0, 1.0, (control_steps, 2))
    envs, runners, bares, ratios, replays, replay_ratios = [], [], [], [], [], []
    for _ in range(repeats):
        e = _env_steps_per_s(env, actions)
        r, commands = _runner_steps_per_s(simulation, planned, duration_s)
        replays.append(_env_replay_steps_per_s(replay_env, commands))
        replay_ratios.append(replays[-1] / r)
        b = _bare_control_steps_per_s(simulation, control_steps)
        envs.append(e)
        runners.append(r)
        bares.append(b)
        ratios.append(e / r)
    env.close()
    replay_env.close()
    vector_steps = max(control_steps // VECTOR_ACTION_REPEAT, 1)
    vector_1, vector_2 = [], []
    for _ in range(repeats):  # interleaved, as the rows above
        vector_1.append(_vector_steps_per_s(scenario_name, 1, vector_steps))
        vector_2.append(_vector_steps_per_s(scenario_name, 2, vector_steps))
    return {
        "scenario": scenario_name,
        "control_hz": round(1.0 / simulation.control_dt_s, 6),
        "physics_steps_per_control": simulation.steps_per_control,
        "control_steps_per_run": control_steps,
        "repeats": repeats,
        "env_steps_per_s": statistics.median(envs),
        "runner_steps_per_s": statistics.median(runners),
        "bare_control_steps_per_s": statistics.median(bares),
        "env_vs_runner": statistics.median(ratios),
        "env_vs_bare": statistics.median(envs) / statistics.median(bares),
        "env_replay_steps_per_s": statistics.median(replays),
        "env_replay_vs_runner": statistics.median(replay_ratios),
        "target_env_vs_runner": 0.9,
        "vector_action_repeat": VECTOR_ACTION_REPEAT,
        "vector_steps_per_run": vector_steps,
        "vector_1_steps_per_s": statistics.median(vector_1),
        "vector_2_steps_per_s": statistics.median(vector_2),
        "vector_2_vs_1": statistics.median(two / one for one, two in zip(vector_1, vector_2)),
        "target_vector_2_vs_1": 1.7,
    }


def run(args: argparse.Namespace) -> int:
    duration_s, repeats = BENCH_ENV_QUICK if args.quick else (args.duration, args.repeats)
    print_figures(benchmark_env(args.scenario, duration_s=duration_s, repeats=repeats), args.json)
    return 0
