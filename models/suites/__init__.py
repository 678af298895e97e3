"""Generated navigation suites: a small specification file of kinds, seeds and options (``dyn300.toml``).

A suite is groups of (kind, seed range, generator options); scene ``S`` of group ``G`` is the text of
:func:`~models.scenario_generator.generate` for that kind and seed, named ``<prefix>-G-S``, and runs with
world seed ``S`` (its file's ``seed``).  Beside the spec, ``NAME-verdicts.json`` (data, written by
``python -m swarmnav.sim.suite_verdicts NAME``) holds each scene's oracle verdict and difficulty metrics, in
order of difficulty; :func:`load_suite` orders the scenes by it when it is there.
"""

from __future__ import annotations

import json
import tomllib
from dataclasses import dataclass, fields
from pathlib import Path as FilePath
from typing import Any

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario_generator import KINDS, GeneratorOptions, generate

SUITE_DIR = FilePath(__file__).resolve().parent
SENSOR_OVERRIDES = {"detector": {"sensor_model": "detector"},
                    "rangefinder": {"sensor_model": "rangefinder", "sensor_count": 12, "range_m": 1.0}}


@dataclass(frozen=True)
class SuiteScene:
    """One generated scene of a suite."""

    name: str
    group: str
    kind: str
    seed: int
    options: GeneratorOptions

    def text(self) -> str:
        return generate(self.kind, self.seed, self.options)


@dataclass(frozen=True)
class Suite:
    name: str
    version: int
    description: str
    scenes: tuple[SuiteScene, ...]
    verdicts: dict[str, dict[str, Any]]  # scene name -> the verdict file's entry (empty without the file)


def list_suites() -> list[str]:
    return sorted(p.stem for p in SUITE_DIR.glob("*.toml"))


def _options(source: str, where: str, table: Any) -> dict[str, Any]:
    if not isinstance(table, dict):
        raise ConfigError(where, "expected a table of generator options", source)
    known = {f.name for f in fields(GeneratorOptions)}
    for key in table:
        if key not in known or key == "name":
            known_list = ", ".join(sorted(known - {"name"}))
            raise ConfigError(f"{where}.{key}", f"unknown generator option (known: {known_list})", source)
    return dict(table)


def load_suite(name: str, sensor_model: str | None = None) -> Suite:
    """A suite by name (``models/suites/NAME.toml``) or path; ``sensor_model`` (``detector`` or ``rangefinder``:
    12 rangefinders at 1 m) overrides every scene's sensing.

    Raises:
        ConfigError: an unknown suite, kind, option or sensing model, or a bad seed range (naming the field).
    """
    path = FilePath(name) if name.endswith(".toml") else SUITE_DIR / f"{name}.toml"
    if not path.is_file():
        raise ConfigError("--suite", f"no suite {name!r} (bundled: {', '.join(list_suites())})")
    source = str(path)
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    if sensor_model is not None and sensor_model not in SENSOR_OVERRIDES:
        raise ConfigError("--sensor-model", f"expected one of {', '.join(SENSOR_OVERRIDES)}, got {sensor_model!r}")
    defaults = _options(source, "defaults", data.get("defaults", {}))
    scenes = []
    for i, group in enumerate(data.get("groups", [])):
        where = f"groups[{i}]"
        kind = group.get("kind")
        if kind not in KINDS:
            raise ConfigError(f"{where}.kind", f"unknown kind {kind!r} (expected one of: {', '.join(KINDS)})", source)
        seeds = group.get("seeds")
        if not (isinstance(seeds, list) and len(seeds) == 2 and all(isinstance(s, int) for s in seeds)
                and 0 <= seeds[0] < seeds[1]):
            raise ConfigError(f"{where}.seeds", f"expected [first, end) with 0 <= first < end, got {seeds!r}", source)
        label = str(group.get("name", kind))
        options = {**defaults, **_options(source, f"{where}.options", group.get("options", {})),
                   **SENSOR_OVERRIDES.get(sensor_model or "", {})}
        for seed in range(*seeds):
            scene_name = f"{data.get('prefix', 'd300')}-{label}-{seed}"
            scenes.append(SuiteScene(scene_name, label, kind, seed, GeneratorOptions(**options, name=scene_name)))
    if not scenes:
        raise ConfigError("groups", "a suite needs at least one group", source)
    verdict_path = path.with_name(f"{path.stem}-verdicts.json")
    verdicts: dict[str, dict[str, Any]] = {}
    if verdict_path.is_file():
        entries = json.loads(verdict_path.read_text(encoding="utf-8"))["scenes"]
        verdicts = {e["scenario"]: e for e in entries}
        rank = {e["scenario"]: k for k, e in enumerate(entries)}
        scenes.sort(key=lambda s: rank.get(s.name, len(rank)))
    return Suite(str(data.get("name", path.stem)), int(data.get("version", 1)), str(data.get("description", "")),
                 tuple(scenes), verdicts)


def stratified_sample(suite: Suite, per_group: int = 2) -> tuple[SuiteScene, ...]:
    """``per_group`` scenes of each group, spread over the group's order (``bench navigation --quick``)."""
    out = []
    for group in dict.fromkeys(s.group for s in suite.scenes):
        members = [s for s in suite.scenes if s.group == group]
        step = max(len(members) // per_group, 1)
        out += members[step // 2::step][:per_group]
    return tuple(out)


__all__ = ["Suite", "SuiteScene", "load_suite", "list_suites", "stratified_sample"]
