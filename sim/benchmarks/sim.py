"""``swarmnav bench sim``: the closed loop against bare ``mj_step`` on one compiled model.

Both run in this process, interleaved, on the same model, so the ratio is
robust to a noisy machine.  Planning is done once, before timing.  The bare
reference replays the closed loop's own wheel commands (one ``ctrl`` write and one
``mj_step(model, data, k)`` per control step), so both drive the same trajectory with
the same contacts: the ratio is the cost of swarmnav's work per control step alone.
(It used to drive fixed wheel speeds, circling near the start and touching an obstacle
on about 9 % of its steps, which made the bare physics dearer than the closed loop's.)
Each repeat times bare, closed loop and logged closed loop back to back; the figures
are medians over the repeats.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path as FilePath

import mujoco

from swarmnav.benchmarks.figures import print_figures
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import MAX_CONTROL_STEPS, load_scenario
from swarmnav.sim.defaults import BENCH_SIM_QUICK
from swarmnav.sim.episode import Episode, EpisodeSpec, plan_episode, run_episode
from swarmnav.sim.simulation import Simulation

# The closed loop's targets on a quiet machine: its rate against bare mj_step, without and with the MCAP log.
TARGET_RATIO, TARGET_LOGGING_RATIO = 0.92, 0.80


def _bare_steps_per_s(simulation: Simulation, wheel_commands_rad_s: list[tuple[float, float]]) -> float:
    """Physics steps per second replaying ``wheel_commands_rad_s`` (one per control step) with bare MuJoCo."""
    model, data = simulation.model, simulation.reset()
    k = simulation.steps_per_control
    ctrl = data.ctrl
    step = mujoco.mj_step
    t0 = time.perf_counter()
    for left, right in wheel_commands_rad_s:
        ctrl[0] = left
        ctrl[1] = right
        step(model, data, k)
    return len(wheel_commands_rad_s) * k / (time.perf_counter() - t0)


def _closed_loop(simulation: Simulation, planned: Episode, duration_s: float, recorders=()):
    """(physics steps per second, realtime factor, the wheel commands it sent) of one closed-loop run."""
    result = run_episode(planned, recorders, time_limit_s=duration_s).result
    steps = result.steps * simulation.steps_per_control
    commands = [(float(left), float(right)) for left, right in result.wheel_command_rad_s]
    return steps / result.wall_time_s, result.sim_time_s / result.wall_time_s, commands


def benchmark_sim(scenario_name: str = "dense-field-30", duration_s: float = 20.0,
                  repeats: int = 3, with_logging: bool = True, sensing: bool = True) -> dict[str, float | int | str]:
    """Measure closed-loop and bare stepping rates; returns the figures ``bench sim`` prints.

    The closed loop is 500 Hz physics, 50 Hz control, 12 rangefinders, the
    collision and clearance checks, no logging; the logging row adds the MCAP
    recorder.  ``duration_s`` must be shorter than the run to the goal so that
    every measurement covers the same simulated time.  ``sensing``: also the laser, sensed-map and Jackal
    lines of :mod:`swarmnav.benchmarks.sensing`.
    """
    scenario = load_scenario(scenario_name)
    if not duration_s * scenario.sim.control_hz <= MAX_CONTROL_STEPS:
        raise ConfigError("--duration", f"{duration_s:g} s at {scenario.sim.control_hz:g} Hz needs "
                          f"{duration_s * scenario.sim.control_hz:.4g} control steps (at most {MAX_CONTROL_STEPS:,})")
    planned = plan_episode(EpisodeSpec(scenario))
    simulation = planned.simulation
    bare, closed, ratios, realtime, logging, logging_ratios = [], [], [], [], [], []
    commands = _closed_loop(simulation, planned, duration_s)[2]  # untimed: the trajectory both replay
    recorder_cls = None
    if with_logging:
        try:
            from swarmnav.log.writer import McapRecorder
            recorder_cls = McapRecorder
        except ImportError:
            recorder_cls = None
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(repeats):
            b = _bare_steps_per_s(simulation, commands)
            c, rt, _ = _closed_loop(simulation, planned, duration_s)
            bare.append(b)
            closed.append(c)
            realtime.append(rt)
            ratios.append(c / b)
            if recorder_cls is not None:
                recorder = recorder_cls(FilePath(tmp) / f"bench_{r}.mcap", overwrite=True)
                lg, _, _ = _closed_loop(simulation, planned, duration_s, [recorder])
                logging.append(lg)
                logging_ratios.append(lg / b)
    figures: dict[str, float | int | str] = {
        "scenario": scenario.name,
        "physics_hz": round(1.0 / simulation.model.opt.timestep, 6),
        "control_hz": round(1.0 / simulation.control_dt_s, 6),
        "rangefinders": int(len(simulation.scene.range_sensor_adr)),
        "geoms": int(simulation.model.ngeom),
        "simulated_s_per_run": duration_s,
        "repeats": repeats,
        "closed_loop_steps_per_s": statistics.median(closed),
        "bare_steps_per_s": statistics.median(bare),
        "ratio": statistics.median(ratios),
        "realtime_factor": statistics.median(realtime),
        "target_ratio": TARGET_RATIO,
    }
    if logging:
        figures["logging_steps_per_s"] = statistics.median(logging)
        figures["logging_ratio"] = statistics.median(logging_ratios)
        figures["target_logging_ratio"] = TARGET_LOGGING_RATIO
    if sensing:
        from swarmnav.benchmarks.sensing import sensing_figures
        figures.update(sensing_figures(duration_s, repeats))
    return figures


def run(args: argparse.Namespace) -> int:
    duration_s, repeats = BENCH_SIM_QUICK if args.quick else (args.duration, args.repeats)
    print_figures(benchmark_sim(args.scenario, duration_s=duration_s, repeats=repeats), args.json)
    return 0
