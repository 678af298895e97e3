"""``swarmnav bench study``: what the study harness costs and gains.

* parallel efficiency: the same 40-cell plan-only study on 2 worker processes against 1,
  as wall time of the whole engine run (worker start-up included) and in the steady state
  (cells per second once every worker has delivered its first cell);
* harness overhead per cell: :func:`run_cell` (loading, the wall limit, rows) against
  the bare :func:`plan_episode` of the same cells, in this process;
* Ray against the local engine: the same study as Ray tasks on a local instance with
  2 CPUs (after a warm-up round) against 2 local worker processes, both in the steady state.

With ``--cells N ...`` it measures instead how the driver scales: plan-only studies
of about N cells each (A* and the straight line on four bundled scenarios, cells of
a few milliseconds, so the driver's bookkeeping is what grows), each run by
``swarmnav study --workers 2 --json`` in a process of its own on the local engine and
on a local Ray instance: cells per second (rows written and parts compacted, worker
and Ray start-up included), the driver's peak resident memory (the study's own
summary), and each rate over the smallest study's of the same engine.

The cells are GWO plans of ``--iterations`` (default 600, about 75 ms each here): with
the planners as fast as they are now, a 60-iteration cell takes 8 ms and the workers'
start-up (about a second) would be most of what the wall-time speed-up measures.
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



SCALE_STUDY = """
name = "bench-study-scale"
scenarios = ["gwo-scenario-1", "gwo-scenario-2", "gwo-scenario-3", "restaurant-table-2"]
mode = "plan"
seeds = {seeds}
[[planners]]
name = "astar"
[[planners]]
name = "straight"
"""
SCALE_CELLS_PER_SEED = 8  # four scenarios, two planners
MAX_SCALE_CELLS = 10_000_000


def run_scale(args: argparse.Namespace) -> int:
    """``bench study --cells N ...``: cells/s and the driver's peak memory per study size and engine."""
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    from swarmnav.models.errors import ConfigError
    if max(args.cells) > MAX_SCALE_CELLS:
        raise ConfigError("--cells", f"at most {MAX_SCALE_CELLS:,} cells, got {max(args.cells):,}")
    engines = ["local"] if args.no_ray else ["local", "ray"]
    results = []
    with tempfile.TemporaryDirectory(prefix="swarmnav-bench-study-") as folder:
        for engine in engines:
            for cells in sorted(set(args.cells)):
                seeds = -(-cells // SCALE_CELLS_PER_SEED)
                path = Path(folder) / f"scale-{seeds}.toml"
                path.write_text(SCALE_STUDY.format(seeds=seeds), encoding="utf-8")
                out = Path(folder) / f"out-{engine}-{seeds}"
                done = subprocess.run([sys.executable, "-m", "swarmnav.cli", "study", str(path), "--out", str(out),
                                       "--engine", engine, "--workers", "2", "--json"],
                                      capture_output=True, text=True)
                if done.returncode != 0:
                    raise RuntimeError(f"bench study --cells: the {engine} study of {seeds * 8} cells failed: "
                                       + (done.stderr.strip().splitlines() or ["?"])[-1])
                summary = json.loads(done.stdout)
                parts = len(list((out / "runs.parquet").glob("*.parquet")))
                results.append({"engine": engine, "cells": summary["ran"], "wall_s": summary["wall_s"],
                                "cells_per_s": round(summary["ran"] / summary["wall_s"], 1),
                                "driver_peak_mb": summary["driver_peak_mb"], "parts": parts,
                                "failed": summary["failed"]})
    for row in results:
        base = next(r for r in results if r["engine"] == row["engine"])
        row["rate_ratio"] = round(row["cells_per_s"] / base["cells_per_s"], 3)
    if args.json:
        print(json.dumps(results))
        return 0
    print(f"plan-only studies (astar and straight on four scenarios), 2 workers; rate: cells/s over the study's "
          f"run (start-up included); ratio: over the smallest study of the same engine")
    print(f"  {'engine':<6} {'cells':>9} {'wall s':>8} {'cells/s':>8} {'ratio':>6} {'driver MB':>10} {'parts':>6}")
    for r in results:
        print(f"  {r['engine']:<6} {r['cells']:>9,} {r['wall_s']:>8.1f} {r['cells_per_s']:>8.1f} "
              f"{r['rate_ratio']:>6.3f} {r['driver_peak_mb']:>10.0f} {r['parts']:>6}")
    return 0


def _arrivals(results) -> list[float]:
    """Seconds from the engine's start to each result's arrival."""
    t0 = time.perf_counter()
    out = []
    for _ in results:
        out.append(time.perf_counter() - t0)
    return out


def steady_rate(arrivals: list[float], workers: int) -> float:
    """Cells per second once every worker has delivered its first cell (start-up and imports excluded)."""
    k = min(workers, len(arrivals) - 1)
    return (len(arrivals) - k) / (arrivals[-1] - arrivals[k - 1])


def run(args: argparse.Namespace) -> int:
    if getattr(args, "cells", None):
        return run_scale(args)
    from swarmnav.models.scenario import load_scenario
    from swarmnav.sim.episode import EpisodeSpec, plan_episode
    from swarmnav.study.cell import run_cell
    from swarmnav.study.engines import run_local
    from swarmnav.study.ray_engine import run_ray, start_ray
    from swarmnav.study.grid import expand
    from swarmnav.study.spec import parse_study
    study = parse_study(BENCH_STUDY.format(seeds=args.seeds, iterations=args.iterations))
    cells = expand(study)
    out: dict = {"cells": len(cells)}

    # Rounds of 1 worker then 2, back to back; medians over the rounds (one run of the same engine varies by
    # 15 % here from one minute to the next).
    rounds = [(_arrivals(run_local(cells, 1)), _arrivals(run_local(cells, 2))) for _ in range(args.rounds)]
    one_s = statistics.median(one[-1] for one, _ in rounds)
    two_s = statistics.median(two[-1] for _, two in rounds)
    out.update(rounds=args.rounds, local_1_worker_s=round(one_s, 3), local_2_workers_s=round(two_s, 3),
               parallel_speedup=round(statistics.median(one[-1] / two[-1] for one, two in rounds), 3),
               parallel_speedup_steady=round(statistics.median(steady_rate(two, 2) / steady_rate(one, 1)
                                                               for one, two in rounds), 3))

    # The overhead is the same whatever the cell's size: measured on light cells (20 iterations) so that the
    # planner's own run-to-run noise does not drown it.
    sample = expand(parse_study(BENCH_STUDY.format(seeds=10, iterations=20)))[:10]
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
            _arrivals(run_ray(cells[:4]))  # start-up and worker imports
            out["ray_startup_s"] = round(time.perf_counter() - t0, 3)
            arrivals = _arrivals(run_ray(cells))
            ray.shutdown()
            local_rate = statistics.median(steady_rate(two, 2) for _, two in rounds)
            out.update(ray_2_cpus_s=round(arrivals[-1], 3),
                       ray_throughput_vs_local=round(steady_rate(arrivals, 2) / local_rate, 3))
    if args.json:
        print(json.dumps(out))
    else:
        print(f"{out['cells']}-cell plan-only study (gwo, {args.iterations} iterations), medians of "
              f"{args.rounds} rounds:")
        print(f"  local engine: 1 worker {one_s:.2f} s, 2 workers {two_s:.2f} s -> speed-up "
              f"{out['parallel_speedup']:.2f}x (start-up included), {out['parallel_speedup_steady']:.2f}x in the "
              f"steady state (cells per second once every worker has delivered its first; target >= 1.8x)")
        print(f"  harness overhead: {out['harness_overhead_ms_per_cell']:.2f} ms per cell "
              f"(a 20-iteration episode alone {out['episode_ms_per_cell']:.1f} ms, median of {len(sample)}; "
              f"target < 5 ms)")
        if "ray_2_cpus_s" in out:
            print(f"  ray, local instance, 2 CPUs: {out['ray_2_cpus_s']:.2f} s (start-up {out['ray_startup_s']:.1f} s "
                  f"excluded) -> {out['ray_throughput_vs_local'] * 100:.0f}% of the local engine's steady-state "
                  f"throughput (target >= 80%)")
        elif "ray" in out:
            print(f"  ray: {out['ray']}")
    return 0
