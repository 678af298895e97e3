"""A study's grid: every (scenario, planner setting, navigator setting, seed, world seed) cell.

A cell's configuration hash covers what decides its result: the scenario file's
bytes, the planner and navigator with their labels and parameters, both seeds, the mode,
the simulated-time limit, and the clearance and budget when the study sets them.  Resuming skips the cells whose hash is already in the
rows; an edited scenario or parameter is a new cell.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path as FilePath
from typing import Any, Iterator

from swarmnav.models.scenario import resolve_scenario_path
from swarmnav.study.spec import Component, Study


@dataclass(frozen=True)
class Cell:
    """One run of a study (picklable: it crosses process and Ray boundaries)."""

    study: str
    scenario: str  # bundled name or path, for load_scenario
    scenario_name: str
    planner: str
    label: str  # the planner entry's label, plus the swept values
    planner_params: dict[str, Any]
    navigator: str
    navigator_label: str
    navigator_params: dict[str, Any]
    seed: int
    world_seed: int | None
    mode: str
    time_limit_s: float | None
    wall_limit_s: float
    config_hash: str
    clearance_m: float | None = None  # the study's planning clearance override (None: the scenario's)
    trust_code: bool = False  # the study's --trust-code (not part of the hash: it decides no result)
    budget: dict[str, Any] | None = None  # the planner's budget, {"evaluations": N} or {"time_s": T} (None: none)
    map_knowledge: str | None = None  # the study's maps axis value (None: the scenario's knowledge.map)
    pose_source: str | None = None  # the study's poses axis value (None: the scenario's knowledge.pose)

    @property
    def physics(self) -> bool:
        return self.mode == "physics"


def config_hash(config: dict[str, Any]) -> str:
    """16 hex digits of SHA-256 over the canonical JSON of a cell's configuration."""
    text = json.dumps(config, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _settings(study: Study):
    """(scenario, planner, planner setting, navigator, navigator setting) in the grid's order."""
    for scenario in study.scenarios:
        for planner in study.planners:
            for planner_params in planner.settings():
                for navigator in study.navigators:
                    for navigator_params in navigator.settings():
                        if study.wants(scenario, planner.arm_label(planner_params), navigator.arm_label(navigator_params)):
                            yield scenario, planner, planner_params, navigator, navigator_params


def iter_cells(study: Study) -> Iterator[Cell]:
    """Every cell of the study, lazily, in a fixed order (scenario, planner, setting, navigator, world seed,
    seed): a driver holds only the cells in flight, whatever the size of the grid."""
    scenario_digest = {s: hashlib.sha256(resolve_scenario_path(s).read_bytes()).hexdigest() for s in study.scenarios}
    pairs = study.seed_pairs()
    for scenario, planner, planner_params, navigator, navigator_params in _settings(study):
        label = planner.arm_label(planner_params)
        navigator_label = navigator.arm_label(navigator_params)
        for (map_knowledge, pose_source), (world_seed, seed) in ((k, p) for k in study.knowledge for p in pairs):
            config = {"scenario_sha256": scenario_digest[scenario], "planner": planner.name,
                      "label": planner.label, "navigator_label": navigator.label,
                      "planner_params": planner_params, "navigator": navigator.name,
                      "navigator_params": navigator_params, "seed": seed,
                      "world_seed": world_seed, "mode": study.mode, "time_limit_s": study.time_limit_s}
            if study.clearance_m is not None:  # absent otherwise: earlier hashes hold
                config["clearance_m"] = study.clearance_m
            if map_knowledge is not None:  # likewise
                config["map_knowledge"] = map_knowledge
            if pose_source is not None:
                config["pose_source"] = pose_source
            budget = study.budget_of(planner)
            if budget is not None:  # likewise
                config["budget"] = budget.as_dict()
            yield Cell(
                study=study.name, scenario=scenario, scenario_name=FilePath(scenario).stem,
                planner=planner.name, label=label,
                planner_params=planner_params, navigator=navigator.name,
                navigator_label=navigator_label,
                navigator_params=navigator_params, seed=seed, world_seed=world_seed,
                mode=study.mode, time_limit_s=study.time_limit_s,
                wall_limit_s=study.wall_limit_s, config_hash=config_hash(config),
                clearance_m=study.clearance_m, trust_code=study.trust_code,
                budget=None if budget is None else budget.as_dict(),
                map_knowledge=map_knowledge, pose_source=pose_source)


def count_cells(study: Study) -> int:
    """How many cells :func:`iter_cells` yields, without building them."""
    if study.claim_arms is not None:
        return sum(1 for _ in _settings(study)) * len(study.knowledge) * len(study.seed_pairs())
    settings = sum(len(p.settings()) for p in study.planners) * sum(len(n.settings()) for n in study.navigators)
    return len(study.scenarios) * settings * len(study.knowledge) * len(study.seed_pairs())


def expand(study: Study) -> list[Cell]:
    """Every cell of the study as a list (for small grids and tests; drivers use :func:`iter_cells`)."""
    return list(iter_cells(study))
