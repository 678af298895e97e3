"""A study's rows as JUnit XML (``swarmnav study --junit FILE``), and its ``--min-success`` check.

JUnit is what CI systems display: one ``<testsuite>`` per scenario, one ``<testcase>`` per row named by
planner label, navigator label and seeds; an ``<error>`` for every row whose outcome is ``error`` (an exception
or a dead worker: the run did not finish), and a ``<failure>`` for every other row that is not a success (it ran
and fell short: no path, the wall limit, a collision, the time limit, the robot left the arena; plan-only rows:
a plan that is not collision-free), each with its outcome and log path.  Each suite's and the document's
``tests``, ``failures``, ``errors``, ``skipped`` and ``time`` add up over their cases, as JUnit readers expect.
Both kinds fail a CI check.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ElementTree
from collections import defaultdict
from pathlib import Path as FilePath
from typing import Any, Iterable


def row_succeeded(row: dict[str, Any]) -> bool:
    """The row's ``success`` column (physics: reached with no collision; plan-only: a collision-free plan)."""
    return bool(row.get("success"))


def _case_name(row: dict[str, Any]) -> str:
    navigator = row.get("navigator_label") or row.get("navigator") or "follow"
    world = row.get("world_seed")
    return (f"{row.get('label') or row.get('planner')} + {navigator} seed {row.get('seed')}"
            + ("" if world is None else f" world seed {world}"))


def _failure_text(row: dict[str, Any]) -> tuple[str, str]:
    outcome = row.get("outcome") or "?"
    if outcome == "ok":  # ran, but not a success: say how
        outcome = row.get("run_outcome") or ("plan not collision-free" if row.get("mode") == "plan" else "not reached")
        if outcome == "goal_reached" and (row.get("collisions") or 0) > 0:
            outcome = "reached after a collision"
    parts = [f"outcome: {outcome}"]
    for key in ("collisions", "first_collision_s", "sim_time_s", "plan_length_m"):
        if row.get(key) is not None:
            parts.append(f"{key}: {row[key]}")
    if row.get("error"):
        parts.append(f"error: {row['error']}")
    if row.get("log"):
        parts.append(f"log: {row['log']}")
    return outcome, "; ".join(parts)


def junit_tree(study: str, rows: Iterable[dict[str, Any]]) -> ElementTree.ElementTree:
    """The JUnit document of the rows (suites in scenario order of first appearance)."""
    by_scenario: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for row in rows:
        by_scenario[str(row.get("scenario"))].append(row)
    root = ElementTree.Element("testsuites", name=study)
    total = failed = errored = 0
    total_s = 0.0
    for scenario, scenario_rows in by_scenario.items():
        suite = ElementTree.SubElement(root, "testsuite", name=f"{study}.{scenario}")
        suite_failed = suite_errored = 0
        suite_s = 0.0
        scenario_rows.sort(key=lambda r: (str(r.get("label")), str(r.get("navigator_label")), r.get("seed") or 0,
                                          -1 if r.get("world_seed") is None else r["world_seed"]))
        for row in scenario_rows:
            seconds = round(float(row.get("cell_wall_s") or 0.0), 3)
            suite_s += seconds
            case = ElementTree.SubElement(suite, "testcase", name=_case_name(row), classname=f"{study}.{scenario}",
                                          time=f"{seconds:.3f}")
            if not row_succeeded(row):
                outcome, text = _failure_text(row)
                kind = "error" if row.get("outcome") == "error" else "failure"
                element = ElementTree.SubElement(case, kind, message=outcome, type=outcome)
                element.text = text
                if kind == "error":
                    suite_errored += 1
                else:
                    suite_failed += 1
            if row.get("log"):
                out = ElementTree.SubElement(case, "system-out")
                out.text = f"log: {row['log']}"
        suite.set("tests", str(len(scenario_rows)))
        suite.set("failures", str(suite_failed))
        suite.set("errors", str(suite_errored))
        suite.set("skipped", "0")
        suite.set("time", f"{suite_s:.3f}")
        total += len(scenario_rows)
        failed += suite_failed
        errored += suite_errored
        total_s += suite_s
    root.set("tests", str(total))
    root.set("failures", str(failed))
    root.set("errors", str(errored))
    root.set("skipped", "0")
    root.set("time", f"{total_s:.3f}")
    return ElementTree.ElementTree(root)


def write_junit(study: str, rows: Iterable[dict[str, Any]], out: str | os.PathLike) -> FilePath:
    """Write the JUnit XML file (its folder made if needed); returns its path."""
    out = FilePath(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tree = junit_tree(study, rows)
    ElementTree.indent(tree)
    tree.write(out, encoding="utf-8", xml_declaration=True)
    return out


def success_shortfalls(rows: Iterable[dict[str, Any]], min_success: float) -> list[str]:
    """One line per configuration (scenario, planner label, navigator) whose success rate is below
    ``min_success``; every row counts, failures and errors included."""
    counts: dict[tuple[str, str, str], list[int]] = defaultdict(lambda: [0, 0])
    for row in rows:
        key = (str(row.get("scenario")), str(row.get("label") or row.get("planner")),
               str(row.get("navigator_label") or row.get("navigator") or "follow"))
        counts[key][0] += row_succeeded(row)
        counts[key][1] += 1
    return [f"{scenario}: {label} + {navigator}: success {ok}/{n} = {ok / n:.3f} < {min_success:g}"
            for (scenario, label, navigator), (ok, n) in counts.items() if ok / n < min_success]
