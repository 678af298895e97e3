"""``swarmnav bench study``: what the study harness costs and gains.

* parallel efficiency: the same 40-cell plan-only study on 2 worker processes against 1
  (wall time of the whole engine run, worker start-up included);
* harness overhead per cell: :func:`run_cell` (loading, the wall limit, rows) against
  the bare :func:`plan_episode` of the same cells, in this process;
* Ray against the local engine: the same study as Ray tasks on a local instance with
  2 CPUs (start-up and a warm-up round excluded) against 2 local worker processes.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

BENCH_STUDY = """
name = "bench-study"
scenarios = ["gwo-scenario-1", "gwo-scenario-2"]
mode = "plan"
seeds = {seeds}
[[planners]]
name = "gwo"
params = {{ iterations = {iterations} }}
"""



def _timed(results) -> tuple[float, int]:
    t0 = time.perf_counter()
    n = sum(1 for _ in results)
    return time.perf_counter() - t0, n


def run(args: argparse.Namespace) -> int:
    from swarmnav.models.scenario import load_scenario
    from swarmnav.sim.episode import EpisodeSpec, plan_episode
    from swarmnav.sim.study.cell import run_cell
    from swarmnav.sim.study.engines import run_local, run_ray, start_ray
    from swarmnav.sim.study.grid import expand
    from swarmnav.sim.study.spec import parse_study
    study = parse_study(BENCH_STUDY.format(seeds=args.seeds, iterations=args.iterations))
    cells = expand(study)
    out: dict = {"cells": len(cells)}

    one_s, _ = _timed(run_local(cells, 1))
    two_s, _ = _timed(run_local(cells, 2))
    out.update(local_1_worker_s=round(one_s, 3), local_2_workers_s=round(two_s, 3),
               parallel_speedup=round(one_s / two_s, 3))

    sample = cells[:10]
    run_cell(sample[0])  # warm caches and imports for both sides
    bare, harness = [], []
    for cell in sample:
        spec = EpisodeSpec(load_scenario(cell.scenario), cell.planner, cell.planner_params, cell.navigator,
                           cell.navigator_params, seed=cell.seed, world_seed=cell.world_seed,
                           clearance_m=cell.clearance_m)
        t0 = time.perf_counter()
        plan_episode(spec)
        bare.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        run_cell(cell)
        harness.append(time.perf_counter() - t0)
    out.update(episode_ms_per_cell=round(statistics.median(bare) * 1e3, 2),
               harness_overhead_ms_per_cell=round((statistics.median(harness) - statistics.median(bare)) * 1e3, 2))

    if not args.no_ray:
        try:
            import ray
        except ImportError:
            out["ray"] = "not installed"
        else:
            t0 = time.perf_counter()
            start_ray(None, 2)
            _timed(run_ray(cells[:4]))  # start-up and worker imports
            out["ray_startup_s"] = round(time.perf_counter() - t0, 3)
            ray_s, _ = _timed(run_ray(cells))
            ray.shutdown()
            out.update(ray_2_cpus_s=round(ray_s, 3), ray_throughput_vs_local=round(two_s / ray_s, 3))
    if args.json:
        print(json.dumps(out))
    else:
        print(f"{out['cells']}-cell plan-only study (gwo, {args.iterations} iterations):")
        print(f"  local engine: 1 worker {one_s:.2f} s, 2 workers {two_s:.2f} s -> speed-up "
              f"{out['parallel_speedup']:.2f}x (start-up included)")
        print(f"  harness overhead: {out['harness_overhead_ms_per_cell']:.2f} ms per cell "
              f"(episode alone {out['episode_ms_per_cell']:.1f} ms, median of {len(sample)})")
        if "ray_2_cpus_s" in out:
            print(f"  ray, local instance, 2 CPUs: {out['ray_2_cpus_s']:.2f} s (start-up {out['ray_startup_s']:.1f} s "
                  f"excluded) -> {out['ray_throughput_vs_local'] * 100:.0f}% of the local engine's throughput")
        elif "ray" in out:
            print(f"  ray: {out['ray']}")
    return 0
