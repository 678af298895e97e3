"""Write a generated suite's verdict file: ``python -m swarmnav.sim.suite_verdicts dyn300``.

For every scene of ``models/suites/NAME.toml`` (with its own world seed): the difficulty metrics of
:mod:`sim.difficulty` and the clairvoyant oracle's verdict, written to ``NAME-verdicts.json`` ordered by
difficulty: scenes the oracle solves first, by the oracle's T* over its static arrival (``t_star_ratio``),
then by ``survivability``; unsolvable scenes last.  Data, not code: the benchmark reads it to order the
scenes and to report where its own oracle runs disagree.
"""

from __future__ import annotations

import json
import sys
import time

from swarmnav.models.scenario import parse_scenario
from swarmnav.models.suites import SUITE_DIR, load_suite
from swarmnav.sim.difficulty import difficulty


def difficulty_key(entry: dict) -> tuple:
    solvable = bool(entry["oracle"]["solvable"])
    return (not solvable, entry["t_star_ratio"] if entry["t_star_ratio"] is not None else 0.0,
            entry["survivability"], entry["scenario"])


def suite_verdicts(name: str, progress: bool = False) -> dict:
    suite = load_suite(name)
    entries = []
    for k, scene in enumerate(suite.scenes):
        t0 = time.perf_counter()
        entry = difficulty(parse_scenario(scene.text(), scene.name))
        entry.update(group=scene.group, kind=scene.kind, seed=scene.seed)
        entries.append(entry)
        if progress:
            print(f"{k + 1}/{len(suite.scenes)} {scene.name} {entry['oracle']['solvable']} "
                  f"{time.perf_counter() - t0:.1f}s", file=sys.stderr, flush=True)
    entries.sort(key=difficulty_key)
    for rank, entry in enumerate(entries):
        entry["difficulty_rank"] = rank
        verdict = entry["oracle"]
        entry["oracle"] = {k: verdict[k] for k in ("solvable", "arrival_s", "reason")}
        settings = {k: v for k, v in verdict.items() if k not in ("solvable", "arrival_s", "reason")}
    return {"suite": suite.name, "version": suite.version, "oracle_settings": settings if entries else {},
            "scenes": entries}


def write(path, data: dict) -> None:
    """One scene per line (a small diff when a verdict changes)."""
    head = {k: v for k, v in data.items() if k != "scenes"}
    lines = [json.dumps(e, sort_keys=True) for e in data["scenes"]]
    text = json.dumps(head)[:-1] + ', "scenes": [\n' + ",\n".join(lines) + "\n]}\n"
    path.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    name = sys.argv[1] if len(sys.argv) > 1 else "dyn300"
    data = suite_verdicts(name, progress=True)
    write(SUITE_DIR / f"{name}-verdicts.json", data)
