"""The sections of a study file (:mod:`swarmnav.study.spec` has the schema), each read with the one TOML
reader (:mod:`swarmnav.models.toml_table`): every problem is one ConfigError naming the file and the field
(``planners[1].params.alpha``)."""

from __future__ import annotations

import fnmatch
import glob
import itertools
import math
from dataclasses import dataclass
from pathlib import Path as FilePath
from typing import Any, Callable

from swarmnav.controllers.navigators import NAVIGATORS
from swarmnav.models.errors import ConfigError
from swarmnav.models.parameters import refuse_code
from swarmnav.models.scenario_limits import MAX_STUDY_RUNS, MAX_SWEEP_VALUES
from swarmnav.models.scenario import MAP_KNOWLEDGE, POSE_SOURCES, check_run_size, list_scenarios, load_scenario, resolve_scenario_path
from swarmnav.models.toml_table import (NON_NEGATIVE, POSITIVE, TomlTable, check_array, check_integer,
                                        check_string, within)
from swarmnav.planners.registry import PLANNERS
from swarmnav.planners.swarm import Budget

MAX_SEEDS = 100_000  # seeds (or world seeds) of one study
MAX_SEED = 2**63 - 1  # as --seed and a scenario's seed (a TOML integer; NumPy's seeds take it)


@dataclass(frozen=True)
class Component:
    """A planner or navigator entry: a registry name, a label, and its parameter grid."""

    name: str
    label: str
    params: dict[str, Any]  # a list value is a sweep
    swept: tuple[str, ...]  # the keys that sweep
    budget: Budget | None = None  # this entry's budget (None: the study's)

    def arm_label(self, setting: dict[str, Any]) -> str:
        """The label of one setting of the sweep: ``label(key=value, ...)`` over the swept keys, else the label."""
        if not self.swept:
            return self.label
        return self.label + "(" + ", ".join(f"{k}={setting[k]}" for k in self.swept) + ")"

    def count(self) -> int:
        """How many settings the sweep has, from the lists' lengths (nothing expanded)."""
        return math.prod(len(self.params[k]) for k in self.swept)

    def settings(self) -> list[dict[str, Any]]:
        """Every parameter table of the sweep (the Cartesian product of the lists), in file order."""
        fixed = {k: v for k, v in self.params.items() if k not in self.swept}
        lists = [self.params[k] for k in self.swept]
        return [{**fixed, **dict(zip(self.swept, combo))} for combo in itertools.product(*lists)]


@dataclass(frozen=True)
class PaperValue:
    scenario: str
    planner: str
    metric: str
    value: float
    note: str


def read_scenarios(top: TomlTable) -> tuple[str, ...]:
    """``scenarios``: bundled names, paths (relative to the study file) or glob patterns of either."""
    items = top.array("scenarios", what="a non-empty list of scenario names, paths or patterns", non_empty=True)
    source = top.source
    bundled = list_scenarios()
    base = FilePath(source).parent if source and not source.startswith("<") else FilePath(".")
    out: list[str] = []
    for i, item in enumerate(items):
        field = top.path(f"scenarios[{i}]")
        check_string(item, field, source, non_empty=True)
        is_path = item.endswith(".toml") or "/" in item
        if any(c in item for c in "*?["):
            found = (sorted(glob.glob(str(base / item))) if is_path else fnmatch.filter(bundled, item))
            if not found:
                top.fail(f"scenarios[{i}]", f"pattern {item!r} matches no scenario")
        else:
            target = str(base / item) if is_path and not FilePath(item).is_absolute() else item
            try:
                resolve_scenario_path(target)
            except ConfigError as exc:
                top.fail(f"scenarios[{i}]", f"{exc.problem} ({item!r})")
            found = [target]
        out.extend(s for s in found if s not in out)
    return tuple(out)


def read_seeds(top: TomlTable, key: str, default: Any) -> tuple[int, ...]:
    """A count ``N`` (seeds 0..N-1) or a list of distinct seeds."""
    value = top.raw(key, default)
    if isinstance(value, int) and not isinstance(value, bool):
        return tuple(range(check_integer(value, top.path(key), top.source, within(1, MAX_SEEDS))))
    seeds = check_array(value, top.path(key), top.source, "a count or a non-empty list of integers (empty grid)",
                        non_empty=True)
    if len(seeds) > MAX_SEEDS:
        top.fail(key, f"lists {len(seeds):,} seeds, at most {MAX_SEEDS:,}")
    for i, seed in enumerate(seeds):
        check_integer(seed, top.path(f"{key}[{i}]"), top.source, within(0, MAX_SEED))
    if len(set(seeds)) != len(seeds):
        top.fail(key, "lists a seed twice")
    return tuple(seeds)


def read_budget(t: TomlTable) -> Budget:
    """``{ evaluations = N }`` (a positive integer) or ``{ time_s = T }`` (positive seconds)."""
    t.only({"evaluations", "time_s"}, " (expected evaluations or time_s)")
    if len(t.keys()) != 1:
        t.fail("", "expected exactly one of evaluations or time_s")
    if t.has("evaluations"):
        return Budget(evaluations=t.integer("evaluations", bounds=within(1)))
    return Budget(time_s=t.number("time_s", bounds=POSITIVE))


def read_components(top: TomlTable, key: str, kind: str, make: Callable[..., Any], trust_code: bool,
                    default: Any = ...) -> tuple[Component, ...]:
    """``[[planners]]`` or ``[[navigators]]``: every entry, and every setting of its sweep built once (names,
    parameters and every swept value checked by the registry)."""
    out: list[Component] = []
    for entry in top.tables(key, default, non_empty=True):
        entry.only({"name", "label", "params"} | ({"budget"} if kind == "planner" else set()))
        name = entry.string("name", non_empty=True)
        label = entry.string("label", name, non_empty=True)
        params = entry.table("params", {})
        swept = tuple(k for k, v in params.data.items() if isinstance(v, list))
        for k in swept:
            if not params.data[k]:
                params.fail(k, "empty grid: the sweep lists no value")
            if len(params.data[k]) > MAX_SWEEP_VALUES:
                params.fail(k, f"{len(params.data[k]):,} values, at most {MAX_SWEEP_VALUES:,} (MAX_SWEEP_VALUES)")
        budget = read_budget(entry.table("budget")) if entry.has("budget") else None
        component = Component(name, label, dict(params.data), swept, budget)
        if component.count() > MAX_STUDY_RUNS:  # counted from the lists' lengths, before any is expanded
            entry.fail("params", f"the sweep has {component.count():,} settings ("
                                 + " x ".join(str(len(params.data[k])) for k in swept)
                                 + f"), more than a study's {MAX_STUDY_RUNS:,} runs (MAX_STUDY_RUNS)")
        for setting in component.settings():
            try:
                make(name, setting, top.source, trust_code=trust_code)
            except ConfigError as exc:  # the registry names "planner.params.x": this entry's field
                entry.fail(exc.field.removeprefix(f"{kind}."), exc.problem)
        out.append(component)
    labels = [c.label for c in out]
    for i, label in enumerate(labels):
        if label in labels[:i]:
            top.fail(f"{key}[{i}].label", f"label {label!r} is used twice (give each entry its own label)")
    return tuple(out)


def check_time_limit(scenarios: tuple[str, ...], time_limit_s: float, source: str | None) -> None:
    """The study's ``time_limit_s`` is refused up front, naming the study file, when it is not a whole number
    of some scenario's control periods or exceeds its step maxima (it would be an error row in every cell)."""
    for ref in scenarios:
        scenario = load_scenario(ref)
        try:
            check_run_size(time_limit_s, scenario.sim, source)
        except ConfigError as exc:
            raise ConfigError("time_limit_s", f"{exc.problem} for scenario {scenario.name!r}", source) from None


def refuse_scenario_code(scenarios: tuple[str, ...], planners: tuple[Component, ...],
                         navigators: tuple[Component, ...]) -> None:
    """A scenario file's own planner or navigator parameter that names code, where the study would use it
    (the same component, not set by the study), is refused before any cell runs (models.parameters)."""
    for ref in scenarios:
        scenario = load_scenario(ref)
        for kind, registry, own, params, components in (
                ("planner", PLANNERS, scenario.planner_name, scenario.planner_params, planners),
                ("navigator", NAVIGATORS, scenario.navigator_name, scenario.navigator_params, navigators)):
            for component in components:
                if component.name == own:
                    unset = {k: v for k, v in params.items() if k not in component.params}
                    refuse_code(registry, kind, own, unset, scenario.source_path)


def read_paper(top: TomlTable, scenarios: tuple[str, ...], labels: list[str]) -> tuple[PaperValue, ...]:
    """``[[paper]]``: a paper's value to print beside ours, for one of the study's scenarios and planners."""
    out = []
    names = {FilePath(s).stem for s in scenarios}
    for entry in top.tables("paper", []):
        entry.only({"scenario", "planner", "metric", "value", "note"})
        scenario = entry.string("scenario", non_empty=True)
        if scenario not in names:
            entry.fail("scenario", f"{scenario!r} is not among the study's scenarios")
        planner = entry.string("planner", non_empty=True)
        if planner not in labels:
            entry.fail("planner", f"{planner!r} is not a planner label of the study ({', '.join(labels)})")
        metric = entry.string("metric", non_empty=True)
        out.append(PaperValue(scenario, planner, metric, entry.number("value"), entry.string("note", "",
                                                                                             non_empty=True)))
    return tuple(out)


def read_knowledge(top: TomlTable) -> tuple[tuple[str | None, str | None], ...]:
    """``maps`` (``"known"`` / ``"unknown"``) and ``poses`` (``"truth"`` / ``"odometry"``): axes of the grid,
    each value given to every scenario as ``--map`` / ``--pose`` would be.  Absent: ``(None,)``, the
    scenario's own ``[knowledge]``.  Returns the (map, pose) pairs in the grid's order (maps outer)."""
    axes = []
    for key, choices in (("maps", MAP_KNOWLEDGE), ("poses", POSE_SOURCES)):
        if not top.has(key):
            axes.append((None,))
            continue
        values = top.array(key, what=f"an array of {' / '.join(choices)}", non_empty=True)
        for value in values:
            if value not in choices:
                top.fail(key, f"each must be one of {', '.join(choices)}, got {value!r}")
        if len(set(values)) != len(values):
            top.fail(key, "a value is repeated")
        axes.append(tuple(values))
    return tuple((m, p) for m in axes[0] for p in axes[1])


def read_clearance(top: TomlTable, scenarios: tuple[str, ...]) -> float | None:
    """``clearance_m``: the planning clearance every scenario takes (None: each scenario's own)."""
    clearance_m = top.number("clearance_m", None, bounds=NON_NEGATIVE)
    if clearance_m is not None:
        for ref in scenarios:
            try:
                load_scenario(ref).with_clearance(clearance_m)
            except ConfigError as exc:
                top.fail("clearance_m", exc.problem)
    return clearance_m
