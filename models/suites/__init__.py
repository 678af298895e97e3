"""Generated navigation suites: a small specification file of kinds, seeds and options (``dyn300.toml``).

A suite is groups of (kind, seed range, generator options); scene ``S`` of group ``G`` is the text of
:func:`~models.scenario_generator.generate` for that kind and seed, named ``<prefix>-G-S``, and runs with
world seed ``S`` (its file's ``seed``).  Beside the spec, ``NAME-verdicts.json`` (data, written by
``python -m swarmnav.sim.suite_verdicts NAME``) holds each scene's oracle verdict and difficulty metrics, in
order of difficulty; :func:`load_suite` orders the scenes by it when it is there.
"""

from __future__ import annotations

import json
import typing
from dataclasses import dataclass, fields
from pathlib import Path as FilePath
from typing import Any

from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario_generator import KINDS, GeneratorOptions, generate
from swarmnav.models.toml_table import TomlTable, parse_toml, read_text, within

SUITE_DIR = FilePath(__file__).resolve().parent
MAX_SCENES = 100_000  # scenes of one suite (over all groups), checked before any is listed
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


MAX_SEED_OFFSET = 10**9  # generator seeds stay far below the largest seed a scenario file holds


def list_suites() -> list[str]:
    return sorted(p.stem for p in SUITE_DIR.glob("*.toml"))


def load_suite(name: str, sensor_model: str | None = None, seed_offset: int = 0) -> Suite:
    """A suite by name (``models/suites/NAME.toml``) or path; ``sensor_model`` (``detector`` or ``rangefinder``:
    12 rangefinders at 1 m) overrides every scene's sensing; ``seed_offset`` shifts every group's seeds (a
    held-out set: the same families and options, scenes nobody measured a navigator on; the shipped verdicts
    and order apply to the suite's own seeds only, so a shifted suite has neither).

    Raises:
        ConfigError: an unknown suite, kind, option or sensing model, a bad option value or seed range
            (naming the file and the field, ``groups[2].options.speed_ratio``).
    """
    path = FilePath(name) if name.endswith(".toml") else SUITE_DIR / f"{name}.toml"
    if not path.is_file():
        raise ConfigError("--suite", f"no suite {name!r} (bundled: {', '.join(list_suites())})")
    if sensor_model is not None and sensor_model not in SENSOR_OVERRIDES:
        raise ConfigError("--sensor-model", f"expected one of {', '.join(SENSOR_OVERRIDES)}, got {sensor_model!r}")
    if not 0 <= seed_offset <= MAX_SEED_OFFSET:
        raise ConfigError("--seed-offset", f"must be from 0 to {MAX_SEED_OFFSET:,}, got {seed_offset}")
    top = parse_toml(read_text(path, "suite"), str(path))
    suite_name = top.string("name", path.stem, non_empty=True)
    version = top.integer("version", 1, bounds=within(1))
    description = top.string("description", "")
    prefix = top.string("prefix", "d300", non_empty=True)
    defaults = top.table("defaults", {})
    default_options = _options(defaults)
    scenes = []
    for group in top.tables("groups", []):
        kind = group.string("kind", choices=KINDS)
        first, end = _seed_range(group)
        label = group.string("name", kind, non_empty=True)
        own = group.table("options", {})
        options = {**default_options, **_options(own), **SENSOR_OVERRIDES.get(sensor_model or "", {})}
        group.close()
        if len(scenes) + end - first > MAX_SCENES:
            group.fail("seeds", f"the suite would have {len(scenes) + end - first:,} scenes (at most {MAX_SCENES:,})")
        try:
            GeneratorOptions(**options).check(kind)
        except ConfigError as exc:  # the generator names its command-line option: name the file's field
            key = exc.field.removeprefix("--").replace("-", "_")
            (own if own.has(key) else defaults).fail(key, exc.problem)
        for seed in range(first + seed_offset, end + seed_offset):
            scene_name = f"{prefix}-{label}-{seed}"
            scenes.append(SuiteScene(scene_name, label, kind, seed, GeneratorOptions(**options, name=scene_name)))
    top.close()
    if not scenes:
        top.fail("groups", "a suite needs at least one group")
    verdict_path = path.with_name(f"{path.stem}-verdicts.json")
    verdicts: dict[str, dict[str, Any]] = {}
    if verdict_path.is_file() and seed_offset == 0:
        entries = json.loads(verdict_path.read_text(encoding="utf-8"))["scenes"]
        verdicts = {e["scenario"]: e for e in entries}
        rank = {e["scenario"]: k for k, e in enumerate(entries)}
        scenes.sort(key=lambda s: rank.get(s.name, len(rank)))
    return Suite(suite_name, version, description, tuple(scenes), verdicts)


def _options(t: TomlTable) -> dict[str, Any]:
    """A table of generator options, each of its :class:`GeneratorOptions` field's type (``name`` is the suite's)."""
    hints = typing.get_type_hints(GeneratorOptions)
    known = sorted(f.name for f in fields(GeneratorOptions) if f.name != "name")
    for key in t.keys():
        if key not in known:
            t.fail(key, f"unknown generator option (known: {', '.join(known)})")
        t.typed(key, hints[key])
    return dict(t.data)


def _seed_range(group: TomlTable) -> tuple[int, int]:
    """``seeds = [first, end)``: scenes ``first`` .. ``end - 1``."""
    seeds = group.raw("seeds")
    if not (isinstance(seeds, list) and len(seeds) == 2
            and all(isinstance(s, int) and not isinstance(s, bool) for s in seeds) and 0 <= seeds[0] < seeds[1]):
        group.fail("seeds", f"expected [first, end) with 0 <= first < end, got {seeds!r}")
    return seeds[0], seeds[1]


def stratified_sample(suite: Suite, per_group: int | tuple[int, int] = 2) -> tuple[SuiteScene, ...]:
    """``per_group`` scenes of each group, spread over the group's order (``bench navigation --quick``); or, with
    ``per_group = (first, end)``, each group's scenes ``first`` to ``end - 1`` in seed order (a contiguous slice:
    with ``seed_offset`` 500, ``(0, 250)`` of ``crowdnav`` are CrowdNav's cases 500-749 in both settings)."""
    if isinstance(per_group, tuple):
        first, end = per_group
        return tuple(scene for group in dict.fromkeys(s.group for s in suite.scenes)
                     for scene in sorted((s for s in suite.scenes if s.group == group), key=lambda s: s.seed)[first:end])
    out = []
    for group in dict.fromkeys(s.group for s in suite.scenes):
        members = [s for s in suite.scenes if s.group == group]
        step = max(len(members) // per_group, 1)
        out += members[step // 2::step][:per_group]
    return tuple(out)


__all__ = ["Suite", "SuiteScene", "load_suite", "list_suites", "stratified_sample"]
