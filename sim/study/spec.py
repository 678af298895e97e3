"""A study file: which scenarios, planners (with swept parameters), navigators and seeds to run.

TOML, bundled under ``models/studies/`` (named by file stem, as scenarios are) or any path::

    name = "gwo-vs-abc"              # default: the file stem
    description = "..."
    scenarios = ["gwo-scenario-*"]   # bundled names, paths, or glob patterns of either
    mode = "plan"                    # "plan" (plan only) or "physics" (plan, then simulate)
    seeds = 10                       # a count (0..N-1) or a list of planner seeds
    quick_seeds = 3                  # optional: `swarmnav study --quick` runs only the first N seeds
    world_seeds = [0]                # optional: seeds of the random obstacle motions (default: the scenario's)
    paired_seeds = false             # optional: true runs the k-th seed with the k-th world seed only (same
                                     # count), instead of every seed with every world seed
    wall_limit_s = 120               # per run; past it the run becomes an outcome "timeout" row
    clearance_m = 0.0                # optional: the planning clearance beyond the robot radius for every
                                     # scenario (default: each scenario's robot.clearance_m)
    reference = "gwo"                # the planner label (or one swept arm, "maco(p0=0.9)") the statistics
                                     # compare against (default: the first)
    budget = { evaluations = 5000 }  # optional: every planner of the study runs until it has spent this
                                     # budget (or { time_s = 2.0 }); see planners.swarm.Budget

    [[planners]]
    name = "gwo"                     # a name in the planner registry
    label = "GWO"                    # optional; default: the name
    params = { population = 50, iterations = [50, 100] }   # a list sweeps that parameter
    budget = { evaluations = 10000 } # optional: this entry's own budget (default: the study's)

    [[navigators]]                   # optional; default: one navigator, follow
    name = "follow"

    [[claims]]                       # optional: a claim of the paper the rows test (see claim_spec.py)
    id = "gwo-shorter-than-abc-sc1"
    statement = "GWO's mean path is shorter than ABC's on scenario 1"
    source = "Abdulla & Hadi (2025), Sect. 6.1"
    scenario = "gwo-scenario-1"
    metric = "plan_length_m"         # or "success"
    better = "lower"
    planner = "gwo"
    than = ["abc"]
    test = "rank_sum"                # or "signed_rank", "fisher" (success)

    [[paper]]                        # optional: a paper's value to print beside ours
    scenario = "gwo-scenario-1"
    planner = "GWO"                  # a planner label
    metric = "plan_length_m"
    value = 14.14
    note = "Table 2"

    [[claims]]                       # optional: a claim of the paper the study tests (schema: the
    id = "gwo-shorter"               # report's claims section); kept as given here

Every problem is a :class:`ConfigError` naming the field (``planners[1].params.alpha``).
"""

from __future__ import annotations

import fnmatch
import glob
import itertools
import math
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path as FilePath
from typing import Any

from swarmnav.controllers.navigators import NAVIGATORS, make_navigator
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import SCENARIO_DIR, list_scenarios, load_scenario, resolve_scenario_path
from swarmnav.models.parameters import refuse_code
from swarmnav.planners.registry import PLANNERS, make_planner
from swarmnav.planners.swarm import Budget
from swarmnav.sim.study.claim_spec import Claim, parse_claims

MAX_SEEDS = 100_000  # seeds (or world seeds) of one study
MAX_SEED = 2**63 - 1  # as --seed and a scenario's seed (a TOML integer; NumPy's seeds take it)
MAX_CELLS = 2_000_000  # runs of one study (scenarios x settings x seed pairs), each a row
MAX_WALL_LIMIT_S = 1e6
STUDY_DIR = SCENARIO_DIR.parent / "studies"  # bundled studies sit beside the bundled scenarios
MODES = ("plan", "physics")
TOP_KEYS = {"name", "description", "scenarios", "mode", "seeds", "quick_seeds", "world_seeds", "wall_limit_s",
            "time_limit_s", "reference", "planners", "navigators", "paper", "clearance_m",
            "paired_seeds", "budget", "claims"}


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


@dataclass(frozen=True)
class Study:
    name: str
    description: str
    source: str
    scenarios: tuple[str, ...]  # bundled names or file paths, each loadable by load_scenario
    mode: str
    seeds: tuple[int, ...]
    world_seeds: tuple[int | None, ...]
    wall_limit_s: float
    time_limit_s: float | None  # simulated-time limit override (physics); None = the scenario's
    reference: str
    planners: tuple[Component, ...]
    navigators: tuple[Component, ...]
    paper: tuple[PaperValue, ...]
    quick_seeds: int | None = None  # the first N seeds make the quick run (None: the quick run is the full one)
    clearance_m: float | None = None  # planning clearance override for every scenario (None: each scenario's)
    paired_seeds: bool = False  # the k-th seed runs with the k-th world seed only
    claims: tuple[Claim, ...] = ()  # the paper's claims the rows test (the report's verdicts)
    trust_code: bool = False  # --trust-code: its files (study, scenarios) may name code to run
    budget: Budget | None = None  # every planner's budget, unless its entry names its own

    def budget_of(self, planner: Component) -> Budget | None:
        """The budget a planner entry runs under: its own, else the study's."""
        return planner.budget or self.budget

    def seed_pairs(self) -> list[tuple[int | None, int]]:
        """(world seed, seed) of every run of one setting, in the grid's order."""
        if self.paired_seeds:
            return list(zip(self.world_seeds, self.seeds))
        return [(w, s) for w in self.world_seeds for s in self.seeds]

    def quick(self) -> "Study":
        """The study on its first ``quick_seeds`` seeds (its rows are the full study's rows for those seeds,
        so a later full run into the same folder resumes them)."""
        if self.quick_seeds is None:
            return self
        if self.paired_seeds:
            return replace(self, seeds=self.seeds[:self.quick_seeds], world_seeds=self.world_seeds[:self.quick_seeds])
        return replace(self, seeds=self.seeds[:self.quick_seeds])

    @property
    def physics(self) -> bool:
        return self.mode == "physics"


def list_studies() -> list[str]:
    """Names of the bundled studies (file stems under models/studies/)."""
    return sorted(p.stem for p in STUDY_DIR.glob("*.toml"))


def resolve_study_path(name_or_path: str) -> FilePath:
    candidate = FilePath(name_or_path)
    if candidate.suffix == ".toml" or candidate.is_file() or "/" in name_or_path:
        if not candidate.is_file():
            raise ConfigError("study", "file does not exist", str(candidate))
        return candidate
    bundled = STUDY_DIR / f"{name_or_path}.toml"
    if not bundled.is_file():
        raise ConfigError("study", f"no bundled study named {name_or_path!r} (see `swarmnav studies`)", name_or_path)
    return bundled


def load_study(name_or_path: str, trust_code: bool = False) -> Study:
    """Read and validate a study file (bundled name or path); ``trust_code``: the study and its scenarios
    may name code to run (``--trust-code``; otherwise such a parameter is a ConfigError, nothing imported).

    Raises:
        ConfigError: missing file, malformed TOML, or any field that breaks the schema.
    """
    path = resolve_study_path(str(name_or_path))
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError("study", f"cannot be read ({exc})", str(path)) from None
    return parse_study(text, str(path), default_name=path.stem, trust_code=trust_code)


def _fail(source: str, field: str, problem: str):
    raise ConfigError(field, problem, source)


def _string(source: str, data: dict, key: str, field: str, default: Any = ...) -> str:
    if key not in data:
        if default is ...:
            _fail(source, field, "is required")
        return default
    if not isinstance(data[key], str) or not data[key]:
        _fail(source, field, f"expected a non-empty string, got {data[key]!r}")
    return data[key]


def _number(source: str, value: Any, field: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or value != value:
        _fail(source, field, f"expected a number, got {value!r}")
    return float(value)


def _scenarios(source: str, value: Any) -> tuple[str, ...]:
    if not isinstance(value, list) or not value:
        _fail(source, "scenarios", "expected a non-empty list of scenario names, paths or patterns")
    bundled = list_scenarios()
    base = FilePath(source).parent if source and not source.startswith("<") else FilePath(".")
    out: list[str] = []
    for i, item in enumerate(value):
        field = f"scenarios[{i}]"
        if not isinstance(item, str) or not item:
            _fail(source, field, f"expected a scenario name, path or pattern, got {item!r}")
        is_path = item.endswith(".toml") or "/" in item
        if any(c in item for c in "*?["):
            found = (sorted(glob.glob(str(base / item))) if is_path else fnmatch.filter(bundled, item))
            if not found:
                _fail(source, field, f"pattern {item!r} matches no scenario")
        else:
            target = str(base / item) if is_path and not FilePath(item).is_absolute() else item
            try:
                resolve_scenario_path(target)
            except ConfigError as exc:
                _fail(source, field, f"{exc.problem} ({item!r})")
            found = [target]
        out.extend(s for s in found if s not in out)
    return tuple(out)


def _seeds(source: str, data: dict, key: str, default: Any) -> tuple:
    value = data.get(key, default)
    if isinstance(value, bool):
        _fail(source, key, f"expected a count or a list of integers, got {value!r}")
    if isinstance(value, int):
        if not 1 <= value <= MAX_SEEDS:
            _fail(source, key, f"the count must be from 1 to {MAX_SEEDS:,}, got {value}")
        return tuple(range(value))
    if not isinstance(value, list) or not value:
        _fail(source, key, "empty grid: expected a count or a non-empty list of integers")
    if len(value) > MAX_SEEDS:
        _fail(source, key, f"lists {len(value):,} seeds, at most {MAX_SEEDS:,}")
    for i, seed in enumerate(value):
        if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED:
            _fail(source, f"{key}[{i}]", f"expected an integer from 0 to {MAX_SEED}, got {seed!r}")
    if len(set(value)) != len(value):
        _fail(source, key, "lists a seed twice")
    return tuple(value)


def _components(source: str, value: Any, key: str, kind: str, make, trust_code: bool) -> tuple[Component, ...]:
    if not isinstance(value, list) or not value:
        _fail(source, key, f"empty grid: expected a non-empty array of [[{key}]] tables")
    out: list[Component] = []
    for i, entry in enumerate(value):
        where = f"{key}[{i}]"
        if not isinstance(entry, dict):
            _fail(source, where, "expected a table")
        allowed = {"name", "label", "params"} | ({"budget"} if kind == "planner" else set())
        for k in sorted(set(entry) - allowed):
            _fail(source, f"{where}.{k}", "unknown key")
        name = _string(source, entry, "name", f"{where}.name")
        label = _string(source, entry, "label", f"{where}.label", name)
        params = entry.get("params", {})
        if not isinstance(params, dict):
            _fail(source, f"{where}.params", "expected a table")
        swept = tuple(k for k, v in params.items() if isinstance(v, list))
        for k in swept:
            if not params[k]:
                _fail(source, f"{where}.params.{k}", "empty grid: the sweep lists no value")
        budget = _budget(source, entry["budget"], f"{where}.budget") if "budget" in entry else None
        component = Component(name, label, dict(params), swept, budget)
        for setting in component.settings():  # every combination builds: names and every swept value checked
            try:
                make(name, setting, source, trust_code=trust_code)
            except ConfigError as exc:
                field = exc.field.replace(f"{kind}.", f"{where}.", 1)
                if field == f"{where}.params" and swept:
                    field = f"{where}.params"
                _fail(source, field, exc.problem)
        out.append(component)
    labels = [c.label for c in out]
    for i, label in enumerate(labels):
        if label in labels[:i]:
            _fail(source, f"{key}[{i}].label", f"label {label!r} is used twice (give each entry its own label)")
    return tuple(out)


def _refuse_scenario_code(scenarios: tuple[str, ...], planners: tuple[Component, ...],
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
def _budget(source: str, value: Any, field: str) -> Budget:
    """``{ evaluations = N }`` (a positive integer) or ``{ time_s = T }`` (positive seconds)."""
    if not isinstance(value, dict):
        _fail(source, field, f"expected a table {{ evaluations = N }} or {{ time_s = T }}, got {value!r}")
    for k in sorted(set(value) - {"evaluations", "time_s"}):
        _fail(source, f"{field}.{k}", "unknown key (expected evaluations or time_s)")
    if len(value) != 1:
        _fail(source, field, "expected exactly one of evaluations or time_s")
    if "evaluations" in value:
        count = value["evaluations"]
        if isinstance(count, bool) or not isinstance(count, int) or count < 1:
            _fail(source, f"{field}.evaluations", f"expected a positive integer, got {count!r}")
        return Budget(evaluations=count)
    time_s = _number(source, value["time_s"], f"{field}.time_s")
    if not 0 < time_s < float("inf"):
        _fail(source, f"{field}.time_s", f"must be positive and finite, got {time_s:g}")
    return Budget(time_s=time_s)


def _paper(source: str, value: Any, scenarios: tuple[str, ...], labels: list[str]) -> tuple[PaperValue, ...]:
    if not isinstance(value, list):
        _fail(source, "paper", "expected an array of [[paper]] tables")
    out = []
    names = {FilePath(s).stem for s in scenarios}
    for i, entry in enumerate(value):
        where = f"paper[{i}]"
        if not isinstance(entry, dict):
            _fail(source, where, "expected a table")
        for k in sorted(set(entry) - {"scenario", "planner", "metric", "value", "note"}):
            _fail(source, f"{where}.{k}", "unknown key")
        scenario = _string(source, entry, "scenario", f"{where}.scenario")
        if scenario not in names:
            _fail(source, f"{where}.scenario", f"{scenario!r} is not among the study's scenarios")
        planner = _string(source, entry, "planner", f"{where}.planner")
        if planner not in labels:
            _fail(source, f"{where}.planner", f"{planner!r} is not a planner label of the study "
                                              f"({', '.join(labels)})")
        metric = _string(source, entry, "metric", f"{where}.metric")
        if "value" not in entry:
            _fail(source, f"{where}.value", "is required")
        out.append(PaperValue(scenario, planner, metric, _number(source, entry["value"], f"{where}.value"),
                              _string(source, entry, "note", f"{where}.note", "")))
    return tuple(out)


def parse_study(text: str, source: str = "<string>", default_name: str = "study", trust_code: bool = False) -> Study:
    """Validate study TOML text (see :func:`load_study`)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError("toml", f"malformed TOML ({exc})", source) from None
    return study_from_tables(data, source, default_name, trust_code)


def _clearance(source: str, data: dict, scenarios: tuple[str, ...]) -> float | None:
    if "clearance_m" not in data:
        return None
    clearance_m = _number(source, data["clearance_m"], "clearance_m")
    for ref in scenarios:
        try:
            load_scenario(ref).with_clearance(clearance_m)
        except ConfigError as exc:
            _fail(source, "clearance_m", exc.problem)
    return clearance_m


def study_from_tables(data: dict[str, Any], source: str = "<tables>", default_name: str = "study",
                      trust_code: bool = False) -> Study:
    """Validate a study given as the tables its TOML file would hold (what a benchmark builds in code)."""
    for key in sorted(set(data) - TOP_KEYS):
        _fail(source, key, "unknown key")
    name = _string(source, data, "name", "name", default_name)
    description = data.get("description", "")
    if not isinstance(description, str):
        _fail(source, "description", f"expected a string, got {description!r}")
    if "scenarios" not in data:
        _fail(source, "scenarios", "is required")
    scenarios = _scenarios(source, data["scenarios"])
    mode = _string(source, data, "mode", "mode", "plan")
    if mode not in MODES:
        _fail(source, "mode", f"unknown value {mode!r} (expected one of: {', '.join(MODES)})")
    seeds = _seeds(source, data, "seeds", 1)
    quick_seeds = None
    if "quick_seeds" in data:
        quick_seeds = data["quick_seeds"]
        if isinstance(quick_seeds, bool) or not isinstance(quick_seeds, int) or not 1 <= quick_seeds <= len(seeds):
            _fail(source, "quick_seeds", f"expected a count from 1 to the {len(seeds)} seeds, got {quick_seeds!r}")
    world_seeds: tuple = _seeds(source, data, "world_seeds", [0]) if "world_seeds" in data else (None,)
    wall_limit_s = _number(source, data.get("wall_limit_s", 600.0), "wall_limit_s")
    if not 0 < wall_limit_s <= MAX_WALL_LIMIT_S:
        _fail(source, "wall_limit_s", f"must be positive and at most {MAX_WALL_LIMIT_S:g} s, got {wall_limit_s:g}")
    time_limit_s = None
    if "time_limit_s" in data:
        time_limit_s = _number(source, data["time_limit_s"], "time_limit_s")
        if not 0 < time_limit_s < math.inf:
            _fail(source, "time_limit_s", f"must be positive and finite, got {time_limit_s:g}")
    if "planners" not in data:
        _fail(source, "planners", "is required")
    planners = _components(source, data["planners"], "planners", "planner", make_planner, trust_code)
    navigators = _components(source, data.get("navigators", [{"name": "follow"}]), "navigators", "navigator",
                             make_navigator, trust_code)
    if not trust_code:
        _refuse_scenario_code(scenarios, planners, navigators)
    labels = [p.label for p in planners]
    reference = _string(source, data, "reference", "reference", labels[0])
    if reference not in labels and not any(reference.startswith(f"{label}(") for label in labels):
        _fail(source, "reference", f"{reference!r} is not a planner label of the study ({', '.join(labels)})")
    paper = _paper(source, data.get("paper", []), scenarios, labels)
    paired = data.get("paired_seeds", False)
    if not isinstance(paired, bool):
        _fail(source, "paired_seeds", f"expected true or false, got {paired!r}")
    if paired and len(world_seeds) != len(seeds):
        _fail(source, "paired_seeds", f"pairs the seeds with the world seeds: {len(seeds)} seeds but "
                                      f"{len(world_seeds) if 'world_seeds' in data else 'no'} world seeds")
    settings = sum(len(c.settings()) for c in planners) * sum(len(c.settings()) for c in navigators)
    cells = len(scenarios) * settings * (len(seeds) if paired else len(seeds) * len(world_seeds))
    if cells > MAX_CELLS:
        _fail(source, "seeds", f"the grid has {cells:,} runs (scenarios x settings x seeds), at most {MAX_CELLS:,}")
    claims = parse_claims(source, data.get("claims", []), scenarios, planners, navigators)
    budget = _budget(source, data["budget"], "budget") if "budget" in data else None
    return Study(name, description, source, scenarios, mode, seeds, world_seeds, wall_limit_s, time_limit_s,
                 reference, planners, navigators, paper, quick_seeds, _clearance(source, data, scenarios), paired,
                 claims, bool(trust_code), budget)
