"""The ``[[claims]]`` tables of a study file: what a paper claims that the study's rows can test.

::

    [[claims]]
    id = "gwo-shorter-than-abc-sc1"        # unique within the study, [a-z0-9-]
    statement = "GWO's mean path is shorter than ABC's on scenario 1"
    source = "Abdulla & Hadi (2025), Sect. 6.1"
    scenario = "gwo-scenario-1"            # one scenario of the study
    metric = "plan_length_m"               # a numeric row column, or "success" (reached with no collision)
    better = "lower"                       # "lower" | "higher": which value the claim calls better
    planner = "gwo"                        # the planner label (or swept arm label) claimed better
    than = ["abc"]                         # one or more labels it is claimed better than (each pair must hold)
    navigator = "follow"                   # optional: only rows of this navigator label
    test = "rank_sum"                      # "rank_sum" | "signed_rank" (paired by seeds) | "fisher" (success)
                                           # | "signed_rank_scenarios" (an average over scenarios, below)

An **aggregate** claim (a paper's average over many start/goal pairs, e.g. Hasan et al. 2023's 30 pairs) takes
``test = "signed_rank_scenarios"`` and a ``scenario`` that is a glob over the study's scenario names (``"*"``,
``"immas-env*"``) matching two or more: each side's mean over its completed runs of each scenario, paired by
scenario, Wilcoxon signed-rank over the scenarios (:mod:`swarmnav.study.claims`).

:func:`read_claims` validates them against the study (its scenarios, its planner and navigator labels, the
row columns); every problem is one :class:`ConfigError` naming the file and the field.  The verdicts are
:mod:`swarmnav.study.claims`'s.
"""

from __future__ import annotations

import fnmatch
import re
from dataclasses import dataclass
from pathlib import Path as FilePath
from typing import Any

from swarmnav.models.toml_table import REQUIRED, TomlTable, check_array, check_string, fail

TESTS = ("rank_sum", "signed_rank", "fisher", "signed_rank_scenarios")
AGGREGATE = "signed_rank_scenarios"  # the test of a claim over scenarios (``scenario`` is a glob)
BETTER = ("lower", "higher")
SUCCESS = "success"
KEYS = {"id", "statement", "source", "scenario", "metric", "better", "planner", "than", "navigator", "test"}
_ID = re.compile(r"[a-z0-9]+(-[a-z0-9]+)*")


@dataclass(frozen=True)
class Claim:
    id: str
    statement: str
    source: str
    scenario: str  # the scenario's name (file stem); an aggregate claim's glob over the names
    metric: str
    better: str
    planner: str
    than: tuple[str, ...]
    test: str
    navigator: str | None = None

    def as_dict(self) -> dict[str, Any]:
        return {"id": self.id, "statement": self.statement, "source": self.source, "scenario": self.scenario,
                "metric": self.metric, "better": self.better, "planner": self.planner, "than": list(self.than),
                "navigator": self.navigator, "test": self.test}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "Claim":
        return cls(data["id"], data["statement"], data["source"], data["scenario"], data["metric"],
                   data["better"], data["planner"], tuple(data["than"]), data["test"], data.get("navigator"))


def numeric_columns() -> tuple[str, ...]:
    """The row columns a numeric claim may test: every integer or floating-point column of ``runs.parquet``."""
    import pyarrow as pa

    from swarmnav.study.rows import RUN_SCHEMA
    return tuple(f.name for f in RUN_SCHEMA if pa.types.is_integer(f.type) or pa.types.is_floating(f.type))


def arm_labels(components) -> list[str]:
    """Every label a row of these planner (or navigator) entries carries, as the grid writes them: the entry's
    label, or for a sweep each swept arm's label (``maco(p0=0.9, rho=0.9)``); a claim names one arm."""
    return [component.arm_label(setting)
            for component in components for setting in (component.settings() if component.swept else [None])]


def read_claims(top: TomlTable, scenarios: tuple[str, ...], planners, navigators) -> tuple[Claim, ...]:
    """Validate a study's ``[[claims]]`` array (``top``: the study's top table; ``planners`` and
    ``navigators``: its components)."""
    entries = top.tables("claims", [])
    names = [FilePath(s).stem for s in scenarios]
    planner_labels = arm_labels(planners)
    navigator_labels = arm_labels(navigators)
    columns = numeric_columns() if entries else ()
    out: list[Claim] = []
    for entry in entries:
        entry.only(KEYS)
        claim_id = entry.string("id", non_empty=True)
        if not _ID.fullmatch(claim_id):
            entry.fail("id", f"{claim_id!r} must be lowercase letters, digits and single hyphens")
        if claim_id in (c.id for c in out):
            entry.fail("id", f"{claim_id!r} is used by an earlier claim")
        statement = entry.string("statement", non_empty=True)
        origin = entry.string("source", non_empty=True)
        test = _one_of(entry, "test", TESTS, "a test")
        scenario = _scenario(entry, names, test)
        metric = entry.string("metric", non_empty=True)
        if metric != SUCCESS and metric not in columns:
            entry.fail("metric", f"{metric!r} is neither 'success' nor a numeric row column "
                                 f"(e.g. plan_length_m, plan_time_s, path_length_m)")
        better = _one_of(entry, "better", BETTER, "a direction")
        planner = _one_of(entry, "planner", planner_labels, "a planner label of the study")
        than = _than(entry, planner, planner_labels)
        navigator = _one_of(entry, "navigator", navigator_labels, "a navigator label of the study", None)
        if (test == "fisher") != (metric == SUCCESS):
            entry.fail("test", f"{test!r} does not test {metric!r} (success rates take 'fisher'; "
                               "a numeric metric 'rank_sum' or 'signed_rank')")
        out.append(Claim(claim_id, statement, origin, scenario, metric, better, planner, than, test, navigator))
    return tuple(out)


def claim_scenarios(claim: Claim, names) -> list[str]:
    """The scenario names a claim compares on: its one scenario, or those its glob matches (aggregate)."""
    if claim.test != AGGREGATE:
        return [claim.scenario]
    return [name for name in names if fnmatch.fnmatchcase(name, claim.scenario)]


def _scenario(entry: TomlTable, names: list[str], test: str) -> str:
    """``scenario``: one of the study's scenarios; for an aggregate claim a glob matching two or more."""
    if test != AGGREGATE:
        return _one_of(entry, "scenario", names, "a scenario of the study")
    pattern = entry.string("scenario", REQUIRED, non_empty=True)
    matched = [name for name in names if fnmatch.fnmatchcase(name, pattern)]
    if len(matched) < 2:
        entry.fail("scenario", f"{pattern!r} matches {len(matched)} of the study's scenarios; an aggregate claim "
                               f"({AGGREGATE}) needs a glob matching two or more")
    return pattern


def _one_of(entry: TomlTable, key: str, allowed, what: str, default: Any = REQUIRED) -> str | None:
    """A non-empty string among ``allowed`` (``default`` when absent)."""
    value = entry.string(key, default, non_empty=True)
    if value is not default and value not in allowed:
        entry.fail(key, f"{value!r} is not {what} ({', '.join(allowed)})")
    return value


def _than(entry: TomlTable, planner: str, planner_labels: list[str]) -> tuple[str, ...]:
    """``than``: one planner label or a non-empty list of them, none the claimed planner, none twice."""
    value = entry.raw("than", None)
    labels = check_array([value] if isinstance(value, str) else value, entry.path("than"), entry.source,
                         "a planner label or a non-empty list of them", non_empty=True)
    than: list[str] = []
    for j, label in enumerate(labels):
        field = entry.path(f"than[{j}]")
        check_string(label, field, entry.source, planner_labels)
        if label == planner or label in than:
            fail(field, f"{label!r} is the claimed planner or listed twice", entry.source)
        than.append(label)
    return tuple(than)
