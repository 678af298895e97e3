"""``swarmnav bench navigation``: every navigator on the bundled dynamic suite, the way navigation
benchmarks report it (BARN, Nav2, CrowdNav): success, collisions, timeouts, SPL, danger, cost.

Every navigator x every scenario of the suite (the bundled ``dyn-*`` files,
made by ``swarmnav scenarios generate``) x N world seeds (run k uses world
seed k and planner seed k), run as a physics study (the study machinery, in this
process; ``--out DIR`` keeps its rows for ``swarmnav report``).  One row per navigator; every run counts in every
rate (failures are never dropped from the denominators).  ``mean_time_to_goal_s``
averages the successful runs only.  ``navigator_us_per_step`` is the wall time
measured around the navigator's ``step`` call per control step;
``realtime_factor`` is simulated over wall time of whole runs (physics, sensing,
navigator).  Scenarios whose obstacles all move on fixed lines give the same run
for every world seed; they are still counted once per seed.  ``--by-scenario``
adds one row per navigator and scenario (the same columns plus ``scenario``), to
see where the failures are.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from typing import Any

from swarmnav.controllers.navigators import NAVIGATORS
from swarmnav.models.scenario import list_scenarios, load_scenario

SUITE_PREFIX = "dyn-"


def default_navigators(settings: dict[str, dict[str, Any]] | None = None) -> list[str]:
    """Every registered navigator that runs with its default parameters, or with its share of ``settings``
    (``policy`` needs a callable: it joins when ``--navigator-set policy=module:function`` names one)."""
    from swarmnav.controllers.navigators import make_navigator
    from swarmnav.models.errors import ConfigError
    names = []
    for name in NAVIGATORS:
        try:
            make_navigator(name, (settings or {}).get(name))
        except ConfigError:
            if name in (settings or {}):
                raise  # asked for with a bad value: say so rather than leave it out
            continue
        names.append(name)
    return names


def navigator_settings(pairs: dict[str, Any], navigators: list[str]) -> dict[str, dict[str, Any]]:
    """``--navigator-set KEY=VALUE``: each navigator gets the keys it has as parameters; a key none has is an error."""
    import dataclasses
    from swarmnav.models.errors import ConfigError
    out: dict[str, dict[str, Any]] = {}
    for key, value in pairs.items():
        takers = [n for n in navigators if key in {f.name for f in dataclasses.fields(NAVIGATORS[n]) if f.init}]
        if not takers:
            raise ConfigError("--navigator-set", f"no navigator of this benchmark has a parameter {key!r}")
        for name in takers:
            out.setdefault(name, {})[key] = value
    return out


def suite_names() -> list[str]:
    """The bundled dynamic suite: scenarios named ``dyn-*``."""
    return [name for name in list_scenarios() if name.startswith(SUITE_PREFIX)]


def navigation_study(seeds: int, navigators: list[str], scenarios: list[str],
                     navigator_params: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """The benchmark as a physics study: each scenario with its own planner, every navigator, run ``k`` with
    world seed ``k`` and planner seed ``k`` (paired)."""
    planners = list(dict.fromkeys(load_scenario(name).planner_name for name in scenarios))
    return {"name": "bench-navigation", "scenarios": scenarios, "mode": "physics", "seeds": seeds,
            "world_seeds": list(range(seeds)), "paired_seeds": True,
            "planners": [{"name": p} for p in planners],
            "navigators": [{"name": n, "params": navigator_params.get(n, {})} for n in navigators]}


def benchmark_navigation(seeds: int = 5, navigators: list[str] | None = None, scenarios: list[str] | None = None,
                         progress: bool = False, navigator_params: dict[str, dict[str, Any]] | None = None,
                         by_scenario: bool = False, out_dir: str | None = None) -> list[dict[str, Any]]:
    """One row per navigator (see the module docstring); ``navigator_params``: per navigator name.  With
    ``by_scenario`` one row per navigator and scenario after them (each with a ``scenario`` key; the
    overall rows have ``scenario`` None).  The runs are a study's rows, kept in ``out_dir`` when given."""
    from swarmnav.sim.study.execute import run_study_tables

    navigator_params = navigator_params or {}
    navigators = navigators or default_navigators(navigator_params)
    names = scenarios or suite_names()
    tables = navigation_study(seeds, navigators, names, navigator_params)
    if out_dir is None:
        with tempfile.TemporaryDirectory(prefix="swarmnav-bench-navigation-") as folder:
            rows = run_study_tables(tables, folder, show_progress=progress)
    else:
        rows = run_study_tables(tables, out_dir, show_progress=progress)
    runs = {n: [r for r in rows if r["navigator"] == n] for n in navigators}
    table = [{"scenario": None, **_row(nav, arm)} for nav, arm in runs.items()]
    if by_scenario:
        for name in names:
            for nav, arm in runs.items():
                table.append({"scenario": name, **_row(nav, [r for r in arm if r["scenario"] == name])})
    return table


def _mean(values: list[float]) -> float | None:
    return sum(values) / len(values) if values else None


def _row(navigator: str, rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Rates over every run (a run that raised, or found no path, counts as a failure in each rate's
    denominator); means over the runs that drove."""
    n = len(rows)
    drove = [r for r in rows if r["outcome"] == "ok"]
    reached = [r["time_to_goal_s"] for r in rows if r["success"]]
    steps = sum(r["control_steps"] for r in drove)
    return {
        "navigator": navigator, "runs": n, "failed_runs": n - len(drove),
        "success_rate": sum(bool(r["success"]) for r in rows) / n,
        "collision_rate": sum(bool(r["collisions"]) for r in drove) / n,
        "timeout_rate": sum(r["run_outcome"] == "timeout" for r in drove) / n,
        "mean_time_to_goal_s": _mean(reached),
        "mean_spl": _mean([r["spl"] or 0.0 for r in drove]),
        "mean_time_in_danger_s": _mean([r["time_in_danger_s"] for r in drove]),
        "mean_replans": _mean([r["replans"] for r in drove]),
        "navigator_us_per_step": 1e6 * sum(r["navigator_wall_s"] for r in drove) / max(steps, 1),
        "realtime_factor": sum(r["sim_time_s"] for r in drove) / max(sum(r["wall_time_s"] for r in drove), 1e-9),
    }


def run(args: argparse.Namespace) -> int:
    from swarmnav.models.errors import ConfigError
    if args.seeds < 1:
        raise ConfigError("--seeds", f"must be at least 1, got {args.seeds}")
    for name in args.navigator or []:
        if name not in NAVIGATORS:
            raise ConfigError("--navigator", f"unknown navigator {name!r} (known: {', '.join(sorted(NAVIGATORS))})")
    if args.suite == "papers":
        from swarmnav.sim.benchmarks.paper_navigation import (PAPER_SUITE, benchmark_paper_navigation,
                                                              print_table)
        paper_rows = benchmark_paper_navigation(args.seeds, tuple(args.scenario or PAPER_SUITE), args.out)
        print(json.dumps(paper_rows)) if args.json else print_table(paper_rows)
        return 0
    from swarmnav.sim.cli import parse_settings  # loaded already: the CLI is what calls this
    settings = navigator_settings(parse_settings(args.navigator_set, "--navigator-set"),
                                  args.navigator or list(NAVIGATORS))
    rows = benchmark_navigation(args.seeds, args.navigator, args.scenario,
                                progress=not args.json and sys.stderr.isatty(), navigator_params=settings,
                                by_scenario=args.by_scenario, out_dir=args.out)
    if args.json:
        print(json.dumps(rows))
        return 0
    overall = [r for r in rows if r["scenario"] is None]
    _print_table(overall, "")
    if args.by_scenario:
        for name in dict.fromkeys(r["scenario"] for r in rows if r["scenario"] is not None):
            print()
            _print_table([r for r in rows if r["scenario"] == name], name)
    return 0


def _print_table(rows: list[dict[str, Any]], title: str) -> None:
    if title:
        print(title)
    header = (f"{'navigator':<18} {'runs':>4} {'success':>7} {'collide':>7} {'timeout':>7} {'t_goal_s':>8} "
              f"{'SPL':>5} {'danger_s':>8} {'replans':>7} {'us/step':>8} {'x_realtime':>10}")
    print(header)
    for r in rows:
        t_goal = f"{r['mean_time_to_goal_s']:.1f}" if r["mean_time_to_goal_s"] is not None else "-"
        print(f"{r['navigator']:<18} {r['runs']:>4} {r['success_rate']:>7.2f} {r['collision_rate']:>7.2f} "
              f"{r['timeout_rate']:>7.2f} {t_goal:>8} {r['mean_spl']:>5.2f} {r['mean_time_in_danger_s']:>8.2f} "
              f"{r['mean_replans']:>7.1f} {r['navigator_us_per_step']:>8.0f} {r['realtime_factor']:>10.1f}")
