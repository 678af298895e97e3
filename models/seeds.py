"""A run's random seeds, each named for what it seeds."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from swarmnav.models.errors import ConfigError


@dataclass(frozen=True)
class Seeds:
    """A run's two random seeds, each named for what it seeds.

    Attributes:
        planner: the planner's draws (``numpy.random.default_rng(planner)``) and the navigator's
            (its own stream under it, ``SeedSequence(planner, spawn_key=(1,))``).
        world: every random obstacle motion (each obstacle its own stream under it).

    Fallbacks, in order: a scenario file's ``seed`` gives both; :meth:`Scenario.with_world_seed`
    replaces ``world`` (and nothing resets it to the file's); an episode's own ``seed`` or
    ``world_seed``, when given, replaces the scenario's (``sim.episode.EpisodeSpec.resolved``).
    """

    planner: int
    world: int

    def __post_init__(self) -> None:
        for name in ("planner", "world"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
                raise ConfigError(f"seeds.{name}", f"must be a non-negative integer, got {value!r}")

    @classmethod
    def derived(cls, seed: int) -> "Seeds":
        """Both seeds from one (Gymnasium's ``reset(seed=...)``): ``SeedSequence(seed).spawn(2)``, the
        first child's first 32-bit word for the planner, the second child's for the world."""
        planner, world = (int(child.generate_state(1)[0]) for child in np.random.SeedSequence(int(seed)).spawn(2))
        return cls(planner, world)
