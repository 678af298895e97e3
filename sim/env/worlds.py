"""Randomised worlds: a new scenario per episode, drawn from a list or from the scenario generator.

``NavigateEnv(scenarios=...)`` takes either

* a list of scenarios (bundled names, paths or :class:`Scenario` objects), or one of them: each
  episode takes one, uniformly; or
* a generator specification, a dict with ``kinds`` (a list of the kinds of
  ``swarmnav scenarios generate``: crossing, head_on, overtake, crowd) and any
  :class:`models.scenario_generator.GeneratorOptions` field, each either one value
  or a ``[low, high]`` range drawn uniformly per episode (integers for integer
  fields, both ends included): ``{"kinds": ["crossing", "crowd"], "obstacles": [2, 6],
  "speed_ratio": [0.3, 0.8], "radius_max_m": [0.25, 0.4], "range_m": [1.0, 2.0]}``.
  Each episode's scenario is ``generate(kind, seed, options)`` with the kind, the
  options and the generator's seed all drawn, so it is the scenario that
  ``swarmnav scenarios generate`` writes for them (its ``description`` says how).

The draw uses its own stream of the reset's seed, ``SeedSequence(seed).spawn(3)[2]``
(the first two children are the planner's and the world's seeds,
:meth:`models.seeds.Seeds.derived`), so the same seed gives the same world and
another seed another.  A reset without a seed draws the episode's seed from the
environment's ``np_random``, which is why Stable-Baselines3's auto-reset (no
options) meets a new world every episode.

Fixed spaces (the padding): the observation layout is the merge of the layouts
of every scenario the source can give (a list: all of them; a generator: per kind,
the scenario with every ranged option at its upper end): the same entries and
shapes, each bound the widest.  ``obstacles`` has as many rows as the most moving
obstacles (unless ``obstacle_slots`` says), zero-padded with ``obstacle_mask`` 0 for
the empty rows; the bounds are wide enough for every draw, so nothing is clipped
that the scenario's own layout would keep.  What changes the shapes cannot vary:
the number of rangefinders and the sensing model must be the same for all (a
ConfigError names ``env.scenarios`` otherwise), and the robot too (the action space).
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass
from pathlib import Path as FilePath
from typing import Any, Protocol, Sequence

import numpy as np

from swarmnav.controllers.policy_interface import ObservationLayout
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import Scenario, load_scenario, parse_scenario
from swarmnav.models.scenario_generator import KINDS, GeneratorOptions, generate
from swarmnav.sim.plugins import load_plugins

FIELD = "env.scenarios"
DRAW_CHILD = 2  # SeedSequence(seed).spawn(3)[2]: children 0 and 1 are Seeds.derived's


class ScenarioSource(Protocol):
    """Where an episode's scenario comes from."""

    def draw(self, rng: np.random.Generator) -> Scenario: ...

    def envelope(self) -> list[Scenario]:
        """Scenarios whose layouts, merged (and widened), bound every draw's."""

    def widen(self, layout: ObservationLayout) -> ObservationLayout:
        """The merged layout, widened where the envelope's scenarios fall short of what a draw can give."""


REDRAWS = 50  # draws of one episode's world before its options are called unfit


def draw_rng(episode_seed: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence(int(episode_seed)).spawn(DRAW_CHILD + 1)[DRAW_CHILD])


@dataclass(frozen=True)
class ScenarioList:
    scenarios: tuple[Scenario, ...]

    def draw(self, rng: np.random.Generator) -> Scenario:
        return self.scenarios[int(rng.integers(len(self.scenarios)))]

    def envelope(self) -> list[Scenario]:
        return list(self.scenarios)

    def widen(self, layout: ObservationLayout) -> ObservationLayout:
        return layout


@dataclass(frozen=True)
class GeneratorSpec:
    """Kinds and option ranges of the scenario generator (see the module docstring)."""

    kinds: tuple[str, ...]
    fixed: dict[str, Any]
    ranges: dict[str, tuple[Any, Any]]

    @classmethod
    def parse(cls, spec: dict[str, Any]) -> "GeneratorSpec":
        spec = dict(spec)
        kinds = spec.pop("kinds", None)
        if isinstance(kinds, str):
            kinds = [kinds]
        if not kinds or any(kind not in KINDS for kind in kinds):
            raise ConfigError(f"{FIELD}.kinds", f"expected a list of {list(KINDS)}, got {kinds!r}")
        known = {f.name: f for f in dataclasses.fields(GeneratorOptions)}
        fixed, ranges = {}, {}
        for key, value in spec.items():
            if key not in known:
                raise ConfigError(f"{FIELD}.{key}", f"unknown option (known: kinds, {', '.join(known)})")
            if isinstance(value, (list, tuple)):
                if len(value) != 2 or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value) \
                        or value[0] > value[1]:
                    raise ConfigError(f"{FIELD}.{key}", f"a range is [low, high] numbers, got {value!r}")
                if key == "sensor_count" and value[0] != value[1]:
                    raise ConfigError(f"{FIELD}.sensor_count", "cannot vary: it is the size of the ranges entry")
                ranges[key] = (value[0], value[1])
            else:
                fixed[key] = value
        generator = cls(tuple(kinds), fixed, ranges)
        for kind in generator.kinds:  # every option and the upper ends checked now, not at the first reset
            generator.options(kind, {key: high for key, (_, high) in ranges.items()}).check(kind)
        return generator

    def options(self, kind: str, drawn: dict[str, Any]) -> GeneratorOptions:
        return GeneratorOptions(**{**self.fixed, **drawn})

    def draw(self, rng: np.random.Generator) -> Scenario:
        kind = self.kinds[int(rng.integers(len(self.kinds)))]
        drawn = {}
        for key, (low, high) in self.ranges.items():
            if isinstance(getattr(GeneratorOptions, key), int):
                drawn[key] = int(rng.integers(int(low), int(high) + 1))
            else:
                drawn[key] = float(rng.uniform(low, high))
        # the radii are drawn too, so a count that fits the envelope's draw may not fit this one's: such a
        # draw is redrawn from the same stream (a bounded number of times), so a reset never fails on it
        for _ in range(REDRAWS):
            seed = int(rng.integers(2**31))
            try:
                return parse_scenario(generate(kind, seed, self.options(kind, drawn)), f"generated {kind} {seed}")
            except ConfigError as exc:
                last = exc
        raise ConfigError(FIELD, f"no {kind} scenario fits {drawn} in {REDRAWS} draws: {last}")

    def envelope(self) -> list[Scenario]:
        upper = {key: high for key, (_, high) in self.ranges.items()}
        out = []
        for kind in self.kinds:
            try:
                out.append(parse_scenario(generate(kind, 0, self.options(kind, upper)), f"generated {kind}"))
            except ConfigError as exc:
                raise ConfigError(FIELD, f"the upper ends of the ranges give no {kind} scenario: {exc}") from None
        return out

    def widen(self, layout: ObservationLayout) -> ObservationLayout:
        """The radii are drawn below ``radius_max_m``: the envelope's largest is not the largest a draw can give."""
        radius_m = float(self.ranges.get("radius_max_m", (0, self.fixed.get("radius_max_m",
                                                                             GeneratorOptions.radius_max_m)))[1])
        if not layout.obstacle_slots or radius_m <= layout.obstacle_radius_max_m:
            return layout
        return dataclasses.replace(layout, obstacle_radius_max_m=radius_m, obstacle_offset_max_m=(
            layout.obstacle_offset_max_m - layout.obstacle_radius_max_m + radius_m))


def scenario_source(value: Any) -> ScenarioSource:
    """The ``scenarios=`` option -> a source: a generator dict, a list of scenarios, or one scenario (a name, a
    path or a :class:`Scenario`, a list of one); ConfigError naming ``env.scenarios`` for anything else."""
    load_plugins()
    if isinstance(value, dict):
        return GeneratorSpec.parse(value)
    if isinstance(value, (str, os.PathLike, Scenario)):
        value = [value]
    if not isinstance(value, Sequence) or not value:
        raise ConfigError(FIELD, f"expected a non-empty list of scenarios, one scenario or a generator dict, "
                                 f"got {value!r}")
    return ScenarioList(tuple(v if isinstance(v, Scenario) else load_scenario(str(v)) for v in value))


def merged_layout(layouts: Sequence[ObservationLayout]) -> ObservationLayout:
    """One layout that holds every one of ``layouts``: the widest bounds, the most obstacle rows."""
    first = layouts[0]
    for layout in layouts[1:]:
        for name in ("range_count", "path_waypoints"):
            if getattr(layout, name) != getattr(first, name):
                raise ConfigError(FIELD, f"the scenarios differ in {name} ({getattr(first, name)} and "
                                         f"{getattr(layout, name)}): the observation's shape must not change")
        if bool(layout.obstacle_slots) != bool(first.obstacle_slots):
            raise ConfigError(FIELD, "the scenarios differ in sensing model: some observe obstacles, some do not")
    return ObservationLayout(**{f.name: max(getattr(layout, f.name) for layout in layouts)
                                for f in dataclasses.fields(ObservationLayout)})
