"""``swarmnav log info LOG`` and ``swarmnav log recover IN OUT``.

``info`` prints the scenario, planner, navigator, seed, duration, outcome and every channel
with its message count and schema, from the file's summary section
(:mod:`swarmnav.log.summary`: a log of any length answers at once).  A file without
footer (a killed run) is read as ``plot`` reads it: what was recovered, with a
warning line that says how much and advises ``log recover``, exit 0.  ``recover``
turns it into a complete, indexed file holding every message up to the writer's
last flush, streaming the messages (memory: one chunk).
"""

from __future__ import annotations

import argparse
import json
import math
import sys

from swarmnav.log.reader import outcome_text, truncation_advice
from swarmnav.log.recover import recover_log
from swarmnav.log.summary import LogSummary, read_summary


def describe(log: LogSummary) -> list[str]:
    """Lines for ``swarmnav log info``."""
    planner, navigator = log.metadata.get("planner", {}), log.metadata.get("navigator", {})
    lines = [
        f"log:        {log.raw.path}",
        f"scenario:   {log.scenario_name}",
        f"planner:    {planner.get('name', '?')} {planner.get('params', '')}",
        f"navigator:  {navigator.get('name', '?')} {navigator.get('params', '')}",
        f"seed:       {log.metadata.get('run', {}).get('seed', '?')}",
        f"duration:   {log.duration_s:.3f} s (simulation)",
        f"outcome:    {outcome_text(log)}",
        f"file:       {log.raw.recovery_line()}",
    ]
    recovery = log.metadata.get("recovery")
    if recovery:
        lines.append(f"recovered:  from {recovery.get('source')} ({recovery.get('problem') or 'complete'}); "
                     f"{recovery.get('messages_recovered')} messages kept")
    collisions = sum(1 for _, kind, _ in log.events if kind == "collision_begin")
    lines.append(f"collisions: {collisions}")
    versions = log.metadata.get("versions", {})
    if versions:
        lines.append("versions:   " + ", ".join(f"{k} {v}" for k, v in sorted(versions.items())))
    lines.append("channels:")
    width = max((len(t) for t in log.counts), default=0)
    for topic, count in log.counts.items():
        lines.append(f"  {topic:<{width}}  {count:>7}  {log.schema_names.get(topic, '')}")
    if log.outcome:
        lines.append("summary:")
        for key, value in log.outcome.items():
            if isinstance(value, float) and math.isfinite(value):
                value = f"{value:.6g}"
            lines.append(f"  {key}: {value}")
    return lines



def run_info(args: argparse.Namespace) -> int:
    log = read_summary(args.log)
    if not log.complete:
        print(f"warning: {args.log}: {truncation_advice(log.raw)}", file=sys.stderr)
    if not args.json:
        print("\n".join(describe(log)))
        return 0
    print(json.dumps({
        "log": str(args.log),
        "scenario": log.scenario_name,
        "planner": log.metadata.get("planner", {}).get("name"),
        "navigator": log.metadata.get("navigator", {}).get("name"),
        "seed": log.metadata.get("run", {}).get("seed"),
        "duration_s": log.duration_s,
        "outcome": log.outcome,
        "events": [{"time_s": t, "kind": k, "details": d} for t, k, d in log.events],
        "channels": {topic: {"count": count, "schema": log.schema_names.get(topic, "")}
                     for topic, count in log.counts.items()},
        "versions": log.metadata.get("versions", {}),
        "complete": log.complete,
        "file": log.raw.recovery_line(),
    }, sort_keys=True))
    return 0



def run_recover(args: argparse.Namespace) -> int:
    raw = recover_log(args.source, args.target)
    print(f"{args.target}: {raw.recovery_line()}")
    return 0
