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
    maps = ["known", "unknown"]      # optional axis: the static map given in advance or mapped online, for
                                     # every scenario (as `run --map`; default: each scenario's [knowledge])
    poses = ["truth", "odometry"]    # optional axis: the pose the navigator sees (as `run --pose`)
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

from dataclasses import dataclass, replace
from pathlib import Path as FilePath
from typing import Any

from swarmnav.controllers.navigators import make_navigator
from swarmnav.models.contained_files import is_input_path, name_problem
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import SCENARIO_DIR
from swarmnav.models.scenario_limits import MAX_STUDY_RUNS
from swarmnav.models.toml_table import POSITIVE, TomlTable, above, parse_toml, read_text, within
from swarmnav.planners.registry import make_planner
from swarmnav.planners.swarm import Budget
from swarmnav.sim.plugins import load_plugins
from swarmnav.study.claim_spec import Claim, claim_scenarios, read_claims
from swarmnav.study.spec_sections import (MAX_SEED, MAX_SEEDS, Component, PaperValue, check_time_limit,  # noqa: F401
                                              read_budget, read_clearance, read_components, read_knowledge, read_paper,
                                              read_scenarios, read_seeds, refuse_scenario_code)

MAX_CELLS = MAX_STUDY_RUNS  # runs of one study (scenarios x settings x seed pairs), each a row
MAX_WALL_LIMIT_S = 1e6
STUDY_DIR = SCENARIO_DIR.parent / "studies"  # bundled studies sit beside the bundled scenarios
MODES = ("plan", "physics")
TOP_KEYS = {"name", "description", "scenarios", "mode", "seeds", "quick_seeds", "world_seeds", "wall_limit_s",
            "time_limit_s", "reference", "planners", "navigators", "paper", "clearance_m", "maps", "poses",
            "paired_seeds", "budget", "claims"}


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
    # --claims-only: the (scenario stem, planner arm label, navigator arm label or None) the claims compare;
    # None: every arm runs
    claim_arms: frozenset[tuple[str, str, str | None]] | None = None
    # maps x poses: the (map, pose) every run of a setting is given ((None, None): the scenario's own)
    knowledge: tuple[tuple[str | None, str | None], ...] = ((None, None),)

    def budget_of(self, planner: Component) -> Budget | None:
        """The budget a planner entry runs under: its own, else the study's."""
        return planner.budget or self.budget

    def seed_pairs(self) -> list[tuple[int | None, int]]:
        """(world seed, seed) of every run of one setting, in the grid's order."""
        if self.paired_seeds:
            return list(zip(self.world_seeds, self.seeds))
        return [(w, s) for w in self.world_seeds for s in self.seeds]

    def claims_only(self) -> "Study":
        """The study restricted to the arms its claims compare (each claim's planner and ``than`` labels on its
        scenario, with its navigator when it names one): the rows the verdicts need and no more.  Its cells
        are the full study's cells (the same hashes), so a later full run into the same folder resumes."""
        names = [FilePath(s).stem for s in self.scenarios]
        arms = frozenset((scenario, label, c.navigator) for c in self.claims for scenario in claim_scenarios(c, names)
                         for label in (c.planner, *c.than))
        return replace(self, claim_arms=arms)

    def wants(self, scenario: str, planner_label: str, navigator_label: str) -> bool:
        """Whether the run grid includes this arm (always, unless :meth:`claims_only`)."""
        if self.claim_arms is None:
            return True
        stem = FilePath(scenario).stem
        return (stem, planner_label, navigator_label) in self.claim_arms or (stem, planner_label, None) in self.claim_arms

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
    if candidate.suffix == ".toml" or is_input_path(candidate) or "/" in name_or_path:
        return candidate  # read_text says what is wrong with anything but a regular file
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
    return parse_study(read_text(path, "study"), str(path), default_name=path.stem, trust_code=trust_code)


def parse_study(text: str, source: str = "<string>", default_name: str = "study", trust_code: bool = False) -> Study:
    """Validate study TOML text (see :func:`load_study`)."""
    return _read_study(parse_toml(text, source), default_name, trust_code)


def study_from_tables(data: dict[str, Any], source: str = "<tables>", default_name: str = "study",
                      trust_code: bool = False) -> Study:
    """Validate a study given as the tables its TOML file would hold (what a benchmark builds in code)."""
    return _read_study(TomlTable(data, "", source), default_name, trust_code)


def _read_study(top: TomlTable, default_name: str, trust_code: bool) -> Study:
    load_plugins()  # the names of installed plugins' planners, navigators and scenarios are valid here too
    top.only(TOP_KEYS)
    name = top.string("name", default_name, non_empty=True)
    problem = name_problem(name)  # the default --out is studies/<name>: a name is never a path
    if problem:
        top.fail("name", problem)
    description = top.string("description", "")
    scenarios = read_scenarios(top)
    mode = top.string("mode", "plan", choices=MODES)
    seeds = read_seeds(top, "seeds", 1)
    quick_seeds = top.integer("quick_seeds", None, bounds=within(1, len(seeds)))
    world_seeds: tuple = read_seeds(top, "world_seeds", [0]) if top.has("world_seeds") else (None,)
    wall_limit_s = top.number("wall_limit_s", 600.0, bounds=above(0, MAX_WALL_LIMIT_S))
    time_limit_s = top.number("time_limit_s", None, bounds=POSITIVE)
    planners = read_components(top, "planners", "planner", make_planner, trust_code)
    navigators = read_components(top, "navigators", "navigator", make_navigator, trust_code, [{"name": "follow"}])
    if time_limit_s is not None:
        check_time_limit(scenarios, time_limit_s, top.source)
    if not trust_code:
        refuse_scenario_code(scenarios, planners, navigators)
    labels = [p.label for p in planners]
    reference = top.string("reference", labels[0], non_empty=True)
    if reference not in labels and not any(reference.startswith(f"{label}(") for label in labels):
        top.fail("reference", f"{reference!r} is not a planner label of the study ({', '.join(labels)})")
    paper = read_paper(top, scenarios, labels)
    paired = top.boolean("paired_seeds", False)
    if paired and len(world_seeds) != len(seeds):
        top.fail("paired_seeds", f"pairs the seeds with the world seeds: {len(seeds)} seeds but "
                                 f"{len(world_seeds) if top.has('world_seeds') else 'no'} world seeds")
    settings = sum(c.count() for c in planners) * sum(c.count() for c in navigators)
    knowledge = read_knowledge(top)
    cells = len(scenarios) * settings * len(knowledge) * (len(seeds) if paired else len(seeds) * len(world_seeds))
    if cells > MAX_CELLS:
        top.fail("seeds", f"the grid has {cells:,} runs (scenarios x settings x seeds), at most {MAX_CELLS:,}")
    claims = read_claims(top, scenarios, planners, navigators)
    budget = read_budget(top.table("budget")) if top.has("budget") else None
    return Study(name, description, top.source, scenarios, mode, seeds, world_seeds, wall_limit_s, time_limit_s,
                 reference, planners, navigators, paper, quick_seeds, read_clearance(top, scenarios), paired,
                 claims, bool(trust_code), budget, knowledge=knowledge)
