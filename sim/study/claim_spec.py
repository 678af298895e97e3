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

:func:`parse_claims` validates them against the study (its scenarios, its planner and navigator labels, the
row columns); every problem is one :class:`ConfigError` naming the file and the field.  The verdicts are
:mod:`swarmnav.sim.study.claims`'s.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path as FilePath
from typing import Any

from swarmnav.models.errors import ConfigError

TESTS = ("rank_sum", "signed_rank", "fisher")
BETTER = ("lower", "higher")
SUCCESS = "success"
KEYS = {"id", "statement", "source", "scenario", "metric", "better", "planner", "than", "navigator", "test"}
_ID = re.compile(r"[a-z0-9]+(-[a-z0-9]+)*")


@dataclass(frozen=True)
class Claim:
    id: str
    statement: str
    source: str
    scenario: str  # the scenario's name (file stem)
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

    from swarmnav.sim.study.rows import RUN_SCHEMA
    return tuple(f.name for f in RUN_SCHEMA if pa.types.is_integer(f.type) or pa.types.is_floating(f.type))


def arm_labels(components) -> list[str]:
    """Every label a row of these planner (or navigator) entries carries, as the grid writes them: the entry's
    label, or for a sweep each swept arm's label (``maco(p0=0.9, rho=0.9)``); a claim names one arm."""
    return [component.arm_label(setting)
            for component in components for setting in (component.settings() if component.swept else [None])]


def _text(source: str, entry: dict, key: str, where: str, required: bool = True) -> str | None:
    if key not in entry:
        if required:
            raise ConfigError(f"{where}.{key}", "is required", source)
        return None
    value = entry[key]
    if not isinstance(value, str) or not value.strip():
        raise ConfigError(f"{where}.{key}", f"expected a non-empty string, got {value!r}", source)
    return value


def _one_of(source: str, value: str, allowed: list[str] | tuple[str, ...], field: str, what: str) -> str:
    if value not in allowed:
        raise ConfigError(field, f"{value!r} is not {what} ({', '.join(allowed)})", source)
    return value


def parse_claims(source: str, value: Any, scenarios: tuple[str, ...], planners, navigators) -> tuple[Claim, ...]:
    """Validate a study's ``[[claims]]`` array (``planners`` and ``navigators``: the study's components)."""
    if not isinstance(value, list):
        raise ConfigError("claims", "expected an array of [[claims]] tables", source)
    names = [FilePath(s).stem for s in scenarios]
    planner_labels = arm_labels(planners)
    navigator_labels = arm_labels(navigators)
    columns = numeric_columns() if value else ()
    out: list[Claim] = []
    for i, entry in enumerate(value):
        where = f"claims[{i}]"
        if not isinstance(entry, dict):
            raise ConfigError(where, "expected a table", source)
        for key in sorted(set(entry) - KEYS):
            raise ConfigError(f"{where}.{key}", "unknown key", source)
        claim_id = _text(source, entry, "id", where)
        if not _ID.fullmatch(claim_id):
            raise ConfigError(f"{where}.id", f"{claim_id!r} must be lowercase letters, digits and single hyphens",
                              source)
        if claim_id in (c.id for c in out):
            raise ConfigError(f"{where}.id", f"{claim_id!r} is used by an earlier claim", source)
        statement = _text(source, entry, "statement", where)
        origin = _text(source, entry, "source", where)
        scenario = _one_of(source, _text(source, entry, "scenario", where), names, f"{where}.scenario",
                           "a scenario of the study")
        metric = _text(source, entry, "metric", where)
        if metric != SUCCESS and metric not in columns:
            raise ConfigError(f"{where}.metric", f"{metric!r} is neither 'success' nor a numeric row column "
                                                 f"(e.g. plan_length_m, plan_time_s, path_length_m)", source)
        better = _one_of(source, _text(source, entry, "better", where), BETTER, f"{where}.better", "a direction")
        planner = _one_of(source, _text(source, entry, "planner", where), planner_labels, f"{where}.planner",
                          "a planner label of the study")
        than_value = entry.get("than")
        if isinstance(than_value, str):
            than_value = [than_value]
        if not isinstance(than_value, list) or not than_value:
            raise ConfigError(f"{where}.than", "expected a planner label or a non-empty list of them", source)
        than = []
        for j, label in enumerate(than_value):
            if not isinstance(label, str):
                raise ConfigError(f"{where}.than[{j}]", f"expected a planner label, got {label!r}", source)
            _one_of(source, label, planner_labels, f"{where}.than[{j}]", "a planner label of the study")
            if label == planner or label in than:
                raise ConfigError(f"{where}.than[{j}]", f"{label!r} is the claimed planner or listed twice", source)
            than.append(label)
        navigator = _text(source, entry, "navigator", where, required=False)
        if navigator is not None:
            _one_of(source, navigator, navigator_labels, f"{where}.navigator", "a navigator label of the study")
        test = _one_of(source, _text(source, entry, "test", where), TESTS, f"{where}.test", "a test")
        if (test == "fisher") != (metric == SUCCESS):
            raise ConfigError(f"{where}.test", f"{test!r} does not test {metric!r} (success rates take 'fisher'; "
                                               "a numeric metric 'rank_sum' or 'signed_rank')", source)
        out.append(Claim(claim_id, statement, origin, scenario, metric, better, planner, tuple(than), test,
                         navigator))
    return tuple(out)
