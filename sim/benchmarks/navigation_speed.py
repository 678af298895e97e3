"""The speed lines of ``swarmnav bench navigation``: figures printed, never asserted (speed is not a test).

* **The oracle's search** (:func:`controllers.oracle_search.search`, clairvoyant): wall and CPU seconds to
  decide each scene the benchmark ran (scenario and world seed), timed on its own here (in the runs it is part of
  the oracle's reset); the median and the maximum per scene (target: every scene of the bundled ``dyn-*``
  suite under 2 s).
* **MPPI's control step** at 1,000 samples x 30 steps (the navigator's defaults), optimising at *every*
  control step (``optimise_period_s = 0``; its default optimises at 10 Hz and replays the sequence between),
  driven in physics on :data:`MPPI_SCENES` for up to :data:`MPPI_SIM_S` simulated seconds each: microseconds
  of wall and of this thread's CPU inside ``step`` per control step (target: at most 1,000).
* **Real-time factors** per navigator, from the benchmark's rows: simulated over wall time and over the runs'
  own CPU time (``run_cpu_s``: what the run costs whatever else loads the machine); target at least 30x.
* **The oracle's physics success** on the scenes it called solvable (target at least 95 %), from its row.
* **CPU per run** on the BARN suites (``cpu_s_per_run``: the mean ``run_cpu_s``, each run's own thread CPU),
  per navigator, and what all 300 worlds x 1 run would cost at those means (CPU minutes, and minutes on 2 cores).

Each figure goes with the machine's load average (``os.getloadavg``), since the wall times of a shared
machine say as much about the other jobs as about swarmnav.
"""

from __future__ import annotations

import os
import statistics
import time
from dataclasses import replace
from typing import Any

MPPI_SCENES = ("dyn-crowd-2", "dyn-crowd-3", "dyn-crossing-2")  # the most obstacles, both sensing models
MPPI_SIM_S = 15.0
ORACLE_TARGET_S = 2.0
MPPI_TARGET_US = 1000.0
REALTIME_TARGET = 30.0
ORACLE_SUCCESS_TARGET = 0.95
BARN_WORLDS = 300  # the BARN line's projection: every world once (the budget: 60 min on 2 cores)


def load_average() -> float:
    return round(os.getloadavg()[0], 2)


def oracle_search_times(scenes: list[tuple[str, int | None]]) -> dict[str, Any]:
    """Wall and CPU seconds of the oracle's search on each (scenario ref, world seed)."""
    from swarmnav.controllers.oracle_search import reactive_agents, search
    from swarmnav.models.scenario import load_scenario
    wall, cpu, names = [], [], []
    load = load_average()
    for ref, world_seed in scenes:
        scenario = load_scenario(ref)
        if world_seed is not None:
            scenario = scenario.with_world_seed(world_seed)
        if reactive_agents(scenario):  # no yardstick there: the oracle does not search
            continue
        w0, c0 = time.perf_counter(), time.thread_time()
        search(scenario)
        cpu.append(time.thread_time() - c0)
        wall.append(time.perf_counter() - w0)
        names.append(f"{scenario.name}@{scenario.world_seed}")
    if not wall:
        return {}
    worst = max(range(len(wall)), key=wall.__getitem__)
    return {"scenes": len(wall), "median_s": round(statistics.median(wall), 4), "max_s": round(max(wall), 4),
            "max_scene": names[worst], "median_cpu_s": round(statistics.median(cpu), 4),
            "max_cpu_s": round(max(cpu), 4), "load_average": load}


class _TimedNavigator:
    """A navigator as it is, with the wall and thread CPU seconds of its ``step`` calls added up."""

    def __init__(self, inner):
        self.inner = inner
        self.uses_detections, self.uses_planner = inner.uses_detections, inner.uses_planner
        self.wall_s = self.cpu_s = 0.0
        self.steps = 0

    @property
    def replan_wall_s(self) -> float:
        return self.inner.replan_wall_s

    def reset(self, setup) -> None:
        self.inner.reset(setup)

    def step(self, observation):
        w0, c0 = time.perf_counter(), time.thread_time()
        out = self.inner.step(observation)
        self.cpu_s += time.thread_time() - c0
        self.wall_s += time.perf_counter() - w0
        self.steps += 1
        return out


def mppi_step_cost(scenes: tuple[str, ...] = MPPI_SCENES, sim_s: float = MPPI_SIM_S) -> dict[str, Any]:
    """Microseconds per control step of ``mppi`` optimising at every step (module docstring)."""
    from swarmnav.controllers.navigators.mppi import MppiNavigator
    from swarmnav.models.scenario import load_scenario
    from swarmnav.sim.episode import EpisodeSpec, plan_episode, run_episode
    params = {"optimise_period_s": 0.0}
    default = MppiNavigator()
    load = load_average()
    per_scene, wall, cpu, steps = {}, 0.0, 0.0, 0
    for name in scenes:
        scenario = load_scenario(name)
        episode = plan_episode(EpisodeSpec(scenario, scenario.planner_name, {}, "mppi", params, seed=0, world_seed=0))
        timed = _TimedNavigator(episode.navigator)
        run_episode(replace(episode, navigator=timed), time_limit_s=min(sim_s, scenario.time_limit_s))
        per_scene[name] = round(1e6 * timed.cpu_s / max(timed.steps, 1), 1)
        wall, cpu, steps = wall + timed.wall_s, cpu + timed.cpu_s, steps + timed.steps
    return {"samples": default.samples, "horizon_steps": default.horizon_steps, "steps": steps,
            "us_per_step": round(1e6 * wall / max(steps, 1), 1), "cpu_us_per_step": round(1e6 * cpu / max(steps, 1), 1),
            "cpu_us_per_step_by_scene": per_scene, "load_average": load}


def speed_lines(rows: list[dict[str, Any]], oracle: dict[str, Any], mppi: dict[str, Any] | None) -> list[str]:
    """The printed lines (see the module docstring) from the benchmark's overall rows and the two timings."""
    def verdict(ok: bool) -> str:
        return "meets" if ok else "MISSES"
    lines = []
    if oracle:
        lines.append(f"oracle search: median {oracle['median_s']:.3f} s, max {oracle['max_s']:.3f} s per scene "
                     f"({oracle['max_scene']}) over {oracle['scenes']} scenes; CPU median {oracle['median_cpu_s']:.3f} "
                     f"s, max {oracle['max_cpu_s']:.3f} s ({verdict(oracle['max_cpu_s'] < ORACLE_TARGET_S)} the "
                     f"target < {ORACLE_TARGET_S:g} s; load average {oracle['load_average']})")
    if mppi:
        lines.append(f"mppi ({mppi['samples']} samples x {mppi['horizon_steps']} steps, optimising every step): "
                     f"{mppi['cpu_us_per_step']:.0f} us CPU per control step ({mppi['us_per_step']:.0f} us wall) over "
                     f"{mppi['steps']} steps ({verdict(mppi['cpu_us_per_step'] <= MPPI_TARGET_US)} the target <= "
                     f"{MPPI_TARGET_US:g} us; load average {mppi['load_average']})")
    factors = [f"{r['navigator']} {r['realtime_factor']:.1f}x wall / "
               f"{'-' if r.get('realtime_factor_cpu') is None else format(r['realtime_factor_cpu'], '.1f')}x CPU"
               for r in rows]
    slow = [r["navigator"] for r in rows if (r.get("realtime_factor_cpu") or 0.0) < REALTIME_TARGET]
    lines.append("real-time factor: " + "; ".join(factors) + f" (target >= {REALTIME_TARGET:g}x; "
                 + (f"below it on CPU: {', '.join(slow)}" if slow else "every navigator meets it on CPU")
                 + f"; load average {load_average()})")
    barn = [r for r in rows if "barn_score" in r and r.get("cpu_s_per_run") is not None]
    if barn:
        total_min = BARN_WORLDS * sum(r["cpu_s_per_run"] for r in barn) / 60.0
        lines.append("CPU per run: " + ", ".join(f"{r['navigator']} {r['cpu_s_per_run']:.2f} s" for r in barn)
                     + f" (BARN's {BARN_WORLDS} worlds x 1 run at these means: {total_min:.1f} CPU-min, "
                     f"{total_min / 2.0:.1f} min on 2 cores; load average {load_average()})")
    for r in rows:
        if r.get("success_on_solvable") is not None:
            lines.append(f"oracle physics success on its solvable scenes: {r['success_on_solvable']:.3f} of "
                         f"{r['oracle_solvable_runs']} ({verdict(r['success_on_solvable'] >= ORACLE_SUCCESS_TARGET)} "
                         f"the target >= {ORACLE_SUCCESS_TARGET:g})")
    return lines


CROWD_AGENTS = 20
CROWD_STEPS = 500
CROWD_TARGET_US = 50.0


def crowd_step_cost(agents: int = CROWD_AGENTS, steps: int = CROWD_STEPS) -> dict[str, Any]:
    """Microseconds per agent per control step (wall and this thread's CPU) of :class:`CrowdSession.advance`,
    for ``agents`` ORCA agents and, apart, as many social-force agents, on a circle of radius 4 m each heading to
    the opposite point (CrowdNav's circle crossing, denser), at 50 Hz, seeing a robot standing at the centre."""
    import math

    import numpy as np

    from swarmnav.models.crowd_agents import AgentSpec, Crowd, CrowdSession
    out: dict[str, Any] = {"agents": agents, "steps": steps, "load_average": load_average()}
    for kind in ("orca", "social_force"):
        specs = []
        for k in range(agents):
            a = 2.0 * math.pi * k / agents
            x, y = 6.0 + 4.0 * math.cos(a), 6.0 + 4.0 * math.sin(a)
            specs.append(AgentSpec(kind, (x, y), 0.3, ((12.0 - x, 12.0 - y),), 1.0, True))
        crowd = Crowd(tuple(specs), np.zeros((0, 3)), np.zeros((0, 4)), (12.0, 12.0), False, 0.02, steps, 0)
        session = CrowdSession(crowd)
        robot = (6.0, 6.0, 0.0, 0.0, 0.3)
        w0, c0 = time.perf_counter(), time.thread_time()
        for step in range(steps):
            session.advance(step, robot)
        per = 1e6 / (steps * agents)
        out[kind] = {"us_per_agent_step": round((time.perf_counter() - w0) * per, 2),
                     "cpu_us_per_agent_step": round((time.thread_time() - c0) * per, 2)}
    return out


def crowd_line(cost: dict[str, Any]) -> str:
    parts = [f"{kind} {cost[kind]['cpu_us_per_agent_step']:.1f} us CPU ({cost[kind]['us_per_agent_step']:.1f} wall)"
             for kind in ("orca", "social_force")]
    worst = max(cost[kind]["cpu_us_per_agent_step"] for kind in ("orca", "social_force"))
    return (f"agents: {', '.join(parts)} per agent per control step with {cost['agents']} agents seeing the robot "
            f"({'meets' if worst <= CROWD_TARGET_US else 'misses'} the target <= {CROWD_TARGET_US:g} us on CPU; "
            f"load average {cost['load_average']:g})")
