"""``swarmnav bench defaults``: does each paper's planner, at its defaults, plan a collision-free path on each of
its paper's bundled scenarios?

Each (planner, scenario) of :data:`PAPER_CASES` is planned with no parameter set (the planner's defaults: paper
mode for the continuous planners, :mod:`planners.run_settings`) on seeds ``0 .. N-1``; a seed counts when the
plan exists (the planners check their answer exactly: a plan that cuts a disc is ``NoPathFound``).  The
line per case gives ``collision_free`` out of ``seeds``, the failures' first reason and the wall time.  The
target (issue 31): at least 9 of 10 on each case (at least 4 of seeds 0-4 where a test guards it: the Kamil et al.
(2020) variants, whose clearance rule ``docs/papers.md`` states, in ``tests/test_kamil_variants.py``).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path as FilePath
from typing import Any

STUDIES = FilePath(__file__).resolve().parents[2] / "models" / "studies"
_KAMIL = [f"adl-abc-feasible/adl-abc-feasible-path-{i}.toml" for i in (1, 2, 3)] + [
    f"adl-abc-case-b-feasible/adl-abc-case-b-feasible-path-{i}.toml" for i in (1, 2, 3)]
#: (paper, planner, scenarios): each paper's planners on the scenarios bundled for it (feasible ones only).
PAPER_CASES: tuple[tuple[str, str, tuple[str, ...]], ...] = (
    ("Abdulla & Hadi (2025)", "gwo", ("gwo-scenario-1", "gwo-scenario-2", "gwo-scenario-3")),
    ("Abdulla & Hadi (2025)", "abc", ("gwo-scenario-1", "gwo-scenario-2", "gwo-scenario-3")),
    ("Kamil et al. (2020)", "abc", tuple(str(STUDIES / s) for s in _KAMIL)),
    ("Kamil et al. (2020)", "adl_abc", tuple(str(STUDIES / s) for s in _KAMIL)),
    ("Gong et al. (2022)", "iaco", ("iaco-simple", "iaco-complex", "iaco-baffle", "iaco-trough")),
    ("Hasan et al. (2023)", "immas", ("immas-env1-scattered", "immas-env2-rings", "immas-env3-curves",
                                      "immas-env4-blocks", "immas-env5-arcs", "immas-env6-rows")),
    ("Habib et al. (2021)", "maco", ("restaurant-table-2", "restaurant-table-5")),
)
TARGET = 0.9


def count(planner: str, scenario: str, seeds: int) -> dict[str, Any]:
    """Plan ``scenario`` with ``planner`` at its defaults on seeds 0 .. seeds - 1; count the plans found."""
    from swarmnav.models.scenario import load_scenario
    from swarmnav.planners.errors import PlanningError
    from swarmnav.sim.episode import EpisodeSpec, plan_episode
    started = time.perf_counter()
    found, reasons = 0, []
    for seed in range(seeds):
        try:
            plan_episode(EpisodeSpec(load_scenario(scenario), planner=planner, seed=seed))
            found += 1
        except PlanningError as exc:
            reasons.append(str(exc).split(";")[0])
    return {"planner": planner, "scenario": FilePath(scenario).stem, "seeds": seeds, "collision_free": found,
            "meets_target": found >= TARGET * seeds, "first_failure": reasons[0] if reasons else None,
            "wall_s": round(time.perf_counter() - started, 2)}


def run(args: argparse.Namespace) -> int:
    seeds = 3 if args.quick else args.seeds
    lines = []
    for paper, planner, scenarios in PAPER_CASES:
        if args.planners and planner not in args.planners:
            continue
        for scenario in scenarios:
            line = {"paper": paper, **count(planner, scenario, seeds)}
            lines.append(line)
            if not args.json:
                print(f"{paper:22s} {planner:8s} {line['scenario']:32s} {line['collision_free']:3d}/{seeds} "
                      f"collision-free  {line['wall_s']:7.2f} s" + (f"  ({line['first_failure']})"
                                                                   if line["first_failure"] else ""), flush=True)
    if args.json:
        json.dump({"seeds": seeds, "target": TARGET, "cases": lines}, sys.stdout, indent=2)
        print()
    return 0
